# --help on every program and sub-command (the shared mechanism: libinsitu/tools/arguments.hpp),
# included from tests/cli/CMakeLists.txt: exit 0, the command's options and their defaults on
# stdout and nothing on stderr, wherever -h or --help stands among the arguments (also where a
# value is due, and before a value that would not parse); and an unknown option still exits 2.
# None of these reads an archive or starts OpenCL.
set(help_cli_dir ${CMAKE_CURRENT_LIST_DIR})
set(help_missing ${CMAKE_CURRENT_BINARY_DIR}/help_no_such.cdb)

# help_case(NAME TARGET TEXTS ARGS...): runs TARGET with ARGS; expects exit 0, every one of the
# |-separated TEXTS on stdout and an empty stderr.
function(help_case name target texts)
  if(NOT TARGET ${target})
    return()
  endif()
  string(JOIN "|" command $<TARGET_FILE:${target}> ${ARGN})
  add_test(NAME help.${name}
           COMMAND ${CMAKE_COMMAND} -DEXPECTED_EXIT=0 "-DEXPECTED_STDOUT_ALL=${texts}"
                   -DEXPECTED_STDERR_EMPTY=ON "-DCOMMAND=${command}"
                   -P ${help_cli_dir}/expect_exit.cmake)
  set_tests_properties(help.${name} PROPERTIES TIMEOUT 30)
endfunction()

# unknown_option_case(NAME TARGET TEXT ARGS...): exit 2 and TEXT in the one line on stderr.
function(unknown_option_case name target text)
  if(NOT TARGET ${target})
    return()
  endif()
  string(JOIN "|" command $<TARGET_FILE:${target}> ${ARGN})
  add_test(NAME unknown_option.${name}
           COMMAND ${CMAKE_COMMAND} -DEXPECTED_EXIT=2 "-DEXPECTED_STDERR_SUBSTRING=${text}"
                   "-DCOMMAND=${command}" -P ${help_cli_dir}/expect_exit.cmake)
  set_tests_properties(unknown_option.${name} PROPERTIES TIMEOUT 30)
endfunction()

# insitu-view: each sub-command's own options, and the overview.
set(render_texts "usage: insitu-view render|--step N|--view V|(default 0)|--opacity-scale J=S"
                 "--light AZ,EL|--ambient A|(default 0.2)|--ao-radius PIXELS|(default 8)"
                 "--fill PIXELS|(default 1)|--mask OUT.png|--out OUT.png|[required]|-h, --help")
string(JOIN "|" render_texts ${render_texts})
help_case(view_render insitu-view "${render_texts}" render --help)
help_case(view_render_short insitu-view "${render_texts}" render -h)
# Where --step expects its value, and after a value that would not parse: help, not an error.
help_case(view_render_in_place_of_a_value insitu-view "${render_texts}"
          render ${help_missing} --step --help)
help_case(view_render_after_a_bad_value insitu-view "${render_texts}"
          render ${help_missing} --step x --elevation 95 -h)
help_case(view_help_render insitu-view "${render_texts}" help render)
help_case(view_info insitu-view "usage: insitu-view info ARCHIVE|--json|damage" info --help)
help_case(view_info_after_archive insitu-view "usage: insitu-view info|--json"
          info ${help_missing} -h)
help_case(view_verify insitu-view "usage: insitu-view verify ARCHIVE|-h, --help" verify --help)
help_case(view_verify_after_archive insitu-view "usage: insitu-view verify" verify
          ${help_missing} -h)
help_case(view_serve insitu-view
          "usage: insitu-view serve|--port P|(default 8765)|--bind ADDR|(default 127.0.0.1)"
          serve --port --help)
help_case(view_overview insitu-view
          "commands:|insitu-view info|insitu-view render|insitu-view verify|insitu-view serve"
          --help)
unknown_option_case(view_info insitu-view "info: unknown flag --bogus" info ${help_missing}
                    --bogus)
unknown_option_case(view_verify insitu-view "verify: unknown flag --bogus" verify
                    ${help_missing} --bogus)
unknown_option_case(view_serve insitu-view "serve: unknown flag --bogus" serve ${help_missing}
                    --bogus)
unknown_option_case(view_render insitu-view "render: unknown flag --bogus" render
                    ${help_missing} --step 1 --bogus 2 --out never.png)
unknown_option_case(view_help_of_unknown_command insitu-view "unknown command \"show\"" help show)

# The other programs.
set(render_tool_texts "usage: insitu-render|--raw FILE|--dims NX,NY,NZ|--size WxH"
                      "(default 512x512)|--early-termination OPACITY|(default 0.99)|-h, --help")
string(JOIN "|" render_tool_texts ${render_tool_texts})
help_case(render_tool insitu-render "${render_tool_texts}" --help)
help_case(render_tool_short insitu-render "${render_tool_texts}" -h)
help_case(render_tool_in_place_of_a_value insitu-render "${render_tool_texts}"
          --dims 1,x,3 --size --help)

set(capture_texts "usage: insitu-capture|--config CONFIG.json|--out ARCHIVE|--on-error stop"
                  "(default stop)|--first-step N|(default 0)|-h, --help")
string(JOIN "|" capture_texts ${capture_texts})
help_case(capture insitu-capture "${capture_texts}" --help)
help_case(capture_short insitu-capture "${capture_texts}" --out -h input.raw)

set(gray_scott_texts "usage: gray-scott|--size N|(default 64)|--steps S|(default 200)"
                     "--image-size WxH|(default 256x256)|--F f|(default 0.025)|--seed n")
string(JOIN "|" gray_scott_texts ${gray_scott_texts})
help_case(gray_scott gray-scott "${gray_scott_texts}" --help)
help_case(gray_scott_short gray-scott "${gray_scott_texts}" -h)
help_case(gray_scott_in_place_of_a_value gray-scott "${gray_scott_texts}" --size --help)

set(vtk_heat_texts "usage: vtk-heat ARCHIVE|--size N|(default 32)|--steps S|(default 40)"
                   "--every K|(default 10)|--write-vti DIR")
string(JOIN "|" vtk_heat_texts ${vtk_heat_texts})
help_case(vtk_heat vtk-heat "${vtk_heat_texts}" --help)
help_case(vtk_heat_short vtk-heat "${vtk_heat_texts}" -h)
help_case(vtk_heat_in_place_of_a_value vtk-heat "${vtk_heat_texts}" ${help_missing} --steps -h)
unknown_option_case(vtk_heat vtk-heat "unknown option --bogus" ${help_missing} --bogus 1)

# The mechanism itself: where -h/--help is recognised and what write_help prints.
add_executable(cli_help_test help_test.cpp)
target_link_libraries(cli_help_test PRIVATE insitu_cli GTest::gtest_main GTest::gmock
                                            insitu_warnings)
gtest_discover_tests(cli_help_test)
