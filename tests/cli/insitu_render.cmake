# Tests of the insitu-render CLI (libinsitu/tools/insitu_render.cpp), included from
# tests/cli/CMakeLists.txt. They run the real binary on small raw volumes written by
# make_raw_volume: renders that must write their images, and the command-line contract (exit 2
# and one line on stderr naming the flag or value for bad arguments and bad input).
set(insitu_render_cli_dir ${CMAKE_CURRENT_LIST_DIR})
set(insitu_render_data ${CMAKE_CURRENT_LIST_DIR}/data)
set(insitu_render_out ${CMAKE_CURRENT_BINARY_DIR}/insitu_render)

add_executable(make_raw_volume make_raw_volume.cpp)
target_link_libraries(make_raw_volume PRIVATE insitu)
target_link_libraries(make_raw_volume PRIVATE insitu_warnings)

# Fixtures: clean (stale images from an earlier run cannot pass) -> volumes -> each render -> its
# file check. Volumes are tiny, so every render takes well under a second on PoCL.
set(volume_f32 ${insitu_render_out}/ramp_32x24x16_float32.raw)
set(volume_u8 ${insitu_render_out}/ramp_20x20x20_uint8.raw)
add_test(NAME insitu_render.clean COMMAND ${CMAKE_COMMAND} -E rm -rf ${insitu_render_out})
add_test(NAME insitu_render.make_float32_volume
         COMMAND make_raw_volume ${volume_f32} 32,24,16 float32)
add_test(NAME insitu_render.make_uint8_volume COMMAND make_raw_volume ${volume_u8} 20,20,20 uint8)
set_tests_properties(insitu_render.clean PROPERTIES FIXTURES_SETUP insitu_render_clean)
set_tests_properties(insitu_render.make_float32_volume insitu_render.make_uint8_volume PROPERTIES
                     FIXTURES_REQUIRED insitu_render_clean
                     FIXTURES_SETUP insitu_render_volumes)

# insitu_render_case(NAME EXIT status STDOUT|STDERR text [FILES names...] ARGS arguments...):
# runs insitu-render with ARGS in the output folder, expects exit status and text in the named
# stream; FILES (relative to the output folder) must then exist, be non-empty and, for PNG, be
# PNG (checked by a second test, insitu_render.NAME.files).
function(insitu_render_case name)
  cmake_parse_arguments(PARSE_ARGV 1 case "" "EXIT;STDOUT;STDERR" "FILES;ARGS")
  string(JOIN "|" command $<TARGET_FILE:insitu-render> ${case_ARGS})
  if(DEFINED case_STDOUT)
    set(expected_text "-DEXPECTED_STDOUT_SUBSTRING=${case_STDOUT}")
  else()
    set(expected_text "-DEXPECTED_STDERR_SUBSTRING=${case_STDERR}")
  endif()
  add_test(NAME insitu_render.${name}
           COMMAND ${CMAKE_COMMAND} -DEXPECTED_EXIT=${case_EXIT} ${expected_text}
                   "-DCOMMAND=${command}" -P ${insitu_render_cli_dir}/expect_exit.cmake
           WORKING_DIRECTORY ${insitu_render_out})
  set_tests_properties(insitu_render.${name} PROPERTIES
                       FIXTURES_REQUIRED insitu_render_volumes TIMEOUT 60)
  if(DEFINED case_FILES)
    string(JOIN "|" files ${case_FILES})
    add_test(NAME insitu_render.${name}.files
             COMMAND ${CMAKE_COMMAND} -DDIRECTORY=${insitu_render_out} "-DFILES=${files}"
                     -P ${insitu_render_cli_dir}/check_files.cmake)
    set_tests_properties(insitu_render.${name} PROPERTIES FIXTURES_SETUP insitu_render_${name})
    set_tests_properties(insitu_render.${name}.files PROPERTIES
                         FIXTURES_REQUIRED insitu_render_${name})
  endif()
endfunction()

set(f32_input --raw ${volume_f32} --dims 32,24,16 --type float32
              --tf ${insitu_render_data}/tf_unit_range.json)

# Successful renders: the summary line names the output, and the files are there.
insitu_render_case(help EXIT 0 STDOUT "usage: insitu-render" ARGS --help)
insitu_render_case(png_orthographic EXIT 0 STDOUT "-> ortho.png" FILES ortho.png
  ARGS ${f32_input} --size 64x48 --azimuth 30 --elevation -20 --out ortho.png)
insitu_render_case(exr_perspective_shaded_with_depth EXIT 0
  STDOUT "-> perspective.exr, depth -> perspective_depth.exr"
  FILES perspective.exr perspective_depth.exr
  ARGS ${f32_input} --camera perspective --fov 40 --shade --step 0.5 --early-termination 2
       --spacing 1,1,2 --origin -1,-1,-1 --size 48x48
       --out perspective.exr --depth-out perspective_depth.exr)
insitu_render_case(uint8_png EXIT 0 STDOUT "-> uint8.png" FILES uint8.png
  ARGS --raw ${volume_u8} --dims 20,20,20 --type uint8
       --tf ${insitu_render_data}/tf_byte_range.json --size=40x40 --elevation=90 --out uint8.png)

# Bad arguments and bad input: exit status 2 and one line naming the culprit.
insitu_render_case(unknown_flag EXIT 2 STDERR "unknown option \"--bogus\""
  ARGS ${f32_input} --bogus --out out.png)
insitu_render_case(bad_dims EXIT 2 STDERR "--dims: expected a positive integer, got \"x\""
  ARGS --raw ${volume_f32} --dims 10,x,3 --type float32
       --tf ${insitu_render_data}/tf_unit_range.json --out out.png)
insitu_render_case(wrong_file_size EXIT 2
  STDERR "has 49152 bytes but --dims 32,24,17 --type float32 needs 52224"
  ARGS --raw ${volume_f32} --dims 32,24,17 --type float32
       --tf ${insitu_render_data}/tf_unit_range.json --out out.png)
insitu_render_case(unknown_type EXIT 2 STDERR "--type: unsupported scalar type \"float16\""
  ARGS --raw ${volume_f32} --dims 32,24,16 --type float16
       --tf ${insitu_render_data}/tf_unit_range.json --out out.png)
insitu_render_case(malformed_tf EXIT 2 STDERR "tf_malformed.json: transfer function: malformed JSON"
  ARGS --raw ${volume_f32} --dims 32,24,16 --type float32
       --tf ${insitu_render_data}/tf_malformed.json --out out.png)
insitu_render_case(jpg_output EXIT 2 STDERR "--out: \"out.jpg\" has an unsupported extension"
  ARGS ${f32_input} --out out.jpg)
insitu_render_case(missing_required_flag EXIT 2 STDERR "missing required option --tf"
  ARGS --raw ${volume_f32} --dims 32,24,16 --type float32 --out out.png)
insitu_render_case(missing_value EXIT 2 STDERR "--out: missing value" ARGS ${f32_input} --out)
insitu_render_case(missing_raw_file EXIT 2 STDERR "--raw \"does_not_exist.raw\""
  ARGS --raw does_not_exist.raw --dims 32,24,16 --type float32
       --tf ${insitu_render_data}/tf_unit_range.json --out out.png)
insitu_render_case(elevation_out_of_range EXIT 2 STDERR "elevation = 100"
  ARGS ${f32_input} --elevation 100 --out out.png)

# Not the user's input: no OpenCL device matches, exit status 1.
insitu_render_case(no_opencl_device EXIT 1 STDERR "matches no OpenCL device"
  ARGS ${f32_input} --out out.png)
set_tests_properties(insitu_render.no_opencl_device PROPERTIES
                     ENVIRONMENT INSITU_OPENCL_DEVICE=no-such-opencl-device)
