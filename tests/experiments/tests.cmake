# Issue #8: replay, tune, experiments. Each test drives the sketchnav command like a user
# (cmake -P scripts); short simulated runs keep the whole set under about two minutes.
set(SN $<TARGET_FILE:sketchnav>)
set(EXP_DIR ${CMAKE_CURRENT_SOURCE_DIR}/experiments)
set(EXP_WORK ${CMAKE_CURRENT_BINARY_DIR}/experiments-work)
foreach(t replay_rendered tune_reproducible short_run bad_input scenarios_slice)
  add_test(NAME experiments_${t}
    COMMAND ${CMAKE_COMMAND} -DSN=${SN} -DWORK=${EXP_WORK}/${t} -DSHARE=${PROJECT_SOURCE_DIR}/share
            -P ${EXP_DIR}/${t}.cmake)
  set_tests_properties(experiments_${t} PROPERTIES TIMEOUT 600 LABELS "experiments")
endforeach()

# Unit tests of the variant generator and the plot writer (fast, no simulation).
sketchnav_add_test(test_experiments
  SOURCES ${EXP_DIR}/test_experiments.cpp ${EXP_DIR}/test_scenarios.cpp
  LINK sketchnav::run sketchnav::core sketchnav::sim sketchnav::mapsketch opencv_imgproc
  LABELS experiments)
if(TARGET test_experiments)
  target_include_directories(test_experiments PRIVATE ${PROJECT_SOURCE_DIR}/apps)
endif()
