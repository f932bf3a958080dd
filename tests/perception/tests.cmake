# Issue 23 item 4: the perception benchmark (apps/perception_bench.*, `replay --make-sequences /
# --truth / --eval`). Unit tests of the generator's geometry, the truth parser and the report;
# a small generated slice through the command (skipped when the shared data is absent).
sketchnav_add_test(test_perception_bench
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/perception/test_perception_bench.cpp
          ${PROJECT_SOURCE_DIR}/apps/perception_bench.cpp
  LINK sketchnav::run sketchnav::core sketchnav::servo opencv_imgproc opencv_imgcodecs
  LABELS perception)
if(TARGET test_perception_bench)
  target_include_directories(test_perception_bench PRIVATE ${PROJECT_SOURCE_DIR}/apps
)
endif()
add_test(NAME perception_replay_slice
  COMMAND ${CMAKE_COMMAND} -DSN=$<TARGET_FILE:sketchnav> -DSRC=${PROJECT_SOURCE_DIR}
          -DWORK=${CMAKE_CURRENT_BINARY_DIR}/perception-slice
          -P ${CMAKE_CURRENT_SOURCE_DIR}/perception/replay_slice.cmake)
set_tests_properties(perception_replay_slice PROPERTIES TIMEOUT 600 LABELS "perception"
                     SKIP_REGULAR_EXPRESSION "SKIPPED: shared data absent")
