# Tests of the web viewer, `insitu-view serve` (viewer/, viewer/web/), included from
# tests/CMakeLists.txt. A small Gray-Scott archive is the fixture; node runs the tests in
# tests/viewer/: browser.test.mjs drives headless Debian chromium through playwright-core
# (installed by scripts/setup into tests/viewer/node_modules) and compares every displayed frame
# with `insitu-view render`; api.test.mjs checks refusals, containment, coalescing and a growing
# archive. Plus the command line of `serve` itself.
if(NOT TARGET gray-scott OR NOT TARGET insitu-view)
  return()  # examples not built (INSITU_BUILD_EXAMPLES=OFF)
endif()
find_program(NODE_EXECUTABLE node)
if(NOT NODE_EXECUTABLE)
  message(WARNING "node not found: the viewer's browser and API tests are not added "
                  "(scripts/setup installs nodejs)")
  return()
endif()

set(viewer_tests_dir ${CMAKE_CURRENT_LIST_DIR}/viewer)
set(viewer_work ${CMAKE_CURRENT_BINARY_DIR}/viewer)
set(viewer_archive ${viewer_work}/viewer.cdb)
set(viewer_config ${CMAKE_CURRENT_BINARY_DIR}/viewer_config.json)
# 32^3 for 20 steps, archived at 10 and 20 in 256x256: every kind of proxy (multi-perspective
# attenuation for orbiting, depth layers for ambient occlusion) and training renderings so a
# colour model is fitted. Well under a second once the kernels are built.
file(WRITE ${viewer_config} [=[
{"fields": ["v"],
 "views": [{"azimuth": 30, "elevation": 20, "size": [256, 256]}],
 "transfer_function": {"points": [[0.0, 0.1, 0.25, 0.75, 0.0], [0.12, 0.1, 0.25, 0.75, 0.0],
                                  [0.2, 0.15, 0.55, 0.9, 0.04], [0.28, 0.35, 0.85, 0.7, 0.1],
                                  [0.36, 0.95, 0.8, 0.3, 0.22], [0.45, 1.0, 0.4, 0.15, 0.4]],
                       "unit_length": 1.0},
 "training_transfer_functions": [
   {"points": [[0.0, 0.9, 0.9, 0.2, 0.0], [0.2, 0.9, 0.3, 0.2, 0.1], [0.45, 0.2, 0.3, 0.9, 0.3]],
    "unit_length": 1.0},
   {"points": [[0.0, 0.2, 0.9, 0.3, 0.0], [0.25, 0.6, 0.6, 0.6, 0.2], [0.45, 0.9, 0.1, 0.1, 0.5]],
    "unit_length": 1.0}],
 "colour_model": {"clusters": 8},
 "intervals": {"count": 8},
 "proxies": ["depth", "distortion", "attenuation", "multi_attenuation", "rendering", "interleaving",
             "entry_depth", "optical_depth"],
 "volume": false,
 "every": 10}
]=])

add_test(NAME viewer.setup_clean COMMAND ${CMAKE_COMMAND} -E rm -rf ${viewer_work})
add_test(NAME viewer.setup_work COMMAND ${CMAKE_COMMAND} -E make_directory ${viewer_work})
add_test(NAME viewer.setup_archive
         COMMAND gray-scott --size 32 --steps 20 --config ${viewer_config} --out ${viewer_archive})
set_tests_properties(viewer.setup_clean PROPERTIES FIXTURES_SETUP viewer_clean)
set_tests_properties(viewer.setup_work PROPERTIES
                     FIXTURES_REQUIRED viewer_clean FIXTURES_SETUP viewer_work)
set_tests_properties(viewer.setup_archive PROPERTIES
                     FIXTURES_REQUIRED viewer_work FIXTURES_SETUP viewer_archive TIMEOUT 120)

set(viewer_environment
    INSITU_VIEW=$<TARGET_FILE:insitu-view> GRAY_SCOTT=$<TARGET_FILE:gray-scott>
    ARCHIVE=${viewer_archive} WORK_DIR=${viewer_work})
# The drag's frame budget (viewer/web/frame_cost.js) needs neither a browser nor an archive.
add_test(NAME viewer.frame_cost
         COMMAND ${NODE_EXECUTABLE} --test-reporter=spec ${viewer_tests_dir}/frame_cost.test.mjs
         WORKING_DIRECTORY ${viewer_tests_dir})
set_tests_properties(viewer.frame_cost PROPERTIES TIMEOUT 60)
# index.html preloads every module of the page (the first frame waits for them all).
add_test(NAME viewer.page_modules
         COMMAND ${NODE_EXECUTABLE} --test-reporter=spec ${viewer_tests_dir}/page_modules.test.mjs
         WORKING_DIRECTORY ${viewer_tests_dir})
set_tests_properties(viewer.page_modules PROPERTIES TIMEOUT 60)
add_test(NAME viewer.gpu_frames
         COMMAND ${NODE_EXECUTABLE} --test-reporter=spec ${viewer_tests_dir}/gpu_frames.test.mjs
         WORKING_DIRECTORY ${viewer_tests_dir})
set_tests_properties(viewer.gpu_frames PROPERTIES TIMEOUT 60)

# Also on this archive, which has a colour model and no light field, frames the page draws
# (WebGL2 through chromium's SwiftShader): colour_model.test.mjs edits opacity and compares the
# canvas with `insitu-view render`; confidence.test.mjs compares the page's confidence overlay
# with `render --mask`. The archive stores every proxy an edit's trust and estimate read (the
# rendering, interleaving, entry and optical depth), so both sides take every term.
foreach(suite IN ITEMS browser api colour_model confidence timeline meaning)
  add_test(NAME viewer.${suite}
           COMMAND ${NODE_EXECUTABLE} --test-reporter=spec ${viewer_tests_dir}/${suite}.test.mjs
           WORKING_DIRECTORY ${viewer_tests_dir})
  # Each takes about 5-10 s on 2 cores; the limit leaves room for a loaded machine.
  set_tests_properties(viewer.${suite} PROPERTIES
                       FIXTURES_REQUIRED viewer_archive
                       ENVIRONMENT "${viewer_environment}"
                       TIMEOUT 180)
endforeach()

# The 40^3 Gray-Scott run archived at steps 300 and 600 (half the image covered by then) in
# 160^2 with 8 intervals and the light field `light_field` (its JSON object) beside the stored
# view's proxies: archive viewer_NAME.cdb, fixture viewer_NAME_archive (about 1-2 s). The
# object may come in parts (joined).
function(viewer_light_field_archive name)
  string(JOIN "" light_field ${ARGN})
  set(config ${CMAKE_CURRENT_BINARY_DIR}/viewer_${name}_config.json)
  file(WRITE ${config} [=[
{"fields": ["v"],
 "views": [{"azimuth": 30, "elevation": 20, "size": [160, 160]}],
 "transfer_function": {"points": [[0.0, 0.1, 0.25, 0.75, 0.0], [0.12, 0.1, 0.25, 0.75, 0.0],
                                  [0.2, 0.15, 0.55, 0.9, 0.04], [0.28, 0.35, 0.85, 0.7, 0.1],
                                  [0.36, 0.95, 0.8, 0.3, 0.22], [0.45, 1.0, 0.4, 0.15, 0.4]],
                       "unit_length": 1.0},
 "intervals": {"count": 8},
 "every": 300,
 "volume": false,
 "light_field": ]=] "${light_field}}\n")
  add_test(NAME viewer.setup_${name}_archive
           COMMAND gray-scott --size 40 --steps 600 --config ${config}
                   --out ${viewer_work}/viewer_${name}.cdb)
  set_tests_properties(viewer.setup_${name}_archive PROPERTIES
                       FIXTURES_REQUIRED viewer_work FIXTURES_SETUP viewer_${name}_archive
                       TIMEOUT 120)
endfunction()

# A browser test tests/viewer/SUITE.test.mjs on the archive viewer_NAME.cdb (ctest viewer.SUITE),
# with more environment (KEY=VALUE) and fixtures after the name.
function(viewer_browser_test suite name)
  cmake_parse_arguments(PARSE_ARGV 2 arg "" "" "ENVIRONMENT;FIXTURES")
  add_test(NAME viewer.${suite}
           COMMAND ${NODE_EXECUTABLE} --test-reporter=spec ${viewer_tests_dir}/${suite}.test.mjs
           WORKING_DIRECTORY ${viewer_tests_dir})
  set(environment INSITU_VIEW=$<TARGET_FILE:insitu-view> ARCHIVE=${viewer_work}/viewer_${name}.cdb
                  WORK_DIR=${viewer_work} ${arg_ENVIRONMENT})
  set_tests_properties(viewer.${suite} PROPERTIES
                       FIXTURES_REQUIRED "viewer_${name}_archive;${arg_FIXTURES}"
                       ENVIRONMENT "${environment}"
                       TIMEOUT 180)
endfunction()

# The browser's own frames (WebGL2 through chromium's SwiftShader), on an archive with a light
# field of 42 cameras at 128^2 and 8-bit depth with the rims' depth: webgl.test.mjs compares
# orbit views (also relit and occluded) and the confidence overlay with `insitu-view render
# --source lightfield` and checks the fallback without WebGL2. (Before a camera on its own rim
# stopped passing by, page and reference read rim hits on a texel's edge from different sides:
# 81 overlay bytes differed by up to 236.)
set(viewer_lf_archive ${viewer_work}/viewer_lf.cdb)
viewer_light_field_archive(lf [=[{"cameras": 42, "size": 128, "attenuation": false}]=])
viewer_light_field_archive(lf_rims [=[{"cameras": 42, "size": 128, "attenuation": false,]=]
                           [=[ "rim_threshold": 0.05}]=])
viewer_browser_test(webgl lf_rims)

# The stored view drawn by the page from its single-perspective proxies (/api/proxies,
# /api/recipe): proxies.test.mjs edits, relights, occludes, enhances and changes the step on the
# same archive, comparing the canvas with `insitu-view render` each time.
viewer_browser_test(proxies lf)

# Edits through an attenuation light field (issue 15): the same run with the light field's a_j
# and mean depths per camera; light_field_edits.test.mjs edits opacity and colour, relights,
# occludes and enhances an orbit view in the page, comparing the canvas with
# `insitu-view render --source lightfield` each time. Without rims (they are on by default), so
# that the page's reconstruction without them, as archives written before hold, stays tested.
# 162 cameras, as the default rig has, at 64^2 (the texels of the other suites' 42 at 128^2).
viewer_light_field_archive(lf_attenuation [=[{"cameras": 162, "size": 64, "attenuation": true,]=]
                           [=[ "rim_threshold": 0}]=])
viewer_browser_test(light_field_edits lf_attenuation)
# The light field fetched by need and streamed (issues 41, 42): streaming.test.mjs edits the
# stored view of a new step without it, then orbits: the cameras around the view first.
viewer_browser_test(streaming lf_attenuation)
# The light field's depth search walks a map pixel at a time where a crossing may lie (issue 41):
# in SwiftShader this suite took 79 s alone and 147 s beside the other viewer tests on the shared
# 2-core machine, so the light-field suites get more than the default's 180 s.
set_tests_properties(viewer.webgl viewer.light_field_edits viewer.streaming PROPERTIES TIMEOUT 300)

# Per-segment fades (issue 15): the same run with its light field split at opacity 0.5 into two
# segments, depth in half floats, the rims' depth; segments.test.mjs moves the page's faders and
# compares the canvas with `insitu-view render --source lightfield --segment-opacity`, checks the
# refusals of bad segment-opacity values, and that the faders are hidden for the archives above
# (no light field; one segment).
viewer_light_field_archive(lf_segments [=[{"cameras": 42, "size": 128, "attenuation": false,]=]
                           [=[ "segments": [0.5], "depth_bits": 16, "rim_threshold": 0.05}]=])
viewer_browser_test(segments lf_segments
                    ENVIRONMENT ARCHIVE_ONE_SEGMENT=${viewer_lf_archive}
                                ARCHIVE_NO_LIGHT_FIELD=${viewer_archive}
                    FIXTURES viewer_archive viewer_lf_archive)

# The compressed field (issue 40): the same 40^3 run archived at steps 300 and 600 with the
# view's proxies and its field compressed by ZFP at accuracy 1e-3 (the "volume" configuration);
# volume.test.mjs orbits, edits the function, shades, changes the step and drags in the page,
# which ray-marches the field, comparing the canvas with `insitu-view render --source volume`.
set(viewer_volume_config ${CMAKE_CURRENT_BINARY_DIR}/viewer_volume_config.json)
file(WRITE ${viewer_volume_config} [=[
{"fields": ["v"],
 "views": [{"azimuth": 30, "elevation": 20, "size": [160, 160]}],
 "transfer_function": {"points": [[0.0, 0.1, 0.25, 0.75, 0.0], [0.12, 0.1, 0.25, 0.75, 0.0],
                                  [0.2, 0.15, 0.55, 0.9, 0.04], [0.28, 0.35, 0.85, 0.7, 0.1],
                                  [0.36, 0.95, 0.8, 0.3, 0.22], [0.45, 1.0, 0.4, 0.15, 0.4]],
                       "unit_length": 1.0},
 "intervals": {"count": 8},
 "every": 300,
 "volume": {"codec": "zfp", "tolerance": 0.001}}
]=])
add_test(NAME viewer.setup_volume_archive
         COMMAND gray-scott --size 40 --steps 600 --config ${viewer_volume_config}
                 --out ${viewer_work}/viewer_volume.cdb)
set_tests_properties(viewer.setup_volume_archive PROPERTIES
                     FIXTURES_REQUIRED viewer_work FIXTURES_SETUP viewer_volume_archive
                     TIMEOUT 120)
viewer_browser_test(volume volume)

# serve's command line: exit 2 and one line on stderr for bad arguments or archives.
function(viewer_serve_case name exit_status stream text)
  string(JOIN "|" command $<TARGET_FILE:insitu-view> serve ${ARGN})
  add_test(NAME viewer.serve_${name}
           COMMAND ${CMAKE_COMMAND} -DEXPECTED_EXIT=${exit_status}
                   "-DEXPECTED_${stream}_SUBSTRING=${text}" "-DCOMMAND=${command}"
                   -P ${CMAKE_CURRENT_LIST_DIR}/cli/expect_exit.cmake)
  set_tests_properties(viewer.serve_${name} PROPERTIES TIMEOUT 60)
endfunction()
viewer_serve_case(missing_archive 2 STDERR "serve: missing ARCHIVE")
viewer_serve_case(no_such_archive 2 STDERR "no_such.cdb" ${viewer_work}/no_such.cdb)
viewer_serve_case(port_not_a_number 2 STDERR "--port http" some.cdb --port http)
viewer_serve_case(port_out_of_range 2 STDERR "--port 70000" some.cdb --port 70000)
viewer_serve_case(port_missing_value 2 STDERR "--port: missing value" some.cdb --port)
viewer_serve_case(unknown_flag 2 STDERR "unknown flag --open" some.cdb --open)
viewer_serve_case(two_archives 2 STDERR "unexpected argument" a.cdb b.cdb)
# Without a usable OpenCL device it cannot serve: exit 1, naming the device setting.
viewer_serve_case(no_opencl_device 1 STDERR "INSITU_OPENCL_DEVICE" ${viewer_archive} --port 0)
set_tests_properties(viewer.serve_no_opencl_device PROPERTIES
                     ENVIRONMENT INSITU_OPENCL_DEVICE=no-such-opencl-device
                     FIXTURES_REQUIRED viewer_archive)

# Truthful trust (issue 42): the trusted range of a step with one view, a light field and a
# compressed field; the warning near the picture; the overlay's kinds of pixel and its legend.
viewer_browser_test(trust volume
                    ENVIRONMENT ARCHIVE_LIGHT_FIELD=${viewer_lf_archive}
                                ARCHIVE_ONE_VIEW=${viewer_archive}
                    FIXTURES viewer_archive viewer_lf_archive)

# Galleries (issue 46): `insitu-view export` of the light-field run served by Python's
# http.server; gallery.test.mjs holds the page's frames there (stored view, orbit, lights and
# occlusion whose terms the page computes, the next step), of the compressed-field run (orbit, an
# edited function) and of the attenuation light-field run (an orbit view recoloured and edited on
# the light field's intervals) to `insitu-view render`, checks that no request leaves the
# gallery, that the page's recipes are serve's, that the same archive exports to the same bytes
# and that a damaged step is left out and listed.
viewer_browser_test(gallery lf ENVIRONMENT ARCHIVE_VOLUME=${viewer_work}/viewer_volume.cdb
                                          ARCHIVE_MODEL=${viewer_archive}
                         ARCHIVE_LF_ATTENUATION=${viewer_work}/viewer_lf_attenuation.cdb
                         ARCHIVE_LF_SEGMENTS=${viewer_work}/viewer_lf_segments.cdb
                    FIXTURES viewer_volume_archive viewer_archive viewer_lf_attenuation_archive
                             viewer_lf_segments_archive)
# Four galleries, a dozen frames held to render and serve's recipes: about 2 minutes on 2 loaded
# cores.
set_tests_properties(viewer.gallery PROPERTIES TIMEOUT 480)

# export's command line and bad input: exit 2 and one line on stderr naming the value.
function(viewer_export_case name text)
  string(JOIN "|" command $<TARGET_FILE:insitu-view> export ${ARGN})
  add_test(NAME viewer.export_${name}
           COMMAND ${CMAKE_COMMAND} -DEXPECTED_EXIT=2 "-DEXPECTED_STDERR_SUBSTRING=${text}"
                   "-DCOMMAND=${command}" -P ${CMAKE_CURRENT_LIST_DIR}/cli/expect_exit.cmake)
  set_tests_properties(viewer.export_${name} PROPERTIES TIMEOUT 60 FIXTURES_REQUIRED viewer_archive)
endfunction()
viewer_export_case(missing_out "expected ARCHIVE... and OUT" ${viewer_archive})
viewer_export_case(existing_out "exists (--replace to replace it)" ${viewer_archive} ${viewer_work})
viewer_export_case(replace_foreign "is neither empty nor a gallery" ${viewer_archive}
                   ${viewer_work} --replace)
viewer_export_case(max_bytes_small "--max-bytes 1000: smaller than one step" ${viewer_archive}
                   ${viewer_work}/never_written --max-bytes 1000)
viewer_export_case(max_bytes_bad "--max-bytes 12x" ${viewer_archive} ${viewer_work}/never_written
                   --max-bytes 12x)
viewer_export_case(unknown_step "--steps 35: the archive has no step 35" ${viewer_archive}
                   ${viewer_work}/never_written --steps 35)
viewer_export_case(unknown_view "--views 4" ${viewer_archive} ${viewer_work}/never_written
                   --views 4)
