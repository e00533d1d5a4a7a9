// The Context's lazily made HTTP client, the Ctrl-C flag and file reading.
#include "context.hpp"

#include "http_client.hpp"

#include <fstream>
#include <iterator>

namespace dermis::cli {

std::atomic<bool> g_interrupted{false};

Http& Context::http() {
    if (!http_) http_ = std::make_shared<Http>(global);
    return *http_;
}

std::string readFileOrThrow(const std::string& path, const std::string& what) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw usageError("cannot read " + path, what);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

} // namespace dermis::cli
