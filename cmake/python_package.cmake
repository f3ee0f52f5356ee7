# Lays out the Python package in DEST (<build>/python/hybridcont): the package's modules from
# SOURCE/python/hybridcont and its data under DEST/data — the shipped model files, the figure script and the
# viewers of the study's and the sweep's reports with Plotly.js (PLOTLY_JS, installed from npm by the build; empty without npm). Run by the
# build (cmake -P) after the extension module is linked into DEST; copies only what changed.
# The package's modules and subpackages (hybridcont/sweeps/), as laid out in the source.
file(GLOB_RECURSE modules RELATIVE ${SOURCE}/python/hybridcont ${SOURCE}/python/hybridcont/*.py)
foreach(module ${modules})
  get_filename_component(folder ${module} DIRECTORY)
  file(COPY ${SOURCE}/python/hybridcont/${module} DESTINATION ${DEST}/${folder})
endforeach()
# A module removed from the source leaves the package too (sweeps.py, now the package sweeps/, included).
file(GLOB_RECURSE built RELATIVE ${DEST} ${DEST}/*.py)
foreach(module ${built})
  if(NOT module MATCHES "^data/" AND NOT EXISTS ${SOURCE}/python/hybridcont/${module})
    file(REMOVE ${DEST}/${module})
  endif()
endforeach()
file(COPY ${SOURCE}/models/ DESTINATION ${DEST}/data/models)
file(COPY ${SOURCE}/python/hybridcont_plot.py DESTINATION ${DEST}/data)
file(COPY ${SOURCE}/report/template.html ${SOURCE}/report/viewer.js ${SOURCE}/report/viewer.css
     ${SOURCE}/report/sweep.html ${SOURCE}/report/sweep.js DESTINATION ${DEST}/data/report)
if(PLOTLY_JS AND EXISTS ${PLOTLY_JS})
  file(COPY ${PLOTLY_JS} DESTINATION ${DEST}/data/report)
endif()
# The command-line tool and the headers model files compile against (a wheel carries both: its `hybridcont` command
# runs data/bin/hybridcont, which reads this folder's data; app/install_paths.h), where the build made the tool.
if(CLI AND EXISTS ${CLI})
  file(COPY ${CLI} DESTINATION ${DEST}/data/bin FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ
       GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
  file(COPY ${SOURCE}/include/hybridcont DESTINATION ${DEST}/data/include)
endif()
