# Tests of insitu-capture (adaptors/capture), included from tests/cli/CMakeLists.txt. They run the
# real binary on the small files make_capture_inputs writes: captures that must write their
# archives, and the command-line contract (exit 2 and one line on stderr naming the flag, value or
# file for bad arguments and bad input; exit 1 for runtime failures). Each run captures 24^3
# volumes into 24x24 images: well under a second on PoCL once the kernels are built.
if(NOT TARGET insitu-capture)
  return()
endif()
set(capture_cli_dir ${CMAKE_CURRENT_LIST_DIR})
set(capture_out ${CMAKE_CURRENT_BINARY_DIR}/insitu_capture)
set(capture_in ${capture_out}/inputs)

add_executable(make_capture_inputs make_capture_inputs.cpp)
target_link_libraries(make_capture_inputs PRIVATE insitu_warnings)
if(TARGET insitu_vtk)
  target_link_libraries(make_capture_inputs PRIVATE VTK::CommonDataModel VTK::IOXML)
  target_compile_definitions(make_capture_inputs PRIVATE INSITU_CAPTURE_INPUTS_WITH_VTK)
endif()
if(TARGET insitu_openvdb)
  target_link_libraries(make_capture_inputs PRIVATE OpenVDB::openvdb)
  target_compile_definitions(make_capture_inputs PRIVATE INSITU_CAPTURE_INPUTS_WITH_OPENVDB)
endif()

# Fixtures: clean (stale archives would be continued, and their steps collide) -> inputs.
add_test(NAME insitu_capture.clean COMMAND ${CMAKE_COMMAND} -E rm -rf ${capture_out})
add_test(NAME insitu_capture.make_inputs COMMAND make_capture_inputs ${capture_in})
set_tests_properties(insitu_capture.clean PROPERTIES FIXTURES_SETUP insitu_capture_clean)
set_tests_properties(insitu_capture.make_inputs PROPERTIES
                     FIXTURES_REQUIRED insitu_capture_clean FIXTURES_SETUP insitu_capture_inputs)

file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/insitu_capture_config.json [=[
{"fields": ["density"],
 "views": [{"azimuth": 30, "elevation": 20, "size": [24, 24]}],
 "transfer_function": {"points": [[0.0, 0, 0, 1, 0], [0.05, 0, 0, 1, 0], [1.0, 1, 0, 0, 0.5]],
                       "unit_length": 1.0},
 "intervals": {"count": 4}, "archive": "overridden.cdb"}
]=])
set(capture_config ${CMAKE_CURRENT_BINARY_DIR}/insitu_capture_config.json)
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/insitu_capture_bad_config.json [=[{"every": 0}]=])
# Names neither a field nor a transfer function: the file's only array, coloured from its values.
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/insitu_capture_unnamed_config.json [=[
{"views": [{"size": [24, 24]}], "intervals": {"count": 4}}
]=])
set(unnamed_config --config ${CMAKE_CURRENT_BINARY_DIR}/insitu_capture_unnamed_config.json)

# capture_case(NAME EXIT status STDOUT|STDERR text [FILES names... [COUNT n]] ARGS arguments...):
# runs insitu-capture with ARGS in the output folder and expects the exit status and the text in
# the named stream. FILES (relative to the archive NAME.cdb, passed as --out unless NO_OUT) must
# then exist; COUNT: exactly n previews.
function(capture_case name)
  cmake_parse_arguments(PARSE_ARGV 1 case "NO_OUT" "EXIT;STDOUT;STDERR;COUNT" "FILES;ARGS")
  set(archive ${capture_out}/${name}.cdb)
  set(arguments ${case_ARGS})
  if(NOT case_NO_OUT)
    list(PREPEND arguments --out ${archive})
  endif()
  string(JOIN "|" command $<TARGET_FILE:insitu-capture> ${arguments})
  if(DEFINED case_STDOUT)
    set(expected_text "-DEXPECTED_STDOUT_SUBSTRING=${case_STDOUT}")
  else()
    set(expected_text "-DEXPECTED_STDERR_SUBSTRING=${case_STDERR}")
  endif()
  add_test(NAME insitu_capture.${name}
           COMMAND ${CMAKE_COMMAND} -DEXPECTED_EXIT=${case_EXIT} ${expected_text}
                   "-DCOMMAND=${command}" -P ${capture_cli_dir}/expect_exit.cmake
           WORKING_DIRECTORY ${capture_out})
  set_tests_properties(insitu_capture.${name} PROPERTIES
                       FIXTURES_REQUIRED insitu_capture_inputs TIMEOUT 60)
  if(DEFINED case_FILES)
    string(JOIN "|" files ${case_FILES})
    set(count_arguments)
    if(DEFINED case_COUNT)
      set(count_arguments -DEXPECTED_COUNT=${case_COUNT} -DPATTERN=previews/*.png)
    endif()
    add_test(NAME insitu_capture.${name}.files
             COMMAND ${CMAKE_COMMAND} -DDIRECTORY=${archive} "-DFILES=${files}"
                     ${count_arguments} -P ${capture_cli_dir}/check_files.cmake)
    set_tests_properties(insitu_capture.${name} PROPERTIES FIXTURES_SETUP insitu_capture_${name})
    set_tests_properties(insitu_capture.${name}.files PROPERTIES
                         FIXTURES_REQUIRED insitu_capture_${name})
  endif()
endfunction()

set(config --config ${capture_config})
set(raw_be --raw-dims 24,24,24 --raw-type float32 --raw-big-endian --raw-spacing 0.5,0.5,1)

# Captures that must write their archives.
capture_case(help NO_OUT EXIT 0 STDOUT "usage: insitu-capture" ARGS --help)
capture_case(raw_big_endian EXIT 0 STDOUT "2 of 2 steps archived (0 skipped"
  FILES manifest.json data.csv proxies/step000000_view0.exr previews/step000001_view0.png COUNT 2
  ARGS ${config} ${raw_be} ${capture_in}/blob_be.f32 ${capture_in}/blob_be.f32)
capture_case(raw_uint16_first_step EXIT 0 STDOUT "1 of 1 steps archived"
  FILES previews/step000005_view0.png COUNT 1
  ARGS ${config} --raw-dims 24,24,24 --raw-type uint16 --first-step 5 ${capture_in}/blob.u16)
# Bad arguments: exit 2 and one line naming the culprit.
capture_case(unknown_flag EXIT 2 STDERR "unknown option \"--bogus\"" ARGS ${config} --bogus x.raw)
capture_case(missing_config EXIT 2 STDERR "missing required option --config" ARGS x.raw)
capture_case(no_inputs EXIT 2 STDERR "no INPUT files given" ARGS ${config})
capture_case(bad_raw_type EXIT 2 STDERR "--raw-type: unsupported raw type \"float16\""
  ARGS ${config} --raw-dims 24,24,24 --raw-type float16 ${capture_in}/blob.u16)
capture_case(raw_needs_dims EXIT 2
  STDERR "blob.u16\" is not .vti, .pvd or .vdb, so it is read as raw, which needs --raw-dims"
  ARGS ${config} ${capture_in}/blob.u16)
capture_case(raw_type_needs_dims EXIT 2 STDERR "--raw-type needs --raw-dims"
  ARGS ${config} --raw-type uint16 ${capture_in}/blob.u16)
capture_case(bad_dims_value EXIT 2 STDERR "--raw-dims: expected an integer >= 1, got \"0\""
  ARGS ${config} --raw-dims 24,0,24 --raw-type uint16 ${capture_in}/blob.u16)
capture_case(wrong_raw_size EXIT 2
  STDERR "blob.u16\" has 27648 bytes but raw dims 24,24,25 uint16 need 28800"
  ARGS ${config} --raw-dims 24,24,25 --raw-type uint16 ${capture_in}/blob.u16)
capture_case(bad_on_error EXIT 2 STDERR "--on-error: expected stop or skip, got \"ignore\""
  ARGS ${config} --on-error ignore ${capture_in}/blob.u16)
capture_case(invalid_config EXIT 2 STDERR "every"
  ARGS --config ${CMAKE_CURRENT_BINARY_DIR}/insitu_capture_bad_config.json ${raw_be}
       ${capture_in}/blob_be.f32)
capture_case(missing_input_stops EXIT 2 STDERR "absent.f32\"" ARGS ${config} ${raw_be}
  ${capture_in}/absent.f32)
capture_case(not_a_vdb EXIT 2 STDERR "not_a_vdb.vdb" ARGS ${config} ${capture_in}/not_a_vdb.vdb)
# Not the user's input: no OpenCL device matches, exit status 1.
capture_case(no_opencl_device EXIT 1 STDERR "matches no OpenCL device"
  ARGS ${config} ${raw_be} ${capture_in}/blob_be.f32)
set_tests_properties(insitu_capture.no_opencl_device PROPERTIES
                     ENVIRONMENT INSITU_OPENCL_DEVICE=no-such-opencl-device)

if(TARGET insitu_vtk)
  # The .pvd lists its files in reverse; steps follow the timesteps, so points_0 is step 0.
  capture_case(pvd_series EXIT 0 STDOUT "3 of 3 steps archived"
    FILES manifest.json previews/step000000_view0.png previews/step000002_view0.png COUNT 3
    ARGS ${config} ${capture_in}/series.pvd)
  capture_case(vti_point_and_cell EXIT 0 STDOUT "2 of 2 steps archived" COUNT 2
    FILES previews/step000000_view0.png previews/step000001_view0.png
    ARGS ${config} ${capture_in}/points_0.vti ${capture_in}/cells.vti)
  # A file that cannot be read stops the run with exit 2, and the archive keeps the step before.
  capture_case(truncated_vti_stops EXIT 2
    STDERR "truncated.vti\": VTK could not read it"
    FILES manifest.json previews/step000000_view0.png COUNT 1
    ARGS ${config} ${capture_in}/points_0.vti ${capture_in}/truncated.vti
         ${capture_in}/points_1.vti)
  # ... or is skipped and named, the run going on.
  capture_case(truncated_vti_skipped EXIT 0 STDOUT "2 of 3 steps archived (1 skipped"
    FILES previews/step000000_view0.png previews/step000002_view0.png COUNT 2
    ARGS ${config} --on-error skip ${capture_in}/points_0.vti ${capture_in}/truncated.vti
         ${capture_in}/points_1.vti)
  capture_case(truncated_vti_skipped_named EXIT 0 STDERR "skipped: \"${capture_in}/truncated.vti\": VTK could not read it"
    ARGS ${config} --on-error skip ${capture_in}/truncated.vti ${capture_in}/points_1.vti)
  # Its only array, not marked as the active scalars, captured without naming it (issue 17).
  capture_case(vti_only_array EXIT 0 STDOUT "2 of 2 steps archived (0 skipped, 0 not selected by the cadence, 0 dropped) in"
    FILES proxies/step000001_view0.exr
    ARGS ${unnamed_config} ${capture_in}/points_0.vti ${capture_in}/points_1.vti)
  capture_case(vti_only_array_named EXIT 0 STDOUT "field \"density\" (named by the first file)"
    ARGS ${unnamed_config} ${capture_in}/points_0.vti)
  capture_case(missing_array EXIT 2 STDERR "no array \"pressure\" in point or cell data"
    ARGS ${config} --field pressure ${capture_in}/points_0.vti)
endif()

if(TARGET insitu_openvdb)
  capture_case(vdb_fog EXIT 0 STDOUT "2 of 2 steps archived" COUNT 2
    FILES previews/step000000_view0.png previews/step000001_view0.png
    ARGS ${config} ${capture_in}/fog_0.vdb ${capture_in}/fog_1.vdb)
  capture_case(vdb_level_set EXIT 0 STDOUT "layers at the level set's zero crossing"
    FILES proxies/step000000_view0.exr
    ARGS ${config} --field surface ${capture_in}/sphere.vdb)
  capture_case(vdb_only_grid EXIT 0 STDOUT "field \"surface\" (named by the first file), layers"
    FILES proxies/step000000_view0.exr
    ARGS ${unnamed_config} ${capture_in}/sphere.vdb)
  capture_case(vdb_missing_grid EXIT 2 STDERR "no grid named \"temperature\" (grids: density"
    ARGS ${config} --field temperature ${capture_in}/fog_0.vdb)
  capture_case(not_a_vdb_skipped EXIT 0 STDOUT "1 of 2 steps archived (1 skipped"
    ARGS ${config} --on-error skip ${capture_in}/not_a_vdb.vdb ${capture_in}/fog_0.vdb)
endif()

# The VTK example end to end: vtk-heat archives steps 10 and 20 in situ and writes them as .vti
# with a .pvd; insitu-capture turns that collection into an archive offline, same configuration.
if(TARGET vtk-heat)
  file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/vtk_heat_config.json [=[
{"fields": ["temperature"], "views": [{"azimuth": 30, "elevation": 25, "size": [24, 24]}],
 "transfer_function": {"points": [[0.0, 0, 0, 1, 0], [0.02, 0, 0, 1, 0], [0.3, 1, 0.5, 0, 1.0]],
                       "unit_length": 0.05},
 "intervals": {"count": 4}}
]=])
  set(heat_config ${CMAKE_CURRENT_BINARY_DIR}/vtk_heat_config.json)
  add_test(NAME vtk_heat.run
           COMMAND vtk-heat ${capture_out}/vtk_heat.cdb --size 16 --steps 20 --every 10
                   --config ${heat_config} --write-vti ${capture_out}/vtk_heat_vti)
  set_tests_properties(vtk_heat.run PROPERTIES FIXTURES_REQUIRED insitu_capture_clean
                       FIXTURES_SETUP vtk_heat_run TIMEOUT 60)
  add_test(NAME vtk_heat.archive
           COMMAND ${CMAKE_COMMAND} -DDIRECTORY=${capture_out}/vtk_heat.cdb
                   "-DFILES=previews/step000010_view0.png|previews/step000020_view0.png"
                   -DEXPECTED_COUNT=2 -DPATTERN=previews/*.png
                   -P ${capture_cli_dir}/check_files.cmake)
  set_tests_properties(vtk_heat.archive PROPERTIES FIXTURES_REQUIRED vtk_heat_run)
  capture_case(vtk_heat_offline EXIT 0 STDOUT "2 of 2 steps archived"
    FILES previews/step000000_view0.png previews/step000001_view0.png COUNT 2
    ARGS --config ${heat_config} ${capture_out}/vtk_heat_vti/heat.pvd)
  set_tests_properties(insitu_capture.vtk_heat_offline PROPERTIES
                       FIXTURES_REQUIRED "insitu_capture_inputs;vtk_heat_run")
endif()
