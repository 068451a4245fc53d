#include "archive/atomic_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "archive/archive_format.hpp"
#include "insitu/error.hpp"

namespace insitu::archive_format {

namespace fs = std::filesystem;

namespace {

std::string errno_text(int error) {
    return std::strerror(error);
}

void fsync_directory(const fs::path& directory) {
    const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0)
        fail<IoError>("cannot open directory \"", directory.string(),
                      "\" to sync it: ", errno_text(errno));
    const int status = ::fsync(fd);
    const int error = errno;
    ::close(fd);
    if (status != 0) {
        fail<IoError>("cannot sync directory \"", directory.string(), "\": ", errno_text(error));
    }
}

}  // namespace

TempFile::TempFile(fs::path final_path) : final_(std::move(final_path)) {
    // pid + counter: unique within the folder without asking the file system.
    static std::atomic<unsigned> counter{0};
    temp_ = final_.parent_path() / (std::string(kTempPrefix) + std::to_string(::getpid()) + "-" +
                                    std::to_string(counter++) + "-" + final_.filename().string());
}

TempFile::~TempFile() {
    if (!committed_) ::unlink(temp_.c_str());
}

void TempFile::write(const void* data, std::size_t size) {
    const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) failed("create", errno);
    const char* bytes = static_cast<const char*>(data);
    std::size_t done = 0;
    while (done < size) {
        const ssize_t written = ::write(fd, bytes + done, size - done);
        if (written < 0) {
            if (errno == EINTR) continue;
            const int error = errno;
            ::close(fd);
            failed("write", error);
        }
        done += static_cast<std::size_t>(written);
    }
    sync_and_close(fd);
}

void TempFile::sync() {
    const int fd = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) failed("reopen", errno);
    sync_and_close(fd);
}

void TempFile::commit() {
    if (::rename(temp_.c_str(), final_.c_str()) != 0) failed("rename", errno);
    committed_ = true;
    fsync_directory(final_.parent_path());
}

void TempFile::sync_and_close(int fd) {
    if (::fsync(fd) != 0) {
        const int error = errno;
        ::close(fd);
        failed("sync", error);
    }
    // close() reports deferred write errors on some file systems (NFS).
    if (::close(fd) != 0) failed("close", errno);
}

void TempFile::failed(const char* what, int error) const {
    fail<IoError>("cannot write \"", final_.string(), "\": ", what, " of temp file \"",
                  temp_.filename().string(), "\" failed: ", errno_text(error));
}

void write_file_atomically(const fs::path& path, const std::string& bytes) {
    TempFile file(path);
    file.write(bytes.data(), bytes.size());
    file.commit();
}

namespace {

/// write() all of `bytes`, retrying on EINTR; the errno of the failure, 0 on success.
int write_all(int fd, const std::string& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t written = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (written < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        done += static_cast<std::size_t>(written);
    }
    return 0;
}

}  // namespace

std::uint64_t append_to_file(const fs::path& path, const std::string& bytes) {
    std::error_code ignored;
    const bool created = !fs::exists(path, ignored);
    const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) fail<IoError>("cannot append to \"", path.string(), "\": ", errno_text(errno));
    struct stat info {};
    if (::fstat(fd, &info) != 0) {
        const int error = errno;
        ::close(fd);
        fail<IoError>("cannot append to \"", path.string(), "\": fstat: ", errno_text(error));
    }
    const auto previous = static_cast<std::uint64_t>(info.st_size);
    int error = write_all(fd, bytes);
    const char* what = "write";
    if (error == 0 && ::fsync(fd) != 0) {
        error = errno;
        what = "sync";
    }
    if (error != 0) {
        // Best effort: a cut that fails too leaves a torn last line, which readers skip.
        if (::ftruncate(fd, static_cast<off_t>(previous)) == 0) ::fsync(fd);
        ::close(fd);
        fail<IoError>("cannot append to \"", path.string(), "\": ", what, ": ", errno_text(error));
    }
    if (::close(fd) != 0) {
        fail<IoError>("cannot append to \"", path.string(), "\": close: ", errno_text(errno));
    }
    if (created) fsync_directory(path.parent_path());
    return previous;
}

void truncate_file(const fs::path& path, std::uint64_t size) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) fail<IoError>("cannot truncate \"", path.string(), "\": ", errno_text(errno));
    const bool done = ::ftruncate(fd, static_cast<off_t>(size)) == 0 && ::fsync(fd) == 0;
    const int error = errno;
    ::close(fd);
    if (!done) fail<IoError>("cannot truncate \"", path.string(), "\": ", errno_text(error));
}

void remove_file_durably(const fs::path& path) {
    if (::unlink(path.c_str()) != 0) {
        if (errno == ENOENT) return;
        fail<IoError>("cannot remove \"", path.string(), "\": ", errno_text(errno));
    }
    fsync_directory(path.parent_path());
}

FileLock::FileLock(const fs::path& path, const std::string& what) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) {
        fail<IoError>(what, ": cannot open lock file \"", path.string(), "\": ", errno_text(errno));
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        const int error = errno;
        // The holder wrote its pid when it took the lock; read it for the message.
        char text[32] = {};
        const ssize_t got = ::pread(fd_, text, sizeof text - 1, 0);
        std::string holder = got > 0 ? std::string(text, static_cast<std::size_t>(got)) : "";
        holder.erase(std::remove(holder.begin(), holder.end(), '\n'), holder.end());
        ::close(fd_);
        fd_ = -1;
        if (error == EWOULDBLOCK) {
            fail<IoError>(what, " is locked by another writer (pid ",
                          holder.empty() ? std::string("unknown") : holder, ", lock file \"",
                          path.string(), "\"): one writer at a time");
        }
        fail<IoError>(what, ": cannot lock \"", path.string(), "\": ", errno_text(error));
    }
    // Only the holder writes the file, so a stale pid from a killed holder is simply replaced.
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
        const int error = errno;
        ::close(fd_);
        fd_ = -1;
        fail<IoError>(what, ": cannot write lock file \"", path.string(),
                      "\": ", errno_text(error));
    }
}

FileLock::~FileLock() {
    // Closing the last descriptor of the open file releases the flock.
    if (fd_ >= 0) ::close(fd_);
}

void remove_temp_files(const fs::path& folder) {
    std::error_code error;
    for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
        if (it->path().filename().string().rfind(kTempPrefix, 0) == 0) {
            std::error_code ignored;
            fs::remove(it->path(), ignored);
        }
    }
}

std::uint32_t crc32_of(const void* data, std::size_t size) {
    // zlib's crc32 takes uInt lengths; feed it in chunks so files over 4 GiB are fine.
    uLong crc = ::crc32(0L, Z_NULL, 0);
    const auto* bytes = static_cast<const Bytef*>(data);
    while (size > 0) {
        const uInt chunk = static_cast<uInt>(std::min<std::size_t>(size, 1u << 30));
        crc = ::crc32(crc, bytes, chunk);
        bytes += chunk;
        size -= chunk;
    }
    return static_cast<std::uint32_t>(crc);
}

std::vector<char> read_whole_file(const std::string& path) {
    std::error_code error;
    if (!fs::is_regular_file(path, error)) {
        fail<IoError>("cannot read \"", path,
                      "\": ", fs::exists(path, error) ? "not a regular file" : "no such file");
    }
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) fail<IoError>("cannot open \"", path, "\"");
    // One read of the size the file has now (a character at a time was a third of opening a
    // long run's index); a journal that grows meanwhile is read up to that size, one cut
    // meanwhile up to its end.
    const std::streamoff size = in.tellg();
    if (size < 0) fail<IoError>("cannot read \"", path, "\"");
    std::vector<char> bytes(static_cast<std::size_t>(size));
    in.seekg(0);
    in.read(bytes.data(), size);
    if (in.bad()) fail<IoError>("cannot read \"", path, "\"");
    bytes.resize(static_cast<std::size_t>(in.gcount()));
    return bytes;
}

}  // namespace insitu::archive_format
