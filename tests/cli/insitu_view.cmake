# Tests of insitu-view (viewer/insitu_view.cpp), included from tests/cli/CMakeLists.txt: a small
# Gray-Scott archive (single + multi-perspective proxies, multi-perspective attenuation, training
# transfer functions so a colour model is fitted), then info, render (stored view, new view,
# edits, lighting, enhancement, mask) and verify, and the command-line contract for bad input.
if(NOT TARGET gray-scott OR NOT TARGET insitu-view)
  return()
endif()

set(view_cli_dir ${CMAKE_CURRENT_LIST_DIR})
set(view_archive ${CMAKE_CURRENT_BINARY_DIR}/insitu_view.cdb)
set(view_output ${CMAKE_CURRENT_BINARY_DIR}/insitu_view_output)
set(view_config ${CMAKE_CURRENT_BINARY_DIR}/insitu_view_config.json)
file(WRITE ${view_config} [=[
{"fields": ["v"],
 "views": [{"azimuth": 30, "elevation": 20, "size": [48, 48], "distortion_tilt": 30}],
 "transfer_function": {"points": [[0.0, 0, 0, 1, 0], [0.1, 0, 0.5, 1, 0.2], [0.4, 1, 0.3, 0, 1]],
                       "unit_length": 1.0},
 "training_transfer_functions": [
   {"points": [[0.0, 0, 0, 1, 0], [0.1, 0, 0.5, 1, 0.05], [0.4, 1, 0.3, 0, 1]], "unit_length": 1.0},
   {"points": [[0.0, 0, 0, 1, 0], [0.1, 0, 0.5, 1, 0.6], [0.4, 1, 0.3, 0, 1]], "unit_length": 1.0}],
 "colour_model": {"clusters": 8},
 "layers": [0.2], "intervals": {"count": 8},
 "proxies": ["depth", "distortion", "attenuation", "multi_attenuation"],
 "precision": "float", "steps": [4, 8], "volume": false}
]=])
set(edited_tf ${CMAKE_CURRENT_BINARY_DIR}/insitu_view_edited_tf.json)
file(WRITE ${edited_tf} [=[
{"points": [[0.0, 0, 0, 1, 0], [0.1, 0, 0.5, 1, 0.05], [0.4, 1, 0.3, 0, 1]], "unit_length": 1.0}
]=])

add_test(NAME insitu_view.setup_clean
         COMMAND ${CMAKE_COMMAND} -E rm -rf ${view_archive} ${view_output})
add_test(NAME insitu_view.setup_output COMMAND ${CMAKE_COMMAND} -E make_directory ${view_output})
add_test(NAME insitu_view.setup_archive
         COMMAND gray-scott --size 24 --steps 8 --config ${view_config} --out ${view_archive})
set_tests_properties(insitu_view.setup_clean PROPERTIES FIXTURES_SETUP insitu_view_clean)
set_tests_properties(insitu_view.setup_output PROPERTIES
                     FIXTURES_REQUIRED insitu_view_clean FIXTURES_SETUP insitu_view_output)
set_tests_properties(insitu_view.setup_archive PROPERTIES
                     FIXTURES_REQUIRED insitu_view_output FIXTURES_SETUP insitu_view_archive
                     TIMEOUT 120)

# archive_case(FIXTURE NAME EXIT STDERR|STDOUT TEXT ARGS...): runs insitu-view ARGS once the
# archive FIXTURE is set up; view_case(NAME ...) on the Gray-Scott archive above.
function(archive_case fixture name exit_status stream text)
  string(JOIN "|" command $<TARGET_FILE:insitu-view> ${ARGN})
  add_test(NAME insitu_view.${name}
           COMMAND ${CMAKE_COMMAND} -DEXPECTED_EXIT=${exit_status}
                   "-DEXPECTED_${stream}_SUBSTRING=${text}" "-DCOMMAND=${command}"
                   -P ${view_cli_dir}/expect_exit.cmake)
  set_tests_properties(insitu_view.${name} PROPERTIES FIXTURES_REQUIRED ${fixture} TIMEOUT 60)
endfunction()
function(view_case name exit_status stream text)
  archive_case(insitu_view_archive ${name} ${exit_status} ${stream} "${text}" ${ARGN})
endfunction()

view_case(help 0 STDOUT "usage:" --help)
view_case(info 0 STDOUT "steps         2 (4 .. 8)" info ${view_archive})
view_case(info_model 0 STDOUT "colour model L=8 K=8" info ${view_archive})
view_case(info_json 0 STDOUT "\"view_count\": 1" info ${view_archive} --json)
view_case(verify 0 STDOUT "0 problems" verify ${view_archive})
view_case(render_stored 0 STDERR "stored view" render ${view_archive} --step 4
          --out ${view_output}/stored.png)
view_case(render_rotated 0 STDERR "new view" render ${view_archive} --step 8 --azimuth 45
          --elevation 10 --mask ${view_output}/rotated_mask.png --out ${view_output}/rotated.exr)
view_case(render_opacity_edit 0 STDERR "colour by model" render ${view_archive} --step 8
          --opacity-scale 1=0.25,2=0.5 --out ${view_output}/opacity.png)
view_case(render_tf_edit 0 STDERR "colour by model" render ${view_archive} --step 8
          --tf ${edited_tf} --out ${view_output}/tf.png)
view_case(render_recompose 0 STDERR "colour by recompose" render ${view_archive} --step 8
          --opacity-scale 1=0.25 --colour recompose --out ${view_output}/recompose.png)
view_case(render_lit 0 STDERR "stored view" render ${view_archive} --step 8 --light camera
          --light 90,30,0.5,0.2 --ao --ao-radius 4 --enhance 0.5,0.5
          --out ${view_output}/lit.png)
add_test(NAME insitu_view.outputs
         COMMAND ${CMAKE_COMMAND} -DDIRECTORY=${view_output}
                 "-DFILES=stored.png|rotated.exr|rotated_mask.png|opacity.png|tf.png|recompose.png|lit.png"
                 -DEXPECTED_COUNT=6 -DPATTERN=*.png -P ${view_cli_dir}/check_files.cmake)
set_tests_properties(insitu_view.outputs PROPERTIES
                     DEPENDS "insitu_view.render_stored;insitu_view.render_rotated;insitu_view.render_opacity_edit;insitu_view.render_tf_edit;insitu_view.render_recompose;insitu_view.render_lit"
                     FIXTURES_REQUIRED insitu_view_archive)

# Bad input: exit 2 and one line naming the offending value.
view_case(no_command 2 STDERR "missing command")
view_case(unknown_command 2 STDERR "unknown command \"show\"" show ${view_archive})
view_case(missing_archive 2 STDERR "no_such.cdb" info ${CMAKE_CURRENT_BINARY_DIR}/no_such.cdb)
view_case(missing_step 2 STDERR "has no step 999" render ${view_archive} --step 999
          --out ${view_output}/never.png)
view_case(missing_view 2 STDERR "has no view 3" render ${view_archive} --step 4 --view 3
          --out ${view_output}/never.png)
view_case(missing_out 2 STDERR "missing --out" render ${view_archive} --step 4)
view_case(unknown_flag 2 STDERR "unknown flag --zoom" render ${view_archive} --step 4 --zoom 2
          --out ${view_output}/never.png)
view_case(bad_scale 2 STDERR "opacity-scale" render ${view_archive} --step 4
          --opacity-scale 1=abc --out ${view_output}/never.png)
view_case(scale_interval_out_of_range 2 STDERR "opacity-scale interval 12" render
          ${view_archive} --step 4 --opacity-scale 12=0.5 --out ${view_output}/never.png)
view_case(bad_elevation 2 STDERR "elevation = 95" render ${view_archive} --step 4
          --elevation 95 --out ${view_output}/never.png)
view_case(bad_enhance 2 STDERR "enhance = \"0.5\"" render ${view_archive} --step 4
          --enhance 0.5 --out ${view_output}/never.png)
view_case(missing_tf_file 2 STDERR "--tf: cannot read" render ${view_archive} --step 4
          --tf ${CMAKE_CURRENT_BINARY_DIR}/no_such_tf.json --out ${view_output}/never.png)
view_case(bad_extension 2 STDERR "never.bmp" render ${view_archive} --step 4
          --out ${view_output}/never.bmp)

# Light fields (issue 14): a Gray-Scott archive with a 12-camera light field split at the layer,
# then info, verify and render from the light field (new view, segment fade, TF edit), fused with
# the view's proxies (auto), and the errors for a segment the light field lacks.
set(lf_archive ${CMAKE_CURRENT_BINARY_DIR}/insitu_view_lf.cdb)
set(lf_config ${CMAKE_CURRENT_BINARY_DIR}/insitu_view_lf_config.json)
set(lf_output ${CMAKE_CURRENT_BINARY_DIR}/insitu_view_lf_output)
file(WRITE ${lf_config} [=[
{"fields": ["v"],
 "views": [{"azimuth": 30, "elevation": 20, "size": [48, 48]}],
 "transfer_function": {"points": [[0.0, 0, 0, 1, 0], [0.1, 0, 0.5, 1, 0.2], [0.4, 1, 0.3, 0, 1]],
                       "unit_length": 1.0},
 "layers": [0.2], "intervals": {"count": 8}, "proxies": ["depth", "attenuation"],
 "steps": [8],
 "volume": false,
 "light_field": {"cameras": 12, "size": 48, "segments": "layers", "depth_bits": 8}}
]=])
add_test(NAME insitu_view.setup_lf_clean
         COMMAND ${CMAKE_COMMAND} -E rm -rf ${lf_archive} ${lf_output})
add_test(NAME insitu_view.setup_lf_output COMMAND ${CMAKE_COMMAND} -E make_directory ${lf_output})
add_test(NAME insitu_view.setup_lf_archive
         COMMAND gray-scott --size 24 --steps 8 --config ${lf_config} --out ${lf_archive})
set_tests_properties(insitu_view.setup_lf_clean PROPERTIES FIXTURES_SETUP insitu_view_lf_clean)
set_tests_properties(insitu_view.setup_lf_output PROPERTIES FIXTURES_REQUIRED insitu_view_lf_clean
                     FIXTURES_SETUP insitu_view_lf_output)
set_tests_properties(insitu_view.setup_lf_archive PROPERTIES
                     FIXTURES_REQUIRED insitu_view_lf_output
                     FIXTURES_SETUP insitu_view_lf_archive TIMEOUT 120)
function(light_field_case name exit_status stream text)
  archive_case(insitu_view_lf_archive ${name} ${exit_status} ${stream} "${text}" ${ARGN})
endfunction()
light_field_case(info_light_field 0 STDOUT
                 "light field   v: 12 cameras, 48^2 maps, 2 segment(s), attenuation yes, depth 8"
                 info ${lf_archive})
light_field_case(verify_light_field 0 STDOUT "0 problems" verify ${lf_archive})
light_field_case(render_light_field 0 STDERR "new view from lightfield" render ${lf_archive}
                 --step 8 --azimuth 200 --elevation -30 --source lightfield
                 --out ${lf_output}/light_field.png)
light_field_case(render_light_field_fade 0 STDERR "new view from lightfield" render
                 ${lf_archive} --step 8 --azimuth 200 --source lightfield --segment-opacity 1=0
                 --out ${lf_output}/light_field_fade.png)
light_field_case(render_light_field_edit 0 STDERR "colour by recompose" render ${lf_archive}
                 --step 8 --azimuth 200 --source lightfield --tf ${edited_tf}
                 --out ${lf_output}/light_field_edit.png)
light_field_case(render_fused 0 STDERR "new view from auto" render ${lf_archive} --step 8
                 --azimuth 120 --out ${lf_output}/fused.png)
light_field_case(render_stored_keeps_proxies 0 STDERR "stored view from single" render
                 ${lf_archive} --step 8 --out ${lf_output}/lf_stored.png)
light_field_case(bad_segment 2 STDERR "segment-opacity segment 5" render ${lf_archive} --step 8
                 --azimuth 200 --source lightfield --segment-opacity 5=0
                 --out ${lf_output}/never.png)
view_case(no_light_field 2 STDERR "has no light field" render ${view_archive} --step 4
          --azimuth 200 --source lightfield --out ${lf_output}/never.png)

# An error budget (issue 17): a Gray-Scott archive whose light field the budget sized, and info
# listing what it chose at the step (the rig, with its measured PSNR), and the rig stored.
set(budget_archive ${CMAKE_CURRENT_BINARY_DIR}/insitu_view_budget.cdb)
set(budget_config ${CMAKE_CURRENT_BINARY_DIR}/insitu_view_budget_config.json)
file(WRITE ${budget_config} [=[
{"fields": ["v"], "views": [{"azimuth": 30, "elevation": 20, "size": [48, 48]}],
 "steps": [8], "light_field": {"attenuation": false},
 "budget": {"psnr_db": 1, "choose": ["light_field"]}}
]=])
add_test(NAME insitu_view.setup_budget_clean COMMAND ${CMAKE_COMMAND} -E rm -rf ${budget_archive})
add_test(NAME insitu_view.setup_budget_archive
         COMMAND gray-scott --size 24 --steps 8 --config ${budget_config} --out ${budget_archive})
set_tests_properties(insitu_view.setup_budget_clean PROPERTIES
                     FIXTURES_SETUP insitu_view_budget_clean)
set_tests_properties(insitu_view.setup_budget_archive PROPERTIES
                     FIXTURES_REQUIRED insitu_view_budget_clean
                     FIXTURES_SETUP insitu_view_budget_archive TIMEOUT 120)
archive_case(insitu_view_budget_archive info_budget 0 STDOUT
             "budget        step 8 v: 16 uniform intervals, half" info ${budget_archive})
archive_case(insitu_view_budget_archive info_budget_light_field 0 STDOUT
             "light field 12 cameras at 64^2" info ${budget_archive})
archive_case(insitu_view_budget_archive info_budget_rig 0 STDOUT
             "light field   v: 12 cameras, 64^2 maps" info ${budget_archive})

# The compressed field (issue 40), on volume_interop.cmake's archive: info lists it, render
# draws any view of it with any function (beside that archive: insitu_view.outputs counts its
# folder's PNGs), and a source it lacks is named.
if(TARGET insitu-capture)
  set(volume_archive ${CMAKE_CURRENT_BINARY_DIR}/volume_interop/run.cdb)
  function(volume_case name exit_status stream text)
    archive_case(volume_interop_archive ${name} ${exit_status} ${stream} "${text}" ${ARGN})
  endfunction()
  volume_case(info_volume 0 STDOUT "volume        density: zfp accuracy tolerance 0.002"
              info ${volume_archive})
  volume_case(render_volume 0 STDERR "new view from volume, colour by the ground truth" render
              ${volume_archive} --step 0 --azimuth 200 --elevation -30 --source volume
              --tf ${edited_tf} --out ${CMAKE_CURRENT_BINARY_DIR}/volume_interop/volume.png)
  volume_case(render_volume_auto 0 STDERR "new view from volume" render ${volume_archive}
              --step 0 --azimuth 100
              --out ${CMAKE_CURRENT_BINARY_DIR}/volume_interop/volume_auto.png)
  view_case(render_volume_missing 2 STDERR "source = volume, but step 4 view 0" render
            ${view_archive} --step 4 --source volume --out ${view_output}/no_volume.png)
endif()
