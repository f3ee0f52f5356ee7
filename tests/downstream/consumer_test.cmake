# The installed package, used the way a downstream project uses it (ctest: package.downstream_consumer):
#  1. `cmake --install BUILD_DIR` into a fresh prefix, WORK_DIR/prefix;
#  2. configure and build this folder's consumer against it (CMAKE_PREFIX_PATH only) and run it;
#  3. run the installed tool: `--help` works, and `--paths` names the figure script, and the model folder
#     when the package has one, inside the prefix itself (never the source tree it was built from).
#
#   cmake -DBUILD_DIR=... -DCONSUMER_SOURCE_DIR=... -DWORK_DIR=... -DBINDIR=bin -DDATADIR=share
#         [-DCONFIG=Release] [-DGENERATOR=...] [-DMAKE_PROGRAM=...] [-DCXX_COMPILER=...] [-DEXPECT_MODELS=ON]
#         -P consumer_test.cmake
foreach(var BUILD_DIR CONSUMER_SOURCE_DIR WORK_DIR BINDIR DATADIR)
  if("${${var}}" STREQUAL "")
    message(FATAL_ERROR "consumer_test.cmake: -D${var}=... is required")
  endif()
endforeach()

# Runs a command; stops the test with its output if it fails. Its output is left in step_output.
function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "${what} failed (exit ${rc}): ${command}\n${out}")
  endif()
  message(STATUS "${what}: ok")
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

set(prefix "${WORK_DIR}/prefix")
set(consumer_build "${WORK_DIR}/build")
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

set(config_args "")
if(NOT "${CONFIG}" STREQUAL "")
  set(config_args --config "${CONFIG}")
endif()
run_step("install into ${prefix}" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}" ${config_args})

set(configure_args -S "${CONSUMER_SOURCE_DIR}" -B "${consumer_build}" "-DCMAKE_PREFIX_PATH=${prefix}"
                   "-DCMAKE_CXX_FLAGS=-O1")  # a tiny program: compile time is what counts
if(NOT "${GENERATOR}" STREQUAL "")
  list(APPEND configure_args -G "${GENERATOR}")
endif()
if(NOT "${MAKE_PROGRAM}" STREQUAL "")
  list(APPEND configure_args "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
endif()
if(NOT "${CXX_COMPILER}" STREQUAL "")
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")  # same ABI as the installed library
endif()
run_step("configure the consumer" "${CMAKE_COMMAND}" ${configure_args})
run_step("build the consumer" "${CMAKE_COMMAND}" --build "${consumer_build}" ${config_args})

set(consumer "${consumer_build}/consumer")
if(NOT EXISTS "${consumer}" AND EXISTS "${consumer_build}/${CONFIG}/consumer")
  set(consumer "${consumer_build}/${CONFIG}/consumer")  # multi-config generators
endif()
run_step("run the consumer" "${consumer}")
if(EXISTS "${consumer_build}/study_consumer")
  run_step("run the study consumer" "${consumer_build}/study_consumer")
endif()
message(STATUS "${step_output}")

set(tool "${prefix}/${BINDIR}/hybridcont")
run_step("${tool} --help" "${tool}" --help)
if(NOT step_output MATCHES "list" OR NOT step_output MATCHES "--paths")
  message(FATAL_ERROR "hybridcont --help does not list its commands and --paths:\n${step_output}")
endif()

run_step("${tool} --paths" "${tool}" --paths)
message(STATUS "${step_output}")
file(REAL_PATH "${prefix}" real_prefix)  # the tool reports paths with symlinks resolved
set(data "${real_prefix}/${DATADIR}/hybridcont")
string(FIND "${step_output}" "plot script: ${data}/hybridcont_plot.py\n" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the installed hybridcont does not use the figure script of its own prefix "
                      "(${data}/hybridcont_plot.py):\n${step_output}")
endif()
if(EXPECT_MODELS)
  set(expected_models "${data}/models")
else()
  set(expected_models "(not found)")  # the package has no model folder, and the source tree's is not used
endif()
string(FIND "${step_output}" "models: ${expected_models}\n" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the installed hybridcont reports another model folder than ${expected_models}:\n"
                      "${step_output}")
endif()
