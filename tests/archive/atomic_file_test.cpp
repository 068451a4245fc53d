// The archive's crash-safe files: what lands under the final name is whole, temp files never
// outlive a failed or abandoned write, and the CRC-32 is zlib's (the manifest's checksums).
#include "archive/atomic_file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "archive/archive_format.hpp"
#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu::archive_format {
namespace {

namespace fs = std::filesystem;
using insitu::testing::expect_error_naming;

class AtomicFile : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = fs::temp_directory_path() /
                     ("insitu_atomic_file_test_" + std::to_string(::getpid()) + "_" +
                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(directory_);
        fs::create_directories(directory_);
    }
    void TearDown() override { fs::remove_all(directory_); }

    std::vector<std::string> names() const {
        std::vector<std::string> found;
        for (const auto& entry : fs::directory_iterator(directory_)) {
            found.push_back(entry.path().filename().string());
        }
        return found;
    }
    static std::string contents(const fs::path& path) {
        std::ifstream in(path, std::ios::binary);
        return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    }

    fs::path directory_;
};

TEST_F(AtomicFile, WritesExactlyTheBytesAndLeavesNoTempFile) {
    const std::string bytes("proxy\0bytes\n", 12);
    write_file_atomically(directory_ / "a.bin", bytes);
    EXPECT_EQ(contents(directory_ / "a.bin"), bytes);
    EXPECT_THAT(names(), ::testing::ElementsAre("a.bin"));
}

TEST_F(AtomicFile, ReplacesAnExistingFileWhole) {
    write_file_atomically(directory_ / "manifest.json", std::string(1000, 'x'));
    write_file_atomically(directory_ / "manifest.json", "{}\n");
    EXPECT_EQ(contents(directory_ / "manifest.json"), "{}\n");
    EXPECT_THAT(names(), ::testing::ElementsAre("manifest.json"));
}

TEST_F(AtomicFile, AnUncommittedTempFileIsRemovedAndTheFinalNameNeverAppears) {
    {
        TempFile file(directory_ / "b.bin");
        file.write("abc", 3);
        EXPECT_EQ(file.temp().parent_path(), directory_);
        EXPECT_EQ(file.temp().filename().string().rfind(kTempPrefix, 0), 0u);
        EXPECT_TRUE(fs::exists(file.temp()));
        EXPECT_FALSE(fs::exists(directory_ / "b.bin"));
    }
    EXPECT_TRUE(names().empty());
}

TEST_F(AtomicFile, AFailedWriteNamesTheFileAndLeavesNothing) {
    const fs::path missing = directory_ / "no_such_folder" / "c.bin";
    expect_error_naming<IoError>([&] { write_file_atomically(missing, "abc"); }, missing.string());
    EXPECT_TRUE(names().empty());
}

TEST_F(AtomicFile, RemoveTempFilesRemovesOnlyTempFiles) {
    write_file_atomically(directory_ / "keep.exr", "k");
    std::ofstream(directory_ / (std::string(kTempPrefix) + "123-0-step.exr")) << "left over";
    remove_temp_files(directory_);
    EXPECT_THAT(names(), ::testing::ElementsAre("keep.exr"));
    remove_temp_files(directory_ / "absent");  // a missing folder is not an error
}

TEST_F(AtomicFile, ReadWholeFileReadsBackAndNamesWhatItCannotRead) {
    const std::string bytes(70000, '\x7f');
    write_file_atomically(directory_ / "big.bin", bytes);
    const std::vector<char> read = read_whole_file((directory_ / "big.bin").string());
    EXPECT_EQ(std::string(read.begin(), read.end()), bytes);
    expect_error_naming<IoError>([&] { read_whole_file((directory_ / "gone").string()); },
                                 "no such file");
    expect_error_naming<IoError>([&] { read_whole_file(directory_.string()); },
                                 "not a regular file");
}

TEST(Crc32, MatchesTheStandardCheckValue) {
    // The CRC-32 (ISO-HDLC) check value of the nine digits, as every implementation publishes.
    const std::string digits = "123456789";
    EXPECT_EQ(crc32_of(digits.data(), digits.size()), 0xCBF43926u);
    EXPECT_EQ(crc32_of(nullptr, 0), 0u);
}

// The append-only indexes (issue 19): an append that the disk refuses part-way is cut back, so
// the next append does not land behind a torn line.
TEST_F(AtomicFile, FailedAppendIsCutBackAndTruncateUndoesAnAppend) {
    const fs::path journal = directory_ / "manifest.journal";
    EXPECT_EQ(append_to_file(journal, "one\n"), 0u);
    EXPECT_EQ(append_to_file(journal, "two\n"), 4u);
    {
        // RLIMIT_FSIZE with SIGXFSZ ignored: write() fails with EFBIG past 10 bytes, after
        // writing the first two of these, as on a disk that fills mid-append.
        rlimit saved{};
        ::getrlimit(RLIMIT_FSIZE, &saved);
        const sighandler_t handler = ::signal(SIGXFSZ, SIG_IGN);
        rlimit limit = saved;
        limit.rlim_cur = 10;
        ::setrlimit(RLIMIT_FSIZE, &limit);
        expect_error_naming<IoError>([&] { append_to_file(journal, "three\n"); },
                                     "cannot append to \"" + journal.string() + "\"");
        ::setrlimit(RLIMIT_FSIZE, &saved);
        ::signal(SIGXFSZ, handler);
    }
    EXPECT_EQ(contents(journal), "one\ntwo\n");
    truncate_file(journal, 4);
    EXPECT_EQ(contents(journal), "one\n");
    remove_file_durably(journal);
    remove_file_durably(journal);  // already gone: nothing to do
    EXPECT_THAT(names(), ::testing::ElementsAre());
}

TEST_F(AtomicFile, LockIsExclusiveNamesItsHolderAndSurvivesTempCleanup) {
    const fs::path path = directory_ / ".lock";
    {
        const FileLock lock(path, "archive \"x\"");
        EXPECT_EQ(contents(path), std::to_string(::getpid()) + "\n");
        expect_error_naming<IoError>(
            [&] { FileLock second(path, "archive \"x\""); },
            "archive \"x\" is locked by another writer (pid " + std::to_string(::getpid()) + ",");
        remove_temp_files(directory_);
        EXPECT_TRUE(fs::exists(path));
    }
    EXPECT_NO_THROW(FileLock again(path, "archive \"x\""));
}

}  // namespace
}  // namespace insitu::archive_format
