# Runs one command and checks how it ended; for CLI tests (cmake -P expect_exit.cmake).
#
#   COMMAND                    the command line: a |-separated string ("prog|--size|8"), the form
#                              that survives add_test(... -DCOMMAND=...) without quoting games,
#                              or a ;-list. Arguments cannot contain "|".
#   EXPECTED_EXIT              exit status to expect (required; 0 for success)
#   EXPECTED_STDERR_SUBSTRING  must occur in stderr (optional)
#   EXPECTED_STDOUT_SUBSTRING  must occur in stdout (optional)
#   EXPECTED_STDOUT_ALL        |-separated texts that must all occur in stdout (optional)
#   EXPECTED_STDERR_EMPTY      ON: stderr must be empty (optional; --help answers on stdout only)
#
# A command expected to fail (EXPECTED_EXIT != 0) must also explain itself in exactly one line on
# stderr, the contract of the project's CLIs. Every failure prints the command, its status and
# both streams, so the ctest log alone says what happened.
if("${COMMAND}" STREQUAL "")
  message(FATAL_ERROR "expect_exit.cmake: set -DCOMMAND=prog|arg|...")
endif()
if(NOT DEFINED EXPECTED_EXIT OR NOT EXPECTED_EXIT MATCHES "^[0-9]+$")
  message(FATAL_ERROR "expect_exit.cmake: set -DEXPECTED_EXIT to a non-negative integer, "
                      "got \"${EXPECTED_EXIT}\"")
endif()

string(REPLACE "|" ";" command "${COMMAND}")
execute_process(COMMAND ${command}
                RESULT_VARIABLE status
                OUTPUT_VARIABLE stdout
                ERROR_VARIABLE stderr)

string(REPLACE ";" " " command_line "${command}")
string(CONCAT context "command: ${command_line}\nexit status: ${status}\n"
                     "stdout:\n${stdout}\nstderr:\n${stderr}")

# A crash yields a text such as "Segmentation fault" rather than a number; STREQUAL catches both.
if(NOT status STREQUAL EXPECTED_EXIT)
  message(FATAL_ERROR "expected exit status ${EXPECTED_EXIT}\n${context}")
endif()
if(DEFINED EXPECTED_STDERR_SUBSTRING)
  string(FIND "${stderr}" "${EXPECTED_STDERR_SUBSTRING}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "stderr lacks \"${EXPECTED_STDERR_SUBSTRING}\"\n${context}")
  endif()
endif()
if(DEFINED EXPECTED_STDOUT_SUBSTRING)
  string(FIND "${stdout}" "${EXPECTED_STDOUT_SUBSTRING}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "stdout lacks \"${EXPECTED_STDOUT_SUBSTRING}\"\n${context}")
  endif()
endif()
if(DEFINED EXPECTED_STDOUT_ALL)
  string(REPLACE "|" ";" expected_texts "${EXPECTED_STDOUT_ALL}")
  foreach(text IN LISTS expected_texts)
    string(FIND "${stdout}" "${text}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "stdout lacks \"${text}\"\n${context}")
    endif()
  endforeach()
endif()
if(EXPECTED_STDERR_EMPTY AND NOT stderr STREQUAL "")
  message(FATAL_ERROR "expected nothing on stderr\n${context}")
endif()
if(NOT EXPECTED_EXIT EQUAL 0)
  string(REGEX MATCHALL "\n" line_ends "${stderr}")
  list(LENGTH line_ends line_count)
  if(NOT line_count EQUAL 1 OR NOT stderr MATCHES "\n$")
    message(FATAL_ERROR "expected exactly one line on stderr, got ${line_count} line end(s)\n"
                        "${context}")
  endif()
endif()
