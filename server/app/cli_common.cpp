#include "app/cli_common.hpp"

#include <filesystem>
#include <iostream>

namespace dermis::app {

int fail(const Error& e) {
    std::cerr << "dermis-server: error: " << e.message << "\n";
    return 1;
}

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

GlBackend backendOf(const std::string& name) {
    return glBackendFromString(name).value_or(GlBackend::Auto);
}

const std::vector<std::string> kBackendNames = {"auto", "egl-device", "egl-surfaceless", "osmesa"};

Status createFolderOf(const std::string& file) {
    const std::filesystem::path parent = std::filesystem::path(file).parent_path();
    if (parent.empty()) return Ok{};
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
    if (ec)
        return makeError(ErrorCode::Io, "dermis-server", parent.string(),
                         "cannot create the output folder: " + ec.message());
    return Ok{};
}

} // namespace dermis::app
