# Sources the mapsketch work adds to the sketchnav executable: target_sources(sketchnav PRIVATE ...)

# The local web server (sketch editor API; other areas register more routes on it). A small
# static library so its HTTP tests (tests/browser) link exactly what the command runs.
pkg_check_modules(CPPHTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)
# run_api.cpp is the live run page (state, frames, stop, capture); the run itself is handed in
# by the command (cmd_ui.cpp), so the library needs only the nav/hw types, not the simulator.
add_library(sketchnav_webui STATIC ui/server.cpp ui/editor_api.cpp ui/run_api.cpp
            ui/run_request.cpp)
add_library(sketchnav::webui ALIAS sketchnav_webui)
target_include_directories(sketchnav_webui PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/ui)
target_link_libraries(sketchnav_webui PUBLIC sketchnav::core sketchnav::mapsketch sketchnav::hw
                      sketchnav::nav PkgConfig::CPPHTTPLIB Threads::Threads opencv_imgproc
                      opencv_imgcodecs)
target_compile_options(sketchnav_webui PRIVATE -Wall -Wextra -Wno-unused-parameter)

target_link_libraries(sketchnav PRIVATE sketchnav_webui opencv_imgproc opencv_imgcodecs)
