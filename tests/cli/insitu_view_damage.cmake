# insitu-view info and verify on damaged archives (viewer/archive_inspection.cpp,
# ArchiveReader::open_damaged), included from tests/cli/CMakeLists.txt. make_damaged_archives
# writes them without OpenCL (damaged_archives.hpp says what is broken in each); info must show
# the steps it can still read and list each problem under "damage:" (exit 3, one line on
# stderr), verify must list every problem (exit 3), and only a directory with no readable index
# is refused (exit 2).
if(NOT TARGET insitu-view)
  return()
endif()
set(damage_cli_dir ${CMAKE_CURRENT_LIST_DIR})
set(damage_out ${CMAKE_CURRENT_BINARY_DIR}/insitu_view_damage)

add_executable(make_damaged_archives make_damaged_archives.cpp)
target_include_directories(make_damaged_archives PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(make_damaged_archives PRIVATE insitu insitu_warnings)

add_test(NAME insitu_view_damage.setup_clean COMMAND ${CMAKE_COMMAND} -E rm -rf ${damage_out})
add_test(NAME insitu_view_damage.setup_archives COMMAND make_damaged_archives ${damage_out})
set_tests_properties(insitu_view_damage.setup_clean PROPERTIES
                     FIXTURES_SETUP insitu_view_damage_clean)
set_tests_properties(insitu_view_damage.setup_archives PROPERTIES
                     FIXTURES_REQUIRED insitu_view_damage_clean
                     FIXTURES_SETUP insitu_view_damage_archives)

# damage_case(NAME EXIT STDOUT-TEXTS STDERR-TEXT ARGS...): runs insitu-view ARGS; expects the exit
# status, every |-separated STDOUT-TEXT on stdout and STDERR-TEXT on stderr ("" for none).
function(damage_case name exit_status stdout_texts stderr_text)
  string(JOIN "|" command $<TARGET_FILE:insitu-view> ${ARGN})
  set(expect_stderr "")
  if(NOT stderr_text STREQUAL "")
    set(expect_stderr "-DEXPECTED_STDERR_SUBSTRING=${stderr_text}")
  endif()
  add_test(NAME insitu_view_damage.${name}
           COMMAND ${CMAKE_COMMAND} -DEXPECTED_EXIT=${exit_status}
                   "-DEXPECTED_STDOUT_ALL=${stdout_texts}" ${expect_stderr}
                   "-DCOMMAND=${command}" -P ${damage_cli_dir}/expect_exit.cmake)
  set_tests_properties(insitu_view_damage.${name} PROPERTIES
                       FIXTURES_REQUIRED insitu_view_damage_archives TIMEOUT 60)
endfunction()

damage_case(info_clean 0 "steps         5 (2 .. 10)|views         2|damage        none" ""
            info ${damage_out}/clean.cdb)
damage_case(verify_clean 0 "20 files checked, 0 problems" "" verify ${damage_out}/clean.cdb)

# Steps 2, 6 (its PNG is damaged, its proxies are not) and 8 (its view 0 EXR has the recorded
# size and another CRC-32) stay listed, and step 4 with view 1; step 10's entry is unusable.
# Each problem is one line naming its file. info reads the index and each file's size, not the
# files (issue 42: a 12,000-step run opens as a 10-step one), so step 8's checksum is verify's
# to find; info says so.
set(damaged_texts
    "steps         4 (2 .. 8)|view 0 single  12x9|view 1 single  12x9"
    "unreadable    step 4 view 0\n|checked       index and file sizes (verify reads every byte)"
    "damage:|step entry skipped: |steps[4].time"
    "step000004_view0.exr\": no such file|step000006_view1.png\": |(truncated or replaced)"
    "data.csv\": header \"not,a,cinema,header\"")
string(JOIN "|" damaged_texts ${damaged_texts})
damage_case(info_damaged 3 "${damaged_texts}" "is damaged: 4 problems"
            info ${damage_out}/damaged.cdb)
set(damaged_json_texts "\"damage\": |\"unreadable\": |\"step\": 4|\"manifest_readable\": true"
                       "step000006_view1.png")
string(JOIN "|" damaged_json_texts ${damaged_json_texts})
damage_case(info_damaged_json 3 "${damaged_json_texts}" "is damaged: 4 problems"
            info ${damage_out}/damaged.cdb --json)
# The first step's proxies are read to describe the archive: a first step whose EXR has its
# size and another CRC-32 is found by info too, and left out.
damage_case(info_first_step_corrupt 3
            "steps         1 (4 .. 4)|unreadable    step 2 view 0|step000002_view0.exr\": CRC-32"
            "is damaged: 1 problem" info ${damage_out}/first_corrupt.cdb)
set(damaged_verify_texts
    "steps[4].time|step000004_view0.exr\": no such file|step000006_view1.png\": "
    "step000008_view0.exr\": CRC-32|data.csv\": header|16 files checked, 5 problems")
string(JOIN "|" damaged_verify_texts ${damaged_verify_texts})
damage_case(verify_damaged 3 "${damaged_verify_texts}" "is damaged: 5 problems"
            verify ${damage_out}/damaged.cdb)

# manifest.json corrupt, its steps in the journal: the journal's steps, the configuration lost.
set(journal_texts
    "steps         3 (2 .. 6)|configuration unknown|damage:|manifest.json\": not valid JSON")
string(JOIN "|" journal_texts ${journal_texts})
damage_case(info_journal 3 "${journal_texts}" "is damaged: 1 problem"
            info ${damage_out}/journal.cdb)
damage_case(verify_journal 3 "manifest.json\": not valid JSON|6 files checked, 1 problem"
            "is damaged: 1 problem" verify ${damage_out}/journal.cdb)

# No readable index at all: refused, one line naming both halves of the index.
damage_case(info_no_index 2 "" "has no readable index" info ${damage_out}/no_index.cdb)
damage_case(verify_no_index 2 "" "manifest.journal\" does not exist"
            verify ${damage_out}/no_index.cdb)
