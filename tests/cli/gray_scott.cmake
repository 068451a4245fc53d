# Tests of the gray-scott mini-app (examples/gray_scott), included from tests/cli/CMakeLists.txt.
# They run the real binary: a tiny simulation that must write its images, and the command-line
# contract (exit 2 and one line on stderr for bad arguments, exit 1 for runtime failures).
if(NOT TARGET gray-scott)
  return()  # examples not built (INSITU_BUILD_EXAMPLES=OFF)
endif()

set(gray_scott_cli_dir ${CMAKE_CURRENT_LIST_DIR})
set(gray_scott_tiny_out ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_tiny)

# A 24^3 box for 20 steps and two 32x32 renders: about a second on PoCL, most of it the kernel
# build. Stale images from an earlier run are removed first so they cannot pass the check.
add_test(NAME gray_scott.tiny_clean COMMAND ${CMAKE_COMMAND} -E rm -rf ${gray_scott_tiny_out})
add_test(NAME gray_scott.tiny_run
         COMMAND gray-scott --size 24 --steps 20 --every 10 --image-size 32x32
                 --out ${gray_scott_tiny_out})
add_test(NAME gray_scott.tiny_images
         COMMAND ${CMAKE_COMMAND} -DDIRECTORY=${gray_scott_tiny_out}
                 "-DFILES=v_step000010.png|v_step000020.png" -DEXPECTED_COUNT=2
                 -DPATTERN=v_step*.png -P ${gray_scott_cli_dir}/check_files.cmake)
set_tests_properties(gray_scott.tiny_clean PROPERTIES FIXTURES_SETUP gray_scott_tiny_clean)
set_tests_properties(gray_scott.tiny_run PROPERTIES
                     FIXTURES_REQUIRED gray_scott_tiny_clean
                     FIXTURES_SETUP gray_scott_tiny_images
                     TIMEOUT 120)
set_tests_properties(gray_scott.tiny_images PROPERTIES FIXTURES_REQUIRED gray_scott_tiny_images)

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
# Runtime failures exit 1: an output folder that cannot be made (its parent is a file) ...
gray_scott_cli_case(output_folder_unusable 1 STDERR "gray-scott:"
                    --size 8 --steps 1 --out ${CMAKE_CURRENT_LIST_FILE}/images)
# ... and a libinsitu exception (no OpenCL device matches), caught in main.
gray_scott_cli_case(library_error 1 STDERR "libinsitu:" --size 8 --steps 1
                    --out ${CMAKE_CURRENT_BINARY_DIR}/gray_scott_library_error)
set_tests_properties(gray_scott.library_error PROPERTIES
                     ENVIRONMENT INSITU_OPENCL_DEVICE=no-such-opencl-device)
