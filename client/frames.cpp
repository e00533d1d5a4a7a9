// Frame ranges and names (as dermis-server render), atomic writes.
#include "frames.hpp"

#include "context.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>

namespace dermis::cli {

std::vector<double> parseFrameRange(const std::string& spec, const std::string& field) {
    static const std::regex re(R"(^\s*([0-9.eE+-]+):([0-9.eE+-]+):([0-9.eE+-]+)\s*$)");
    std::smatch m;
    double a = 0, b = 0, step = 0;
    try {
        if (!std::regex_match(spec, m, re)) throw std::invalid_argument("format");
        a = std::stod(m[1]);
        b = std::stod(m[2]);
        step = std::stod(m[3]);
    } catch (const std::exception&) {
        throw usageError("expected A:B:STEP in seconds, got \"" + spec + "\"", field);
    }
    if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(step) || a < 0 || b < a || step <= 0)
        throw usageError("need 0 <= A <= B and STEP > 0 in A:B:STEP, got \"" + spec + "\"", field);
    const double n = std::floor((b - a) / step + 1e-9) + 1;
    if (n > 100000) throw usageError("more than 100000 frames", field);
    std::vector<double> times;
    for (int k = 0; k < static_cast<int>(n); ++k)
        times.push_back(a + k * step);
    return times;
}

std::string framePath(const std::string& pattern, int index) {
    static const std::regex field(R"(%0?[0-9]*d)");
    std::smatch m;
    if (!std::regex_search(pattern, m, field)) return pattern;
    char buf[32];
    std::snprintf(buf, sizeof buf, m.str().c_str(), index);
    return m.prefix().str() + buf + m.suffix().str();
}

std::string extensionOf(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    if (!ext.empty()) ext.erase(0, 1);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

std::string imageFormatOf(const std::string& path) {
    const std::string ext = extensionOf(path);
    if (ext == "png") return "png";
    if (ext == "jpg" || ext == "jpeg") return "jpeg";
    return "";
}

std::string partialPathOf(const std::string& path) { return path + ".dermis-part"; }

bool writeAll(int fd, const char* data, std::size_t n) {
    for (std::size_t done = 0; done < n;) {
        const ssize_t w = ::write(fd, data + done, n - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        done += static_cast<std::size_t>(w);
    }
    return true;
}

void writeFileAtomically(const std::string& path, const std::string& bytes) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path parent = fs::path(path).parent_path();
    if (!parent.empty()) fs::create_directories(parent, ec);
    const std::string tmp = partialPathOf(path);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw usageError("cannot write " + tmp, path);
    if (!writeAll(fd, bytes.data(), bytes.size())) {
        ::close(fd);
        ::unlink(tmp.c_str());
        throw usageError("cannot write " + tmp, path);
    }
    if (::close(fd) != 0 || ::rename(tmp.c_str(), path.c_str()) != 0) {
        ::unlink(tmp.c_str());
        throw usageError("cannot write " + path, path);
    }
}

} // namespace dermis::cli
