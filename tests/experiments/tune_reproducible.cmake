# The tuner's table is reproducible with a seed: two identical tiny sweeps (2 gains x 1 short
# scenario x 1 seed, 6 simulated seconds) give the same tune.csv; the table has one row per
# gain and a recommendation among them.
file(REMOVE_RECURSE ${WORK})
foreach(run a b)
  execute_process(COMMAND ${SN} --json tune --lambda 0.4,1.2 --scenarios exp3-8 --seeds 1
                          --seed 7 --max-time 6 --jobs 2 --out ${WORK}/${run}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out_${run} ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "tune ${run} failed (${rc}):\n${out_${run}}\n${err}")
  endif()
endforeach()
file(READ ${WORK}/a/tune.csv ta)
file(READ ${WORK}/b/tune.csv tb)
if(NOT ta STREQUAL tb)
  message(FATAL_ERROR "tune tables differ with the same seed:\n${ta}\n---\n${tb}")
endif()
string(JSON nrows LENGTH "${out_a}" rows)
string(JSON rec GET "${out_a}" recommended)
if(NOT nrows EQUAL 2 OR NOT (rec EQUAL 0.4 OR rec EQUAL 1.2))
  message(FATAL_ERROR "unexpected tune output:\n${out_a}")
endif()
if(NOT EXISTS ${WORK}/a/tune.png)
  message(FATAL_ERROR "tune wrote no plot")
endif()
message(STATUS "tune table (reproduced):\n${ta}")
