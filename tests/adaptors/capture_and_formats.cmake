# Tests of the VTK and OpenVDB adaptors (adaptors/vtk, adaptors/openvdb) and of insitu-capture's
# readers (adaptors/capture), included from tests/CMakeLists.txt. The raw reader is always tested;
# each adaptor's suite joins when its optional target was built.
if(NOT TARGET insitu_capture_readers)
  return()
endif()
add_executable(insitu_adaptor_tests raw_reader_test.cpp)
target_link_libraries(insitu_adaptor_tests PRIVATE insitu_capture_readers insitu_test_support GTest::gtest
                                                   GTest::gmock GTest::gtest_main)
target_link_libraries(insitu_adaptor_tests PRIVATE insitu_warnings)
if(TARGET insitu_vtk)
  target_sources(insitu_adaptor_tests PRIVATE vtk_adaptor_test.cpp)
  target_link_libraries(insitu_adaptor_tests PRIVATE insitu_vtk VTK::IOXML)
endif()
if(TARGET insitu_openvdb)
  target_sources(insitu_adaptor_tests PRIVATE openvdb_adaptor_test.cpp)
  target_link_libraries(insitu_adaptor_tests PRIVATE insitu_openvdb)
endif()
gtest_discover_tests(insitu_adaptor_tests DISCOVERY_TIMEOUT 60)
