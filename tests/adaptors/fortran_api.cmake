# Tests of the Fortran module (adaptors/c/insitu.f90) on arrays without the TARGET attribute:
# fortran_api_test.f90 hands one field over in many ways, each to an archive of its own, and the
# previews of each must be byte-identical to those of the contiguous real64 array (the
# cell-centred blocks to those of the whole cell-centred array): the same field seen through a
# wrong address, stride, ghost count, type or block origin would look different.
# Included from tests/adaptors/CMakeLists.txt; skipped without a Fortran compiler, like the module.
if(NOT TARGET insitu_fortran)
  return()
endif()
enable_language(Fortran)  # per directory: adaptors/c enabled it for its own
add_executable(insitu_fortran_api_test fortran_api_test.f90)
target_link_libraries(insitu_fortran_api_test PRIVATE insitu::insitu_fortran)
if(CMAKE_Fortran_COMPILER_ID STREQUAL "GNU")
  target_compile_options(insitu_fortran_api_test PRIVATE -std=f2018)
  target_link_libraries(insitu_fortran_api_test PRIVATE insitu_warnings)
endif()

# The cases of fortran_api_test.f90, by the case each must look like.
set(fortran_api_like_contiguous
    section in_place ghosts automatic real32 int16 uint16 uint8 blocks)
set(fortran_api_like_cell cell_blocks)
set(prefix ${CMAKE_CURRENT_BINARY_DIR}/fortran_api_)
# The old archives go first: an archive left by an earlier run would be continued, and its step
# would not be selected again.
set(archives "")
foreach(case contiguous cell errors ${fortran_api_like_contiguous} ${fortran_api_like_cell})
  list(APPEND archives ${prefix}${case}.cdb)
endforeach()
add_test(NAME fortran_api.clean COMMAND ${CMAKE_COMMAND} -E rm -rf ${archives})
add_test(NAME fortran_api.run COMMAND insitu_fortran_api_test ${prefix})
set_tests_properties(fortran_api.clean PROPERTIES FIXTURES_SETUP fortran_api_clean)
set_tests_properties(fortran_api.run PROPERTIES
                     FIXTURES_REQUIRED fortran_api_clean
                     FIXTURES_SETUP fortran_api_archives
                     TIMEOUT 120)
foreach(reference contiguous cell)
  foreach(case IN LISTS fortran_api_like_${reference})
    foreach(view 0 1)
      set(preview previews/step000002_view${view}.png)
      add_test(NAME fortran_api.${case}_matches_${reference}_view${view}
               COMMAND ${CMAKE_COMMAND} -E compare_files
                       ${prefix}${reference}.cdb/${preview} ${prefix}${case}.cdb/${preview})
      set_tests_properties(fortran_api.${case}_matches_${reference}_view${view} PROPERTIES
                           FIXTURES_REQUIRED fortran_api_archives)
    endforeach()
  endforeach()
endforeach()
