# Tests of the gray-scott mini-app (examples/gray_scott), included from tests/cli/CMakeLists.txt.
# They run the real binary: tiny simulations that must write their archives (default and JSON
# configuration), and the command-line contract (exit 2 and one line on stderr for bad arguments
# or configurations, exit 1 for runtime failures).
if(NOT TARGET gray-scott)
  return()  # examples not built (INSITU_BUILD_EXAMPLES=OFF)
endif()

set(gray_scott_cli_dir ${CMAKE_CURRENT_LIST_DIR})

# gray_scott_archive_case(NAME FILES COUNT ARGS...): removes the archive NAME.cdb (a run continues
# an existing archive, so stale steps would make it fail), runs gray-scott with ARGS and
# --out NAME.cdb, then checks that FILES (|-separated, relative to the archive) exist and that
# exactly COUNT previews were written.
function(gray_scott_archive_case name files count)
  set(archive ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_${name}.cdb)
  add_test(NAME gray_scott.${name}_clean COMMAND ${CMAKE_COMMAND} -E rm -rf ${archive})
  add_test(NAME gray_scott.${name}_run COMMAND gray-scott ${ARGN} --out ${archive})
  add_test(NAME gray_scott.${name}_archive
           COMMAND ${CMAKE_COMMAND} -DDIRECTORY=${archive} "-DFILES=${files}"
                   -DEXPECTED_COUNT=${count} -DPATTERN=previews/*.png
                   -P ${gray_scott_cli_dir}/check_files.cmake)
  set_tests_properties(gray_scott.${name}_clean PROPERTIES FIXTURES_SETUP gray_scott_${name}_clean)
  set_tests_properties(gray_scott.${name}_run PROPERTIES
                       FIXTURES_REQUIRED gray_scott_${name}_clean
                       FIXTURES_SETUP gray_scott_${name}_archive
                       TIMEOUT 120)
  set_tests_properties(gray_scott.${name}_archive PROPERTIES
                       FIXTURES_REQUIRED gray_scott_${name}_archive)
endfunction()

# A 24^3 box for 20 steps, archived at steps 10 and 20 in 32x32: well under a second on PoCL
# once the kernels are built.
gray_scott_archive_case(tiny
  "manifest.json|data.csv|proxies/step000010_view0.exr|proxies/step000020_view0.exr|previews/step000010_view0.png|previews/step000020_view0.png"
  2 --size 24 --steps 20 --every 10 --image-size 32x32)

# The same through a JSON configuration: an explicit step list, two views, field u, and an
# "archive" that --out overrides.
set(gray_scott_config ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_config.json)
file(WRITE ${gray_scott_config} [=[
{"fields": ["u"],
 "views": [{"azimuth": 0, "elevation": 0, "size": [24, 24]},
           {"azimuth": 90, "elevation": 30, "camera": "perspective", "fov": 40, "size": [16, 24]}],
 "transfer_function": {"points": [[0.3, 0, 0, 1, 0], [1.0, 1, 1, 1, 0.3]], "unit_length": 1.0},
 "layers": [0.6], "intervals": {"count": 4}, "proxies": ["depth", "distortion", "attenuation"],
 "steps": [5, 15], "archive": "overridden.cdb", "writer": {"queue": 2, "when_full": "block"}}
]=])
gray_scott_archive_case(configured
  "proxies/step000005_view0.exr|proxies/step000015_view1.exr|previews/step000005_view1.png|previews/step000015_view0.png"
  4 --size 16 --steps 16 --config ${gray_scott_config})

# gray_scott_cli_case(NAME EXIT STDERR|STDOUT TEXT ARGS...): runs gray-scott with ARGS and expects
# exit status EXIT and TEXT in the named stream.
function(gray_scott_cli_case name exit_status stream text)
  string(JOIN "|" command $<TARGET_FILE:gray-scott> ${ARGN})
  add_test(NAME gray_scott.${name}
           COMMAND ${CMAKE_COMMAND} -DEXPECTED_EXIT=${exit_status}
                   "-DEXPECTED_${stream}_SUBSTRING=${text}" "-DCOMMAND=${command}"
                   -P ${gray_scott_cli_dir}/expect_exit.cmake)
  set_tests_properties(gray_scott.${name} PROPERTIES TIMEOUT 60)
endfunction()

gray_scott_cli_case(help 0 STDOUT "usage: gray-scott" --help)
gray_scott_cli_case(unknown_flag 2 STDERR "unknown option --bogus" --size 8 --bogus)
gray_scott_cli_case(stray_argument 2 STDERR "unexpected argument 64" --size 8 64)
gray_scott_cli_case(missing_value 2 STDERR "--steps needs a value" --steps)
gray_scott_cli_case(size_not_integer 2 STDERR "--size abc: not an integer" --size abc)
gray_scott_cli_case(size_too_small 2 STDERR "--size 3" --size 3)
gray_scott_cli_case(every_zero 2 STDERR "--every 0" --every 0)
gray_scott_cli_case(feed_not_finite 2 STDERR "--F nan" --F nan)
gray_scott_cli_case(kill_negative 2 STDERR "k = -0.1" --k -0.1)
gray_scott_cli_case(image_size_malformed 2 STDERR "--image-size 32" --image-size 32)
gray_scott_cli_case(elevation_out_of_range 2 STDERR "--elevation 95" --elevation 95)
# Du = 0.2 is the textbook 2D value; in 3D with dt = 1 explicit Euler diverges, so it is refused.
gray_scott_cli_case(unstable_diffusion 2 STDERR "Du = 0.2" --Du 0.2)
# A configuration libinsitu rejects is a usage error naming the key; a missing file too.
set(gray_scott_bad_config ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_bad_config.json)
file(WRITE ${gray_scott_bad_config} [=[{"every": 0}]=])
gray_scott_cli_case(config_invalid 2 STDERR "every" --config ${gray_scott_bad_config})
gray_scott_cli_case(config_missing 2 STDERR "cannot open configuration file"
                    --config ${CMAKE_CURRENT_BINARY_DIR}/no_such_config.json)
# An unknown key is a usage error naming the nearest known one ...
set(gray_scott_typo_config ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_typo_config.json)
file(WRITE ${gray_scott_typo_config} [=[{"views": [{"size": [8, 8]}], "evry": 4}]=])
gray_scott_cli_case(config_typo 2 STDERR "\"evry\" (did you mean \"every\"?)" --size 8
                    --steps 4 --config ${gray_scott_typo_config})
# ... and with "strict": false it does not stop the run, but is named.
set(gray_scott_odd_config ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_odd_config.json)
file(WRITE ${gray_scott_odd_config}
     [=[{"views": [{"size": [8, 8], "zoom": 2}], "every": 4, "strict": false}]=])
gray_scott_cli_case(config_unknown_key 0 STDERR "views[0].zoom" --size 8 --steps 4
                    --config ${gray_scott_odd_config}
                    --out ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_config_unknown_key.cdb)
set_tests_properties(gray_scott.config_unknown_key PROPERTIES
                     FIXTURES_REQUIRED gray_scott_config_unknown_key_clean)
add_test(NAME gray_scott.config_unknown_key_clean
         COMMAND ${CMAKE_COMMAND} -E rm -rf
                 ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_config_unknown_key.cdb)
set_tests_properties(gray_scott.config_unknown_key_clean PROPERTIES
                     FIXTURES_SETUP gray_scott_config_unknown_key_clean)
# Runtime failures exit 1: an archive that cannot be made (its parent is a file) ...
gray_scott_cli_case(archive_unusable 1 STDERR "gray-scott: libinsitu:"
                    --size 8 --steps 1 --out ${CMAKE_CURRENT_LIST_FILE}/run.cdb)
# ... steps that cannot be archived (an archive that already holds them): the run completes and
# then fails with the count and the last error ...
set(gray_scott_twice ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_twice.cdb)
add_test(NAME gray_scott.steps_already_archived_setup
         COMMAND ${CMAKE_COMMAND} -E rm -rf ${gray_scott_twice})
add_test(NAME gray_scott.steps_already_archived_first
         COMMAND gray-scott --size 8 --steps 2 --every 1 --image-size 8x8 --out ${gray_scott_twice})
set_tests_properties(gray_scott.steps_already_archived_setup PROPERTIES
                     FIXTURES_SETUP gray_scott_twice_clean)
set_tests_properties(gray_scott.steps_already_archived_first PROPERTIES
                     FIXTURES_REQUIRED gray_scott_twice_clean FIXTURES_SETUP gray_scott_twice)
# A rerun in the same directory replays archived steps: skipped with one notice, exit 0.
gray_scott_cli_case(steps_already_archived 0 STDOUT "2 steps already in the archive skipped" --size 8 --steps 2
                    --every 1 --image-size 8x8 --out ${gray_scott_twice})
set_tests_properties(gray_scott.steps_already_archived PROPERTIES
                     FIXTURES_REQUIRED gray_scott_twice)
# ... and a libinsitu exception (no OpenCL device matches), caught in main.
gray_scott_cli_case(library_error 1 STDERR "libinsitu:" --size 8 --steps 1
                    --out ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_library_error.cdb)
set_tests_properties(gray_scott.library_error PROPERTIES
                     ENVIRONMENT INSITU_OPENCL_DEVICE=no-such-opencl-device)
