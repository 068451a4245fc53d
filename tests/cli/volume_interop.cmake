# The compressed field read by a tool other than libinsitu (issue 40), included from
# tests/cli/CMakeLists.txt: insitu-capture archives a field with "volume" (odd sizes, NaN and Inf
# samples), dump_volume writes what ArchiveReader::load_volume gives, and volume_interop.py
# decodes the archive's block files with zfpy (Debian python3-zfpy, which scripts/setup
# installs) and compares both, and the original within the tolerance. No zfpy: the test fails.
if(NOT TARGET insitu-capture)
  return()
endif()
set(INSITU_SYSTEM_PYTHON /usr/bin/python3 CACHE FILEPATH "Python with Debian's numpy and zfpy")
set(interop_script ${CMAKE_CURRENT_LIST_DIR}/volume_interop.py)
set(interop_out ${CMAKE_CURRENT_BINARY_DIR}/volume_interop)
set(interop_input ${interop_out}/field_37x30x23.f32)
set(interop_archive ${interop_out}/run.cdb)

add_executable(dump_volume dump_volume.cpp)
target_link_libraries(dump_volume PRIVATE insitu insitu_warnings)

file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/volume_interop_config.json [=[
{"fields": ["density"], "views": [{"azimuth": 30, "elevation": 20, "size": [24, 24]}],
 "intervals": {"count": 4}, "volume": {"codec": "zfp", "tolerance": 0.002}}
]=])

# Fixtures: clean -> input -> capture -> dump -> zfpy's check.
add_test(NAME volume_interop.clean COMMAND ${CMAKE_COMMAND} -E rm -rf ${interop_out})
add_test(NAME volume_interop.make_input
         COMMAND ${INSITU_SYSTEM_PYTHON} ${interop_script} make
                 ${interop_input})
add_test(NAME volume_interop.capture
         COMMAND insitu-capture --config ${CMAKE_CURRENT_BINARY_DIR}/volume_interop_config.json
                 --out ${interop_archive} --raw-dims 37,30,23 --raw-type float32 ${interop_input})
add_test(NAME volume_interop.dump
         COMMAND dump_volume ${interop_archive} 0 density ${interop_out}/load_volume.f32)
add_test(NAME volume_interop.zfpy
         COMMAND ${INSITU_SYSTEM_PYTHON} ${interop_script} check ${interop_archive} 0
                 ${interop_out}/load_volume.f32 ${interop_input})
set_tests_properties(volume_interop.clean PROPERTIES FIXTURES_SETUP volume_interop_clean)
set_tests_properties(volume_interop.make_input PROPERTIES FIXTURES_REQUIRED volume_interop_clean
                     FIXTURES_SETUP volume_interop_input)
set_tests_properties(volume_interop.capture PROPERTIES FIXTURES_REQUIRED volume_interop_input
                     FIXTURES_SETUP volume_interop_archive TIMEOUT 60)
set_tests_properties(volume_interop.dump PROPERTIES FIXTURES_REQUIRED volume_interop_archive
                     FIXTURES_SETUP volume_interop_dump)
set_tests_properties(volume_interop.zfpy PROPERTIES FIXTURES_REQUIRED volume_interop_dump
                     PASS_REGULAR_EXPRESSION "equal to load_volume")
