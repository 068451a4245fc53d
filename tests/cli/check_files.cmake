# Checks the files a command wrote; for CLI tests (cmake -P check_files.cmake).
#
#   DIRECTORY       folder the files are in (required)
#   FILES           names relative to DIRECTORY, |-separated or a ;-list (required); each must
#                   exist and be non-empty, and a *.png must start with the PNG signature
#   EXPECTED_COUNT  optional: exactly this many entries of DIRECTORY match PATTERN, so that a run
#                   writing more than it should is caught too
#   PATTERN         glob for EXPECTED_COUNT (default "*")
if(NOT DEFINED DIRECTORY OR NOT DEFINED FILES)
  message(FATAL_ERROR "check_files.cmake: set -DDIRECTORY=... and -DFILES=a|b|...")
endif()
if(NOT IS_DIRECTORY "${DIRECTORY}")
  message(FATAL_ERROR "${DIRECTORY} is not a folder")
endif()

string(REPLACE "|" ";" files "${FILES}")
foreach(name IN LISTS files)
  set(path "${DIRECTORY}/${name}")
  if(NOT EXISTS "${path}")
    file(GLOB present RELATIVE "${DIRECTORY}" "${DIRECTORY}/*")
    message(FATAL_ERROR "${path} was not written (the folder holds: ${present})")
  endif()
  file(SIZE "${path}" bytes)
  if(bytes EQUAL 0)
    message(FATAL_ERROR "${path} is empty")
  endif()
  if(name MATCHES "\\.png$")
    # The 8-byte signature every PNG starts with (PNG specification, section 5.2).
    file(READ "${path}" signature LIMIT 8 HEX)
    if(NOT signature STREQUAL "89504e470d0a1a0a")
      message(FATAL_ERROR "${path} does not start with the PNG signature (got ${signature})")
    endif()
  endif()
endforeach()

if(DEFINED EXPECTED_COUNT)
  if(NOT DEFINED PATTERN)
    set(PATTERN "*")
  endif()
  file(GLOB matches RELATIVE "${DIRECTORY}" "${DIRECTORY}/${PATTERN}")
  list(LENGTH matches count)
  if(NOT count EQUAL EXPECTED_COUNT)
    message(FATAL_ERROR "expected ${EXPECTED_COUNT} entries matching ${PATTERN} in ${DIRECTORY}, "
                        "found ${count}: ${matches}")
  endif()
endif()
