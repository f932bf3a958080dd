# Sources the nav work adds to the sketchnav executable: target_sources(sketchnav PRIVATE ...)
# The run harness (`sketchnav run` as a function) is a small static library so the closed-loop
# integration tests (tests/integration) run exactly what the command runs.
add_library(sketchnav_runharness STATIC run_harness.cpp)
target_include_directories(sketchnav_runharness PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
# nav is public: RunOptions' observer hooks carry nav types (TelemetryRow, Observation).
# sim and mapsketch are public too: RunSettings (run_harness.h) holds their Params.
target_link_libraries(sketchnav_runharness PUBLIC sketchnav::core sketchnav::hw sketchnav::nav
  sketchnav::sim sketchnav::mapsketch
  PRIVATE sketchnav::drivers sketchnav::landmarks opencv_imgproc
  opencv_imgcodecs)
target_compile_options(sketchnav_runharness PRIVATE -Wall -Wextra -Wno-unused-parameter)
target_link_libraries(sketchnav PRIVATE sketchnav_runharness)
