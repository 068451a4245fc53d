# Tests of the C API (adaptors/c): the GoogleTest suite, and the C and Fortran example
# simulations run for real, each followed by a check of the archive it wrote.
# Included from tests/CMakeLists.txt.
add_executable(insitu_c_api_tests c_api_test.cpp)
target_link_libraries(insitu_c_api_tests PRIVATE insitu::insitu_c insitu_test_support GTest::gtest_main)
target_link_libraries(insitu_c_api_tests PRIVATE insitu_warnings)
gtest_discover_tests(insitu_c_api_tests DISCOVERY_TIMEOUT 60)

# c_api_example_tests(NAME TARGET [ARGS...]): runs TARGET ARCHIVE [ARGS...] with a fresh archive
# folder NAME.cdb and checks the archive. The examples run 40 steps with "every": 10 and two
# views, so steps 10..40 x views 0..1 give exactly 8 proxy files and 8 previews. The old archive
# is removed first: an archive left by an earlier run would be continued, and its duplicate steps
# would fail the run.
function(c_api_example_tests name target)
  if(NOT TARGET ${target})
    return()  # examples not built, or no Fortran compiler
  endif()
  set(archive ${CMAKE_CURRENT_BINARY_DIR}/${name}.cdb)
  set(check_files ${PROJECT_SOURCE_DIR}/tests/cli/check_files.cmake)
  add_test(NAME ${name}.clean
           COMMAND ${CMAKE_COMMAND} -E rm -rf ${archive} ${archive}.json)
  add_test(NAME ${name}.run COMMAND ${target} ${archive} ${ARGN})
  add_test(NAME ${name}.archive
           COMMAND ${CMAKE_COMMAND} -DDIRECTORY=${archive}
                   "-DFILES=manifest.json|data.csv|proxies/step000010_view0.exr|proxies/step000040_view1.exr"
                   -DEXPECTED_COUNT=8 -DPATTERN=proxies/*.exr -P ${check_files})
  add_test(NAME ${name}.previews
           COMMAND ${CMAKE_COMMAND} -DDIRECTORY=${archive}
                   "-DFILES=previews/step000010_view0.png|previews/step000040_view1.png"
                   -DEXPECTED_COUNT=8 -DPATTERN=previews/*.png -P ${check_files})
  set_tests_properties(${name}.clean PROPERTIES FIXTURES_SETUP ${name}_clean)
  set_tests_properties(${name}.run PROPERTIES
                       FIXTURES_REQUIRED ${name}_clean
                       FIXTURES_SETUP ${name}_archive
                       TIMEOUT 120)
  set_tests_properties(${name}.archive ${name}.previews PROPERTIES
                       FIXTURES_REQUIRED ${name}_archive)
endfunction()

# c_api_example_failure(NAME TARGET EXIT TEXT ARGS...): runs TARGET ARGS... and expects exit
# status EXIT and TEXT in its one line on stderr.
function(c_api_example_failure name target exit_status text)
  if(NOT TARGET ${target})
    return()
  endif()
  string(JOIN "|" command $<TARGET_FILE:${target}> ${ARGN})
  add_test(NAME ${target}.${name}
           COMMAND ${CMAKE_COMMAND} -DEXPECTED_EXIT=${exit_status}
                   "-DEXPECTED_STDERR_SUBSTRING=${text}" "-DCOMMAND=${command}"
                   -P ${PROJECT_SOURCE_DIR}/tests/cli/expect_exit.cmake)
  set_tests_properties(${target}.${name} PROPERTIES TIMEOUT 60)
endfunction()

c_api_example_tests(heat_c heat_c)
c_api_example_tests(heat_fortran heat_fortran)
if(TARGET heat_fortran)
  add_test(NAME heat_fortran.deallocates
           COMMAND ${CMAKE_COMMAND}
                   -DSOURCE=${PROJECT_SOURCE_DIR}/examples/fortran/heat_fortran.f90
                   -P ${CMAKE_CURRENT_LIST_DIR}/expect_deallocated.cmake)
endif()
# The interior as a non-contiguous array section, passed with strides instead of ghost counts.
c_api_example_tests(heat_fortran_interior heat_fortran 40 interior)
# A real(c_float) copy: the other specific procedure of the generic insitu_set_field.
c_api_example_tests(heat_fortran_float heat_fortran 40 float)

# No OpenCL device: the instrument cannot be made, the code says why (a ComputeError crossed the
# C boundary as INSITU_ERROR_COMPUTE) and the example stops before its first step.
foreach(target heat_c heat_fortran)
  set(archive ${CMAKE_CURRENT_BINARY_DIR}/${target}_no_device.cdb)
  c_api_example_failure(no_opencl_device ${target} 1 "INSITU_ERROR_COMPUTE" ${archive})
  if(TEST ${target}.no_opencl_device)
    set_tests_properties(${target}.no_opencl_device PROPERTIES
                         ENVIRONMENT INSITU_OPENCL_DEVICE=no-such-opencl-device)
  endif()
  c_api_example_failure(usage ${target} 2 "usage: ${target} ARCHIVE")
endforeach()

# heat_c and heat_fortran run the same simulation in the same floating-point order, so their
# previews must be byte-identical: a transposed or shifted Fortran array (column-major vs
# x-fastest, 1-based bounds, ghosts, strides) would change them. Only previews are compared; the
# EXR headers are the archive writer's to extend.
function(c_api_compare_previews name reference)
  if(NOT TEST ${name}.run OR NOT TEST ${reference}.run)
    return()
  endif()
  foreach(view 0 1)
    set(preview previews/step000040_view${view}.png)
    add_test(NAME ${name}.matches_${reference}_view${view}
             COMMAND ${CMAKE_COMMAND} -E compare_files
                     ${CMAKE_CURRENT_BINARY_DIR}/${reference}.cdb/${preview}
                     ${CMAKE_CURRENT_BINARY_DIR}/${name}.cdb/${preview})
    set_tests_properties(${name}.matches_${reference}_view${view} PROPERTIES
                         FIXTURES_REQUIRED "${name}_archive;${reference}_archive")
  endforeach()
endfunction()

c_api_compare_previews(heat_fortran heat_c)
c_api_compare_previews(heat_fortran_interior heat_c)
c_api_compare_previews(heat_fortran_float heat_c)
