# The command's contract: --help everywhere, exit codes, one-line errors.
set(SN $<TARGET_FILE:sketchnav>)
add_test(NAME cli_help COMMAND ${SN} --help)
set_tests_properties(cli_help PROPERTIES PASS_REGULAR_EXPRESSION "Subcommands:.*probe.*route.*run")
add_test(NAME cli_no_subcommand_is_usage_error COMMAND ${SN})
set_tests_properties(cli_no_subcommand_is_usage_error PROPERTIES WILL_FAIL TRUE)
foreach(sub run ui train recognise propose replay tune experiments scenarios sim route probe base-emulator)
  add_test(NAME cli_help_${sub} COMMAND ${SN} ${sub} --help)
  set_tests_properties(cli_help_${sub} PROPERTIES PASS_REGULAR_EXPRESSION "sketchnav ${sub} ")
endforeach()
# Exit code 2 and a one-line reason for bad usage / input (checked by a small driver script).
add_test(NAME cli_exit_codes
  COMMAND ${CMAKE_COMMAND} -DSN=${SN} -DWORK=${CMAKE_CURRENT_BINARY_DIR}/cli-work
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/exit_codes.cmake)
# A simulated run says what ground truth shows: how far its odometry is off and how far the
# sketch alone puts the goal (a failed, 3-second run: the exit code is not the point here).
add_test(NAME cli_run_reports_ground_truth
  COMMAND ${SN} run --max-time 3 --out ${CMAKE_CURRENT_BINARY_DIR}/cli-work/run-truth)
set_tests_properties(cli_run_reports_ground_truth PROPERTIES
  PASS_REGULAR_EXPRESSION "ground truth: odometry off [0-9.]+ m.*the sketch alone puts the goal [0-9.]+ m off"
  TIMEOUT 300)
# recognise --eval --plot and --annotate write their pictures (a demo-set model, 4 images).
# Its own folder: cli_exit_codes empties cli-work when it starts.
add_test(NAME cli_recognise_pictures
  COMMAND ${CMAKE_COMMAND} -DSN=${SN} -DSRC=${PROJECT_SOURCE_DIR}
          -DWORK=${CMAKE_CURRENT_BINARY_DIR}/cli-recognise-pictures
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/recognise_outputs.cmake)
set_tests_properties(cli_recognise_pictures PROPERTIES TIMEOUT 600)
# kill -9 during `sketchnav run` leaves every output readable to its last whole record
# (telemetry.csv, events.jsonl, the log file, the rawlog, summary.json, trajectory.png; issue 28).
if(SKETCHNAV_BUILD_TESTS)
  add_executable(test_run_kill ${CMAKE_CURRENT_LIST_DIR}/test_run_kill.cpp)
  add_dependencies(test_run_kill sketchnav)  # the test runs the command itself
  target_link_libraries(test_run_kill PRIVATE sketchnav::drivers opencv_imgcodecs
                        sketchnav_test_support GTest::gtest_main)
  target_include_directories(test_run_kill PRIVATE ${PROJECT_SOURCE_DIR}/tests/hardware)
  target_compile_definitions(test_run_kill PRIVATE SKETCHNAV_EXE="$<TARGET_FILE:sketchnav>")
  gtest_discover_tests(test_run_kill DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600 LABELS cli)
endif()
# Strict settings: unknown keys are exit 2 with the closest known key, on every subcommand.
add_test(NAME cli_settings_strict
  COMMAND ${CMAKE_COMMAND} -DSN=${SN} -DSRC=${PROJECT_SOURCE_DIR}
          -DWORK=${CMAKE_CURRENT_BINARY_DIR}/cli-settings
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/settings.cmake)
set_tests_properties(cli_settings_strict PROPERTIES TIMEOUT 300)
# Two simulated runs with one seed write identical telemetry.csv and events.jsonl.
add_test(NAME cli_run_deterministic
  COMMAND ${CMAKE_COMMAND} -DSN=${SN} -DSRC=${PROJECT_SOURCE_DIR}
          -DWORK=${CMAKE_CURRENT_BINARY_DIR}/cli-run-deterministic
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/determinism.cmake)
set_tests_properties(cli_run_deterministic PROPERTIES TIMEOUT 300)
# A short simulated run repeated from its summary's settings as --config: same settings,
# same outcome, same telemetry.
add_test(NAME cli_settings_roundtrip
  COMMAND ${CMAKE_COMMAND} -DSN=${SN} -DWORK=${CMAKE_CURRENT_BINARY_DIR}/cli-settings-roundtrip
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/settings_roundtrip.cmake)
set_tests_properties(cli_settings_roundtrip PROPERTIES TIMEOUT 600)
