# Sources the experiments work (issue #8: replay, tune, experiments) adds to the sketchnav
# executable. The experiment and scenario model is the run library (run/: sketchnav::run).
target_link_libraries(sketchnav PRIVATE opencv_imgproc opencv_imgcodecs opencv_videoio)
# Issue 25: the scenario generator and `sketchnav scenarios` (generation + benchmark).
target_sources(sketchnav PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/cmd_scenarios.cpp)
