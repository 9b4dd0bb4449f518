# Installs detsim into a scratch prefix, then configures, builds and runs a tiny consumer project
# that uses only find_package(detsim CONFIG REQUIRED) and detsim::detsim, and compiles every C++
# snippet of the docs in it.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "command failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

# The libraries are already built in the tree that runs this test: install them from there (a
# rebuild from scratch would only repeat the same compilation).
run(${CMAKE_COMMAND} --install ${BINARY_DIR} --prefix ${prefix})
# Every C++ block of the README and docs/, as translation units the consumer compiles (not links):
# code the docs show must compile against the installed package (scripts/doc_snippets.py).
file(GLOB doc_pages ${SOURCE_DIR}/README.md ${SOURCE_DIR}/docs/*.md ${SOURCE_DIR}/*/README.md)
run(${PYTHON} ${SOURCE_DIR}/scripts/doc_snippets.py ${WORK_DIR}/doc_snippets ${doc_pages})
message(STATUS "${last_output}")
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/install/consumer -B ${WORK_DIR}/consumer -G ${GENERATOR}
    -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_PREFIX_PATH=${prefix}
    -DDOC_SNIPPETS_DIR=${WORK_DIR}/doc_snippets)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/consumer)
run(${WORK_DIR}/consumer/consumer)
if(NOT last_output MATCHES "1.5 \\* 2.25 = 3.375")
  message(FATAL_ERROR "unexpected consumer output: ${last_output}")
endif()
message(STATUS "consumer ran: ${last_output}")
run(${WORK_DIR}/consumer/consumer_tool run --scenario consumer_drop --json)
if(NOT last_output MATCHES "\"scenario\":\"consumer_drop\",\"frames\":120,")
  message(FATAL_ERROR "unexpected consumer_tool output: ${last_output}")
endif()
message(STATUS "consumer_tool ran: ${last_output}")
# The C API example of docs/C_API.md, built from C against the installed package: the ball rests
# a radius above the plane.
run(${WORK_DIR}/consumer/docs_C_API_c0)
if(NOT last_output MATCHES "^y = 0\\.50[0-9] m, state hash [0-9a-f]+")
  message(FATAL_ERROR "unexpected output of the C API example: ${last_output}")
endif()
message(STATUS "the C API example ran: ${last_output}")
