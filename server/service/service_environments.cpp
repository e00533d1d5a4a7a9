// Environments for image-based light (`render.environment`, issue #26): uploaded Radiance .hdr
// and OpenEXR images, content-addressed like patterns; list, add, delete; decoded for a render.
#include "service_state.hpp"

#include "io/atomic_file.hpp"
#include "io/image_io.hpp"
#include "common/sha256.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>

namespace dermis {

using namespace detail;

namespace {

json environmentSummary(const EnvironmentEntry& e) {
    json j = {{"id", e.id}, {"name", e.name}, {"builtin", e.builtin}};
    if (!e.builtin) {
        j["width"] = e.width;
        j["height"] = e.height;
        j["bytes"] = e.bytes;
    }
    return j;
}

/// "hdr" for a Radiance file ("#?RADIANCE", "#?RGBE", any "#?" signature), "exr" for OpenEXR's
/// magic number; "" for anything else.
std::string environmentExtension(const std::vector<std::uint8_t>& b) {
    if (b.size() >= 2 && b[0] == '#' && b[1] == '?') return "hdr";
    if (b.size() >= 4 && b[0] == 0x76 && b[1] == 0x2F && b[2] == 0x31 && b[3] == 0x01) return "exr";
    return "";
}

} // namespace

Result<EnvironmentImage> detail::decodeEnvironmentBytes(const std::vector<std::uint8_t>& bytes,
                                                        const std::string& dataDir, int maxSide,
                                                        const std::string& field) {
    const char* where = "dermis::decodeEnvironmentBytes";
    const std::string ext = environmentExtension(bytes);
    if (ext.empty())
        return makeError(ErrorCode::Parse, where, field, "expected a Radiance .hdr or an OpenEXR image of linear radiance");
    const std::string temp = dataDir + "/environments/" + Store::newId("u") + kTempMarker + "upload." + ext;
    if (auto s = writeFileAtomically(temp, bytes); !s) return withoutDataPath(s.error(), dataDir);
    auto image = readEnvironmentImage(temp, maxSide);
    std::error_code ec;
    std::filesystem::remove(temp, ec);
    if (!image) {
        Error e = withoutDataPath(image.error(), dataDir);
        e.field = field;
        if (e.code == ErrorCode::NotFound) e.code = ErrorCode::Parse;
        return e;
    }
    return image;
}

json Service::listEnvironments() const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    json out = json::array();
    EnvironmentEntry studio;
    studio.id = kBuiltinStudioEnvironment;
    studio.name = "studio";
    studio.builtin = true;
    out.push_back(environmentSummary(studio));
    for (const auto& [id, e] : state_->environments)
        out.push_back(environmentSummary(e));
    return {{"environments", out}};
}

Result<json> Service::addEnvironment(const std::vector<std::uint8_t>& bytes, const std::string& name,
                                     bool* existing) {
    const char* where = "dermis::Service::addEnvironment";
    if (existing) *existing = false;
    if (bytes.size() > limits_.maxUploadBytes)
        return makeError(ErrorCode::TooLarge, where, "body",
                         "larger than " + std::to_string(limits_.maxUploadBytes) + " bytes");
    const std::string ext = environmentExtension(bytes);
    if (ext.empty())
        return makeError(ErrorCode::Parse, where, "body",
                         "expected a Radiance .hdr or an OpenEXR image of linear radiance");
    const std::string digest = toHex(sha256(bytes));
    const std::string id = Store::contentId("e", digest);
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        if (auto known = state_->environments.find(id); known != state_->environments.end()) {
            if (existing) *existing = true;
            return environmentSummary(known->second);
        }
    }
    // Decoded first, outside the write lock (scene edits do not wait for a decode), then stored
    // with its size.
    const std::string folder = state_->store->dir() + "/environments/";
    auto image = decodeEnvironmentBytes(bytes, state_->store->dir(), limits_.maxImageSide, "body");
    if (!image) return image.error();
    std::lock_guard<std::mutex> write(state_->writeMutex);
    if (auto s = state_->store->putBlob("environments", id, ext, bytes,
                                        {{"name", sanitizeName(name)}, {"bytes", bytes.size()},
                                         {"width", image->width}, {"height", image->height},
                                         {"created", nowSeconds()}});
        !s)
        return withoutDataPath(s.error(), state_->store->dir());
    const std::string file = folder + id + "." + ext;
    EnvironmentEntry e;
    e.id = id;
    e.name = sanitizeName(name);
    e.file = file;
    e.bytes = bytes.size();
    e.width = image->width;
    e.height = image->height;
    json summary = environmentSummary(e);
    {
        std::lock_guard<std::mutex> cache(state_->environmentCacheMutex);
        state_->environmentCache = {id, std::make_shared<const EnvironmentImage>(std::move(*image))};
    }
    std::unique_lock<std::shared_mutex> lock(state_->mutex);
    state_->environments[id] = std::move(e);
    return summary;
}

Status Service::deleteEnvironment(const std::string& id) {
    std::lock_guard<std::mutex> write(state_->writeMutex);
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        if (id == kBuiltinStudioEnvironment)
            return makeError(ErrorCode::Conflict, "dermis::Service", "id",
                             "the built-in environment cannot be deleted");
        if (!state_->environments.count(id)) return notFound("id", "no environment \"" + id + "\"");
        for (const auto& [sid, s] : state_->scenes)
            if (s.scene->render.environment == id)
                return makeError(ErrorCode::Conflict, "dermis::Service", "id",
                                 "environment \"" + id + "\" is used by scene " + sid);
    }
    if (auto s = state_->store->removeBlob("environments", id); !s) return s;
    {
        std::unique_lock<std::shared_mutex> lock(state_->mutex);
        state_->environments.erase(id);
    }
    {
        std::lock_guard<std::mutex> cache(state_->environmentCacheMutex);
        if (state_->environmentCache.first == id) state_->environmentCache = {};
    }
    returnFreedMemory();
    return Ok{};
}

Result<std::shared_ptr<const EnvironmentImage>> Service::State::environmentImage(const std::string& id) const {
    if (id.empty() || id == kBuiltinStudioEnvironment) return std::shared_ptr<const EnvironmentImage>();
    std::string file;
    {
        std::shared_lock<std::shared_mutex> lock(mutex);
        auto it = environments.find(id);
        if (it == environments.end()) return notFound("/render/environment", "no environment \"" + id + "\"");
        file = it->second.file;
    }
    std::lock_guard<std::mutex> cache(environmentCacheMutex);
    if (environmentCache.first == id) return environmentCache.second;
    auto image = readEnvironmentImage(file, limits.maxImageSide);
    if (!image) {
        Error e = withoutDataPath(image.error(), store->dir());
        e.field = "/render/environment";
        return e;
    }
    environmentCache = {id, std::make_shared<const EnvironmentImage>(std::move(*image))};
    return environmentCache.second;
}

} // namespace dermis
