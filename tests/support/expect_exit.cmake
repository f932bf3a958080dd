# expect(CODE PATTERN ARGS...): runs ${SN} ARGS and fails the calling test script unless it
# exits with CODE and its output matches PATTERN. Shared by the command-line test scripts.
function(expect code pattern)
  # A bad input must not hang the command (a FIFO given as an input once did): 120 s at most.
  execute_process(COMMAND ${SN} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  TIMEOUT 120)
  if(NOT rc EQUAL ${code})
    message(FATAL_ERROR "sketchnav ${ARGN}: exit ${rc}, expected ${code}\n${out}\n${err}")
  endif()
  if(NOT "${out}${err}" MATCHES "${pattern}")
    message(FATAL_ERROR "sketchnav ${ARGN}: output does not match '${pattern}':\n${out}\n${err}")
  endif()
endfunction()

# run_ok(OUT ERR ARGS...): runs ${SN} ARGS, fails the calling test script unless it exits 0,
# and returns its stdout and stderr in the variables named OUT and ERR.
function(run_ok out_var err_var)
  execute_process(COMMAND ${SN} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "sketchnav ${ARGN}: exit ${rc}, expected 0\n${out}\n${err}")
  endif()
  set(${out_var} "${out}" PARENT_SCOPE)
  set(${err_var} "${err}" PARENT_SCOPE)
endfunction()
