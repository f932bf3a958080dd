# expect(CODE PATTERN ARGS...): runs ${SN} ARGS and fails the calling test script unless it
# exits with CODE and its output matches PATTERN. Shared by the command-line test scripts.
function(expect code pattern)
  execute_process(COMMAND ${SN} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL ${code})
    message(FATAL_ERROR "sketchnav ${ARGN}: exit ${rc}, expected ${code}\n${out}\n${err}")
  endif()
  if(NOT "${out}${err}" MATCHES "${pattern}")
    message(FATAL_ERROR "sketchnav ${ARGN}: output does not match '${pattern}':\n${out}\n${err}")
  endif()
endfunction()
