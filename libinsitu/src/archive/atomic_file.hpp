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

/// Appends `bytes` to `path` (created when missing, its folder then synced so that the name
/// survives a crash) and fsync()s it: the append-only indexes (manifest.journal, data.csv) cost
/// O(1) a step this way. Returns the size the file had before, for truncate_file(). When the
/// write fails part-way the file is cut back to that size, so a failed append leaves no torn
/// line for the next append to run into. IoError naming the file otherwise.
std::uint64_t append_to_file(const std::filesystem::path& path, const std::string& bytes);
/// Cuts `path` back to `size` bytes and syncs it (undoes an append_to_file); IoError naming it.
void truncate_file(const std::filesystem::path& path, std::uint64_t size);
/// Removes `path` if it exists and syncs its folder; IoError naming it.
void remove_file_durably(const std::filesystem::path& path);

/// An exclusive flock() on `path` (created when missing) holding the holder's pid as text, kept
/// for this object's lifetime; the kernel drops it when the process dies, even by SIGKILL.
/// IoError naming `what` and the holder's pid when another open file (this process or another)
/// holds it.
class FileLock {
public:
    FileLock(const std::filesystem::path& path, const std::string& what);
    ~FileLock();
    FileLock(const FileLock&) = delete;
    FileLock& operator=(const FileLock&) = delete;

private:
    int fd_ = -1;
};

/// Removes the temp files killed runs left in `folder` (best effort: a leftover is only clutter).
void remove_temp_files(const std::filesystem::path& folder);

/// zlib CRC-32 of a buffer.
std::uint32_t crc32_of(const void* data, std::size_t size);
/// The whole file; IoError naming it when it cannot be read.
std::vector<char> read_whole_file(const std::string& path);

}  // namespace insitu::archive_format
