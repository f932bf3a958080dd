# Replay on a sequence rendered by the simulator agrees with its truth.
# The fixture: the lab's landmark seen from 1.2-2.0 m (the range at which the robot passes
# landmarks) at normalised offsets -0.25, -0.12, 0, +0.12, +0.25 (15 frames). The turns are 6x
# the servo's dead band (0.02), so once the landmark is found the direction is unambiguous;
# what can fail is perception. Threshold 80 % (>= 12 of 15): measured 15/15 for L1, L5, L6, L8
# and 11/15 for the smaller L3 (misses, never a wrong direction); a broken sign convention
# (Left <-> Right) scores at most 3/15 and a replay that never finds the landmark 0/15.
#
# What is tested is replay's pipeline (rendering, sign conventions, the truth CSV, the outputs),
# not how perception generalises: the model here is trained on the demo set plus the textures
# the world shows, so the rendered landmark is a photo it knows. The simulator's own runs never
# do that (doc/simulator.md); how perception does on photos it was not trained on is measured by
# bench/perception (doc/perception-benchmark.md).
file(REMOVE_RECURSE ${WORK})
file(COPY ${SHARE}/landmarks/ DESTINATION ${WORK}/set)
file(GLOB textures ${SHARE}/textures/*/*_Iconic.jpg)
foreach(t ${textures})
  get_filename_component(dir ${t} DIRECTORY)
  get_filename_component(cls ${dir} NAME)
  file(COPY ${t} DESTINATION ${WORK}/set/${cls})
endforeach()
execute_process(COMMAND ${SN} train --landmarks ${WORK}/set -o ${WORK}/set.slm
                RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "train failed (${rc}): ${err}")
endif()
foreach(lm L1 L5)
  execute_process(COMMAND ${SN} replay --make-fixture ${WORK}/${lm} --landmark ${lm}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE cls ERROR_VARIABLE err
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "make-fixture ${lm} failed (${rc}): ${err}")
  endif()
  execute_process(COMMAND ${SN} --json replay --frames ${WORK}/${lm} --target ${cls}
                          --model ${WORK}/set.slm
                          --truth ${WORK}/${lm}/truth.csv --out ${WORK}/out-${lm}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "replay ${lm} failed (${rc}):\n${out}\n${err}")
  endif()
  set(cls_${lm} ${cls})
  string(JSON agreement GET "${out}" agreement)
  string(JSON frames GET "${out}" truth_frames)
  message(STATUS "${lm} (${cls}): agreement ${agreement} over ${frames} frames")
  if(NOT frames EQUAL 15)
    message(FATAL_ERROR "expected 15 truth frames, got ${frames}")
  endif()
  if(agreement LESS 0.8)
    message(FATAL_ERROR "${lm}: agreement ${agreement} < 0.8\n${out}")
  endif()
  foreach(f replay.csv contact.png)
    if(NOT EXISTS ${WORK}/out-${lm}/${f})
      message(FATAL_ERROR "replay wrote no ${f}")
    endif()
  endforeach()
  file(STRINGS ${WORK}/out-${lm}/replay.csv lines)
  list(LENGTH lines n)
  if(NOT n EQUAL 16)
    message(FATAL_ERROR "replay.csv: expected a header + 15 rows, got ${n} lines")
  endif()
endforeach()

# Replay reads frames through the camera drivers: an unreadable frame in the folder is skipped
# with a warning and counted (dropped_frames), as a run's folder camera does; the rest replay.
file(COPY ${WORK}/L1/ DESTINATION ${WORK}/L1-corrupt FILES_MATCHING PATTERN "*.png")
file(WRITE ${WORK}/L1-corrupt/frame_0007b.png "not a png")
execute_process(COMMAND ${SN} --json replay --frames ${WORK}/L1-corrupt --target ${cls_L1}
                        --model ${WORK}/set.slm --out ${WORK}/out-corrupt
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "replay with a corrupt frame failed (${rc}):\n${out}\n${err}")
endif()
string(JSON frames GET "${out}" frames)
string(JSON dropped GET "${out}" dropped_frames)
string(JSON detected GET "${out}" detected)
if(NOT frames EQUAL 15 OR NOT dropped EQUAL 1 OR detected LESS 12)
  message(FATAL_ERROR "expected 15 frames, 1 dropped, >= 12 detected: ${frames}, ${dropped}, "
                      "${detected}\n${out}")
endif()
if(NOT err MATCHES "skipped unreadable frame")
  message(FATAL_ERROR "no warning for the corrupt frame:\n${err}")
endif()
