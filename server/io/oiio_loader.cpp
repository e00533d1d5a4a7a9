// Loading libdermis_oiio.so on first use. See oiio_loader.hpp.
#include "io/oiio_loader.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <vector>

#ifndef DERMIS_OIIO_MODULE_BUILD_PATH
#define DERMIS_OIIO_MODULE_BUILD_PATH ""
#endif

namespace dermis::oiio {
namespace {

constexpr const char* kWhere = "dermis::oiio::oiioApi";

/// Candidate paths, most specific first (see the header).
std::vector<std::string> candidatePaths() {
    if (const char* env = std::getenv("DERMIS_OIIO_MODULE"); env && *env) return {env};
    std::vector<std::string> paths;
    auto add = [&](const std::string& p) {
        if (!p.empty() && std::find(paths.begin(), paths.end(), p) == paths.end()) paths.push_back(p);
    };
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) add((exe.parent_path() / kModuleFileName).string());
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&candidatePaths), &info) && info.dli_fname)
        add((std::filesystem::path(info.dli_fname).parent_path() / kModuleFileName).string());
    add(DERMIS_OIIO_MODULE_BUILD_PATH);
    return paths;
}

} // namespace

Result<const OiioApi*> loadOiioModule(const std::string& path) {
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        const char* why = dlerror();
        return makeError(ErrorCode::Unavailable, kWhere, kModuleFileName,
                         "cannot load the image module " + path + ": " + (why ? why : "unknown"));
    }
    using Entry = const OiioApi* (*)();
    auto entry = reinterpret_cast<Entry>(dlsym(handle, "dermis_oiio_api"));
    const OiioApi* api = entry ? entry() : nullptr;
    if (!api || api->abiVersion != kAbiVersion) {
        dlclose(handle);
        return makeError(ErrorCode::Unavailable, kWhere, kModuleFileName,
                         path + (api ? " is a different version of the image module (ABI " +
                                           std::to_string(api->abiVersion) + ", want " +
                                           std::to_string(kAbiVersion) + ")"
                                     : " is not the image module (no dermis_oiio_api)"));
    }
    return api;
}

Result<const OiioApi*> oiioApi() {
    static std::mutex mutex;
    static const OiioApi* loaded = nullptr;
    std::lock_guard<std::mutex> lock(mutex);
    if (loaded) return loaded;
    std::string reasons;
    for (const std::string& path : candidatePaths()) {
        auto api = loadOiioModule(path);
        if (api) return loaded = *api;
        reasons += (reasons.empty() ? "" : "; ") + api.error().message;
    }
    return makeError(ErrorCode::Unavailable, kWhere, kModuleFileName,
                     std::string("the image module ") + kModuleFileName +
                         " (OpenImageIO: EXR and formats other than PNG and JPEG) cannot be "
                         "loaded; put it beside the executable or set DERMIS_OIIO_MODULE (" +
                         reasons + ")");
}

} // namespace dermis::oiio
