#pragma once
// Files in tests: a fresh scratch directory per test, whole files as text, and a file's CRC-32
// as the archive's manifest records it, so test files need no copies of these.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace insitu::testing {

/// TMPDIR/<prefix>_<pid>_<test name>, emptied and created: tests running in parallel processes
/// and tests of one process never share it.
inline std::filesystem::path fresh_test_directory(const std::string& prefix) {
    const std::filesystem::path directory =
        std::filesystem::temp_directory_path() /
        (prefix + "_" + std::to_string(::getpid()) + "_" +
         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(directory);
    std::filesystem::create_directories(directory);
    return directory;
}

inline std::string read_text(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

/// CRC-32 (zlib's) of a whole file.
inline std::uint32_t file_crc(const std::filesystem::path& path) {
    const std::string bytes = read_text(path);
    return static_cast<std::uint32_t>(
        ::crc32(0L, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(bytes.size())));
}

}  // namespace insitu::testing
