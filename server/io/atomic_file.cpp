// Whole-or-nothing file writes and whole-file reads. See atomic_file.hpp.
#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace dermis {

namespace fs = std::filesystem;

namespace {

std::string errnoText(int err) {
    return std::strerror(err);
}

/// Writes all of `bytes` to fd, retrying short writes and EINTR. Returns 0 or an errno value.
int writeAll(int fd, const std::vector<std::uint8_t>& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        done += static_cast<std::size_t>(n);
    }
    return 0;
}

} // namespace

bool isTempName(const std::string& fileName) {
    return fileName.find(kTempMarker) != std::string::npos;
}

Status syncFolder(const std::string& folder, const char* where) {
    const int fd = ::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return makeError(ErrorCode::Io, where, folder, "cannot open: " + errnoText(errno));
    const int rc = ::fsync(fd);
    const int err = errno;
    ::close(fd);
    if (rc != 0) return makeError(ErrorCode::Io, where, folder, "fsync failed: " + errnoText(err));
    return Ok{};
}

Status writeFileAtomically(const std::string& path, const std::vector<std::uint8_t>& bytes,
                           Durability durability, const char* where) {
    static std::atomic<unsigned> counter{0};
    std::string tmp;
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        tmp = path + kTempMarker + std::to_string(::getpid()) + "." + std::to_string(counter++);
        fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST) break;
    }
    if (fd < 0)
        return makeError(ErrorCode::Io, where, path,
                         "cannot create the temporary file " + tmp + ": " + errnoText(errno));
    int err = writeAll(fd, bytes);
    const char* step = "write";
    if (err == 0 && durability == Durability::Durable && ::fsync(fd) != 0) {
        err = errno;
        step = "fsync";
    }
    if (::close(fd) != 0 && err == 0) {
        err = errno;
        step = "close";
    }
    if (err == 0 && std::rename(tmp.c_str(), path.c_str()) != 0) {
        err = errno;
        step = "rename";
    }
    if (err != 0) {
        ::unlink(tmp.c_str());
        return makeError(ErrorCode::Io, where, path,
                         std::string("cannot write (") + step + "): " + errnoText(err));
    }
    if (durability == Durability::Durable)
        return syncFolder(fs::path(path).parent_path().string(), where);
    return Ok{};
}

Result<std::vector<std::uint8_t>> readWholeFile(const std::string& path, std::size_t maxBytes,
                                                const char* where) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        const int err = errno;
        return makeError(err == ENOENT ? ErrorCode::NotFound : ErrorCode::Io, where, path,
                         err == ENOENT ? "no such file" : "cannot open: " + errnoText(err));
    }
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0)
        return makeError(ErrorCode::Io, where, path, "cannot stat: " + errnoText(errno));
    if (!S_ISREG(st.st_mode)) return makeError(ErrorCode::Io, where, path, "not a regular file");
    if (static_cast<std::uint64_t>(st.st_size) > maxBytes)
        return makeError(ErrorCode::TooLarge, where, path,
                         "is " + std::to_string(st.st_size) + " bytes, more than the limit of " +
                             std::to_string(maxBytes));
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(st.st_size));
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return makeError(ErrorCode::Io, where, path, "cannot read: " + errnoText(errno));
        if (n == 0) break; // shrank while reading
        done += static_cast<std::size_t>(n);
    }
    bytes.resize(done);
    return bytes;
}

} // namespace dermis
