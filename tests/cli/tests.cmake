# The command's contract: --help everywhere, exit codes, one-line errors.
set(SN $<TARGET_FILE:sketchnav>)
add_test(NAME cli_help COMMAND ${SN} --help)
set_tests_properties(cli_help PROPERTIES PASS_REGULAR_EXPRESSION "Subcommands:.*probe.*route.*run")
add_test(NAME cli_no_subcommand_is_usage_error COMMAND ${SN})
set_tests_properties(cli_no_subcommand_is_usage_error PROPERTIES WILL_FAIL TRUE)
foreach(sub run ui train recognise propose replay tune experiments sim route probe base-emulator)
  add_test(NAME cli_help_${sub} COMMAND ${SN} ${sub} --help)
  set_tests_properties(cli_help_${sub} PROPERTIES PASS_REGULAR_EXPRESSION "sketchnav ${sub} ")
endforeach()
# Exit code 2 and a one-line reason for bad usage / input (checked by a small driver script).
add_test(NAME cli_exit_codes
  COMMAND ${CMAKE_COMMAND} -DSN=${SN} -DWORK=${CMAKE_CURRENT_BINARY_DIR}/cli-work
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/exit_codes.cmake)
