# Device tests over loopback with real peer processes: Aravis's fake GigE Vision camera
# (arv-fake-gv-camera-0.8, from aravis-tools) and `sketchnav base-emulator`.
# The fake GigE camera listens on the fixed GVCP port 3956, so these tests share a lock and
# never run concurrently with each other.
find_program(ARV_FAKE_GV_CAMERA arv-fake-gv-camera-0.8)
if(NOT ARV_FAKE_GV_CAMERA)
  set(ARV_FAKE_GV_CAMERA arv-fake-gv-camera-0.8)  # the tests fail with a clear message
endif()
if(SKETCHNAV_BUILD_TESTS)
  add_executable(test_hw_loopback
    ${CMAKE_CURRENT_LIST_DIR}/test_aravis_gv.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_base_emulator.cpp)
  add_dependencies(test_hw_loopback sketchnav)  # the tests run the command itself
  target_link_libraries(test_hw_loopback PRIVATE sketchnav::drivers opencv_core
                        sketchnav_test_support GTest::gtest_main)
  target_include_directories(test_hw_loopback PRIVATE ${CMAKE_CURRENT_LIST_DIR})
  target_compile_definitions(test_hw_loopback PRIVATE
    ARV_FAKE_GV_CAMERA="${ARV_FAKE_GV_CAMERA}"
    SKETCHNAV_EXE="$<TARGET_FILE:sketchnav>")
  gtest_discover_tests(test_hw_loopback DISCOVERY_TIMEOUT 60
    PROPERTIES TIMEOUT 120 LABELS hardware RESOURCE_LOCK gvcp_3956)
endif()

# `run --record FILE` then `run --replay FILE`: a short simulated run on the integration hall
# leaves a readable rawlog (frames, odometry, scans, commands), which the simulator-free replay
# reads back.
add_test(NAME run_record_replay
  COMMAND ${CMAKE_COMMAND} -DSN=$<TARGET_FILE:sketchnav> -DSRC=${PROJECT_SOURCE_DIR}
          -DWORK=${CMAKE_CURRENT_BINARY_DIR}/record-replay
          -DCACHE=${PROJECT_BINARY_DIR}/model-cache
          -P ${CMAKE_CURRENT_LIST_DIR}/record_replay.cmake)
set_tests_properties(run_record_replay PROPERTIES TIMEOUT 300 LABELS "hardware;integration")

# The replay gives the recorded run's commands, tick for tick, from a ROS bag (when sketchnav is
# built with ROS) and from a rawlog.
set(_record_formats rawlog)
if(TARGET sketchnav::ros)
  list(APPEND _record_formats bag)
endif()
foreach(ext IN LISTS _record_formats)
  add_test(NAME run_replay_same_commands_${ext}
    COMMAND ${CMAKE_COMMAND} -DSN=$<TARGET_FILE:sketchnav> -DSRC=${PROJECT_SOURCE_DIR}
            -DWORK=${CMAKE_CURRENT_BINARY_DIR}/replay-same-${ext} -DEXT=${ext}
            -DCACHE=${PROJECT_BINARY_DIR}/model-cache
            -P ${CMAKE_CURRENT_LIST_DIR}/record_replay_same.cmake)
  set_tests_properties(run_replay_same_commands_${ext} PROPERTIES TIMEOUT 300
                       LABELS "hardware;integration")
endforeach()
