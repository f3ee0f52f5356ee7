# Lays out the Python package in DEST (<build>/python/hybridcont): the package's modules from
# SOURCE/python/hybridcont and its data under DEST/data — the shipped model files, the figure script and the
# viewers of the study's and the sweep's reports with Plotly.js (PLOTLY_JS, installed from npm by the build; empty without npm). Run by the
# build (cmake -P) after the extension module is linked into DEST; copies only what changed.
file(GLOB modules ${SOURCE}/python/hybridcont/*.py)
file(COPY ${modules} DESTINATION ${DEST})
# A module removed from the source leaves the package too.
file(GLOB built ${DEST}/*.py)
foreach(module ${built})
  get_filename_component(name ${module} NAME)
  if(NOT EXISTS ${SOURCE}/python/hybridcont/${name})
    file(REMOVE ${module})
  endif()
endforeach()
file(COPY ${SOURCE}/models/ DESTINATION ${DEST}/data/models)
file(COPY ${SOURCE}/python/hybridcont_plot.py DESTINATION ${DEST}/data)
file(COPY ${SOURCE}/report/template.html ${SOURCE}/report/viewer.js ${SOURCE}/report/viewer.css
     ${SOURCE}/report/sweep.html ${SOURCE}/report/sweep.js DESTINATION ${DEST}/data/report)
if(PLOTLY_JS AND EXISTS ${PLOTLY_JS})
  file(COPY ${PLOTLY_JS} DESTINATION ${DEST}/data/report)
endif()
