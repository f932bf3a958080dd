file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(FIX ${SRC}/tests/integration/fixtures)
execute_process(
  COMMAND ${SN} --json run --world ${FIX}/hall.world.json --sketch ${FIX}/hall.sketch.json
          --cache-dir ${CACHE} --max-time 6 --out ${WORK}/rec --record ${WORK}/run.rawlog
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
# The run itself is cut short (exit 1, "time limit"): only the recording is under test here.
if(NOT EXISTS ${WORK}/run.rawlog)
  message(FATAL_ERROR "no rawlog written (exit ${rc}):\n${err}")
endif()
string(JSON mode GET "${out}" mode)
if(NOT mode STREQUAL "sim")
  message(FATAL_ERROR "unexpected summary: ${out}")
endif()
file(GLOB frames ${WORK}/run_Images/*.png)
list(LENGTH frames nframes)
if(nframes LESS 5)
  message(FATAL_ERROR "only ${nframes} frames recorded beside the rawlog")
endif()
# The recorded log is a device: probe it as a camera and as a laser.
execute_process(COMMAND ${SN} --json probe rawlog://${WORK}/run.rawlog --frames 1000
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(JSON received GET "${out}" received)
if(NOT rc EQUAL 0 OR NOT received EQUAL nframes)
  message(FATAL_ERROR "probe of the rawlog camera: exit ${rc}, received ${received} of ${nframes}\n${out}\n${err}")
endif()
# Simulator-free replay on the recording: runs, reports mode replay, writes its outputs.
execute_process(
  COMMAND ${SN} --json run --replay ${WORK}/run.rawlog --sketch ${FIX}/hall.sketch.json
          --cache-dir ${CACHE} --max-time 6 --out ${WORK}/replay
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT EXISTS ${WORK}/replay/summary.json)
  message(FATAL_ERROR "replay wrote no summary (exit ${rc}):\n${out}\n${err}")
endif()
string(JSON mode GET "${out}" mode)
string(JSON frames GET "${out}" perception frames)
if(NOT mode STREQUAL "replay" OR frames LESS 1)
  message(FATAL_ERROR "replay summary wrong: ${out}")
endif()
# Bad input: a missing recording is a one-line input error, exit 2.
execute_process(COMMAND ${SN} run --replay ${WORK}/none.rawlog --sketch ${FIX}/hall.sketch.json
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "none.rawlog: no such file")
  message(FATAL_ERROR "missing replay file: exit ${rc}: ${err}")
endif()
