# Crash safety of the proxy archive (issue 4): archive_crash_test forks a child that appends
# steps and SIGKILLs it at random points, then checks the archive each time. Its own small
# executable: it forks, and nothing else (no OpenCL device, no other suites) shares its process.
add_executable(archive_crash_test archive_crash_test.cpp)
target_link_libraries(archive_crash_test PRIVATE insitu GTest::gtest GTest::gtest_main)
add_test(NAME archive_crash COMMAND archive_crash_test)
set_tests_properties(archive_crash PROPERTIES TIMEOUT 60)

# archive_test checks the manifest's "producer" against the project's version.
target_compile_definitions(insitu_tests PRIVATE INSITU_PROJECT_VERSION="${PROJECT_VERSION}")
