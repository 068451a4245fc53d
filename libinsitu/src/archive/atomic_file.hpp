#pragma once
// Crash-safe files (DESIGN.md "Archive"): every file is written to a temp file in its final
// folder, fsync'ed, renamed into place and the folder fsync'ed, so a file name in the archive
// always holds complete bytes. Also the CRC-32 the manifest records and the whole-file read the
// reader checks it on.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace insitu::archive_format {

/// A temp file beside `final_path` (named with kTempPrefix), removed unless commit() renamed it
/// into place. Errors are IoError naming the final path, the step that failed and errno's text.
class TempFile {
public:
    explicit TempFile(std::filesystem::path final_path);
    ~TempFile();
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;

    const std::filesystem::path& temp() const { return temp_; }

    /// Creates the temp file holding the `size` bytes at `data`, synced to disk.
    void write(const void* data, std::size_t size);
    /// fsync()s a temp file someone else wrote (write_png).
    void sync();
    /// Renames the temp file to the final path and syncs the folder.
    void commit();

private:
    void sync_and_close(int fd);
    [[noreturn]] void failed(const char* what, int error) const;

    std::filesystem::path final_;
    std::filesystem::path temp_;
    bool committed_ = false;
};

/// `path` holds exactly `bytes`, or (on IoError) is as it was.
void write_file_atomically(const std::filesystem::path& path, const std::string& bytes);

/// Removes the temp files killed runs left in `folder` (best effort: a leftover is only clutter).
void remove_temp_files(const std::filesystem::path& folder);

/// zlib CRC-32 of a buffer.
std::uint32_t crc32_of(const void* data, std::size_t size);
/// The whole file; IoError naming it when it cannot be read.
std::vector<char> read_whole_file(const std::string& path);

}  // namespace insitu::archive_format
