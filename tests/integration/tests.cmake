# Closed-loop navigation runs in the simulator (issue #7): short worlds under fixtures/, fixed
# seeds, assertions on outcome and clearance. They run exactly what `sketchnav run` runs
# (run/: sketchnav::run), with the demo landmark model trained once into the build tree.
if(TARGET sketchnav::run)
  sketchnav_add_test(test_integration_nav
    SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_closed_loop.cpp
    LINK sketchnav::run sketchnav::hw
    LABELS integration
    TIMEOUT 900)
  if(TARGET test_integration_nav)
    target_compile_definitions(test_integration_nav PRIVATE
      SKETCHNAV_MODEL_CACHE_DIR="${PROJECT_BINARY_DIR}/model-cache")
  endif()
endif()
