# A run is repeatable from its summary: summary.json's "settings" object, written as a --config
# file, makes a second run (no other options: its seed and time limit come from the settings)
# with the same settings, the same outcome and the same telemetry.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/../support/expect_exit.cmake)

function(run_any dir)
  execute_process(COMMAND ${SN} ${ARGN} --out ${dir} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 AND NOT rc EQUAL 1)  # a 3-second run fails; bad input would be 2
    message(FATAL_ERROR "sketchnav ${ARGN}: exit ${rc}\n${out}\n${err}")
  endif()
  file(READ ${dir}/summary.json s)
  set(summary "${s}" PARENT_SCOPE)
endfunction()

run_any(${WORK}/a run --seed 2 --max-time 3 --set servo.lambda=0.6 --set objectness.nms_iou=0.6
        --set landmarks.match.min_inliers=14)
set(first "${summary}")
string(JSON settings GET "${first}" settings)
foreach(key nav.select nav.locate nav.planner nav.movers nav.goal_door route sim objectness
            nav.perception landmarks.recognition landmarks.match landmarks.train servo)
  string(REPLACE "." ";" path "${key}")
  string(JSON t ERROR_VARIABLE e TYPE "${settings}" ${path})
  if(NOT t STREQUAL "OBJECT")
    message(FATAL_ERROR "summary settings lack '${key}': ${settings}")
  endif()
endforeach()
string(JSON seed GET "${settings}" sim seed)
string(JSON lambda GET "${settings}" servo lambda)
string(JSON max_time GET "${settings}" nav max_time_s)
string(JSON nms GET "${settings}" objectness nms_iou)
string(JSON inliers GET "${settings}" landmarks match min_inliers)
if(NOT seed EQUAL 2 OR NOT lambda EQUAL 0.6 OR NOT max_time EQUAL 3 OR NOT nms EQUAL 0.6
   OR NOT inliers EQUAL 14)
  message(FATAL_ERROR "summary settings are not the run's: seed ${seed}, lambda ${lambda}, "
                      "max_time_s ${max_time}, objectness.nms_iou ${nms}, "
                      "landmarks.match.min_inliers ${inliers}")
endif()
file(WRITE ${WORK}/settings.json "${settings}")

run_any(${WORK}/b --config ${WORK}/settings.json run)
set(second "${summary}")
string(JSON settings2 GET "${second}" settings)
string(JSON same EQUAL "${settings}" "${settings2}")
if(NOT same)
  message(FATAL_ERROR "the rerun's settings differ:\n${settings}\n---\n${settings2}")
endif()
foreach(field success reason time_s path_length_m seed sections_done)
  string(JSON v1 GET "${first}" ${field})
  string(JSON v2 GET "${second}" ${field})
  if(NOT v1 STREQUAL v2)
    message(FATAL_ERROR "the rerun's ${field} differs: ${v1} vs ${v2}")
  endif()
endforeach()
file(SHA256 ${WORK}/a/telemetry.csv h1)
file(SHA256 ${WORK}/b/telemetry.csv h2)
if(NOT h1 STREQUAL h2)
  message(FATAL_ERROR "the rerun's telemetry.csv differs")
endif()
