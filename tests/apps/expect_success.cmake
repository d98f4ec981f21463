# Runs COMMAND (a ;-list: the program and its arguments), echoing its output, and checks: exit
# status 0 and the output (stdout then stderr) matching REGEX. (ctest's PASS_REGULAR_EXPRESSION
# alone would pass a command that printed the text and then crashed.)
execute_process(COMMAND ${COMMAND} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err
                ECHO_OUTPUT_VARIABLE ECHO_ERROR_VARIABLE)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "expected exit status 0, got '${status}'")
endif()
if(NOT "${out}${err}" MATCHES "${REGEX}")
  message(FATAL_ERROR "the output does not match '${REGEX}'")
endif()
