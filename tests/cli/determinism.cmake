# A simulated run is bit-repeatable: two runs of the lab with one seed write the same
# telemetry.csv and events.jsonl (tests/support/compare_runs.sh). Every before/after check of
# a change that must not change behaviour rests on this.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
foreach(run a b)
  execute_process(COMMAND ${SN} run --seed 3 --max-time 6 --out ${WORK}/${run}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 AND NOT rc EQUAL 1)  # a 6-second run fails (timeout); bad input would be 2
    message(FATAL_ERROR "sketchnav run: exit ${rc}\n${out}\n${err}")
  endif()
endforeach()
execute_process(COMMAND bash ${SRC}/tests/support/compare_runs.sh ${WORK}/a ${WORK}/b
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "two runs with seed 3 differ:\n${out}${err}")
endif()
# The comparison itself must see a difference: a run with another seed is not the same.
execute_process(COMMAND ${SN} run --seed 4 --max-time 6 --out ${WORK}/c
                RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
execute_process(COMMAND bash ${SRC}/tests/support/compare_runs.sh ${WORK}/a ${WORK}/c
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 1)
  message(FATAL_ERROR "compare_runs.sh found seeds 3 and 4 identical (exit ${rc}):\n${out}${err}")
endif()
