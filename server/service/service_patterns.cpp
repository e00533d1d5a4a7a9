// Pattern images: built-in library and uploads; list, preview, delete.
#include "service_state.hpp"

#include "core/preview.hpp"
#include "io/frame_io.hpp"
#include "io/image_header.hpp"
#include "io/image_io.hpp"
#include "common/sha256.hpp"

#include <algorithm>

namespace dermis {

using namespace detail;

namespace {

json patternSummary(const PatternEntry& e, const HeightImage* img) {
    json j = {{"id", e.id}, {"name", e.name}, {"builtin", e.builtin}};
    if (img) {
        j["width"] = img->width;
        j["height"] = img->height;
    }
    if (e.info) {
        j["kind"] = std::string(toString(e.info->kind));
        j["model"] = std::string(toString(e.info->model));
        j["target"] = std::string(toString(e.info->target));
        j["joint"] = e.info->joint;
        j["axis"] = e.info->axis;
        j["theta_min"] = e.info->thetaMin;
        j["theta_max"] = e.info->thetaMax;
        j["description"] = e.info->description;
    } else {
        j["bytes"] = e.bytes;
    }
    return j;
}

std::string sniffExtension(const std::vector<std::uint8_t>& b) {
    auto starts = [&](std::initializer_list<std::uint8_t> m) {
        return b.size() >= m.size() && std::equal(m.begin(), m.end(), b.begin());
    };
    if (starts({0x89, 'P', 'N', 'G'})) return "png";
    if (starts({0xFF, 0xD8, 0xFF})) return "jpg";
    if (starts({'I', 'I', 42, 0}) || starts({'M', 'M', 0, 42})) return "tif";
    if (starts({0x76, 0x2F, 0x31, 0x01})) return "exr";
    if (starts({'8', 'B', 'P', 'S'})) return "psd";
    return "img";
}

} // namespace

Result<HeightImage> detail::decodePatternBytes(const std::vector<std::uint8_t>& bytes, const ServerLimits& limits,
                                               const char* where, const std::string& field, DecodeBudget* budget) {
    if (bytes.size() > limits.maxUploadBytes)
        return makeError(ErrorCode::TooLarge, where, field, "larger than " + std::to_string(limits.maxUploadBytes) + " bytes");
    // PNG and JPEG sides from their headers before anything is decoded: a small file declaring
    // 8192² would otherwise cost the decode (hundreds of MB) before the limit refuses it.
    const auto tooLarge = [&](std::uint64_t w, std::uint64_t h) {
        return makeError(ErrorCode::TooLarge, where, field,
                         "image is " + std::to_string(w) + "x" + std::to_string(h) + ", the limit is " +
                             std::to_string(limits.maxImageSide) + " per side");
    };
    if (auto declared = encodedImageSize(bytes.data(), bytes.size());
        declared && (declared->width > static_cast<std::uint32_t>(limits.maxImageSide) ||
                     declared->height > static_cast<std::uint32_t>(limits.maxImageSide)))
        return tooLarge(declared->width, declared->height);
    // The decode's memory, reserved before it starts: pixels as decoded (up to 4 bytes) plus the
    // float map (4 bytes), from the declared size, else the worst case the side limit allows.
    std::optional<DecodeBudget::Lease> lease;
    if (budget) {
        const auto side = static_cast<std::uint64_t>(std::max(limits.maxImageSide, 1));
        const auto declared = encodedImageSize(bytes.data(), bytes.size());
        const std::uint64_t pixels = declared ? std::uint64_t(declared->width) * declared->height : side * side;
        auto reserved = budget->reserve(static_cast<std::size_t>(pixels * 8), std::chrono::seconds(2), field);
        if (!reserved) return reserved.error();
        lease.emplace(std::move(*reserved));
    }
    auto img = readHeightImageFromMemory(bytes, limits.maxImageSide);
    if (!img) {
        Error e = img.error();
        if (e.field.empty()) e.field = field; // the image as a whole: the upload's body, the batch's part
        return e;
    }
    if (img->width > limits.maxImageSide || img->height > limits.maxImageSide)
        return tooLarge(static_cast<std::uint64_t>(img->width), static_cast<std::uint64_t>(img->height));
    return img;
}

json Service::listPatterns() const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    json out = json::array();
    for (const auto& [id, e] : state_->patterns) {
        auto img = state_->images.find(id);
        out.push_back(patternSummary(e, img == state_->images.end() ? nullptr : &img->second->pixels));
    }
    return {{"patterns", out}};
}

Result<json> Service::addPattern(const std::vector<std::uint8_t>& bytes, const std::string& name,
                                 bool* existing) {
    const char* where = "dermis::Service::addPattern";
    if (existing) *existing = false;
    if (bytes.size() > limits_.maxUploadBytes)
        return makeError(ErrorCode::TooLarge, where, "body",
                         "larger than " + std::to_string(limits_.maxUploadBytes) + " bytes");
    // Content-addressed: the same bytes again answer the stored pattern (two identical uploads at
    // the same moment may both store it: same id, same bytes, the later name kept).
    const std::string digest = toHex(sha256(bytes));
    const std::string id = Store::contentId("p", digest);
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto known = state_->patterns.find(id);
        if (known != state_->patterns.end()) {
            auto img = state_->images.find(id);
            if (existing) *existing = true;
            return patternSummary(known->second, img == state_->images.end() ? nullptr : &img->second->pixels);
        }
    }
    auto img = decodePatternBytes(bytes, limits_, where, "body", state_->decodeBudget.get());
    if (!img) return img.error();
    PatternEntry e;
    e.id = id;
    e.sha256 = digest;
    e.name = sanitizeName(name);
    e.bytes = bytes.size();
    auto stored = makePatternImage(std::move(*img));
    json summary = patternSummary(e, &stored->pixels);
    std::lock_guard<std::mutex> write(state_->writeMutex);
    if (auto s = state_->store->putBlob("patterns", e.id, sniffExtension(bytes), bytes,
                                        {{"name", e.name}, {"bytes", e.bytes}, {"created", nowSeconds()}});
        !s)
        return withoutDataPath(s.error(), state_->store->dir());
    std::unique_lock<std::shared_mutex> lock(state_->mutex);
    state_->images[e.id] = std::move(stored);
    state_->patterns[e.id] = std::move(e);
    return summary;
}

Result<EncodedImage> Service::patternImage(const std::string& id, int size) const {
    if (size < 1 || size > 2048) return bad("size", "must be in [1, 2048]");
    std::shared_ptr<const PatternImage> src;
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto it = state_->images.find(id);
        if (it == state_->images.end() || !state_->patterns.count(id))
            return notFound("id", "no pattern \"" + id + "\"");
        src = it->second;
    }
    auto png = encodePng(heightPreview(src->pixels, size), false);
    if (!png) return png.error();
    return EncodedImage{std::move(*png), "image/png", ""};
}

Status Service::deletePattern(const std::string& id) {
    std::lock_guard<std::mutex> write(state_->writeMutex);
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto it = state_->patterns.find(id);
        if (it == state_->patterns.end()) return notFound("id", "no pattern \"" + id + "\"");
        if (it->second.builtin)
            return makeError(ErrorCode::Conflict, "dermis::Service", "id", "built-in patterns cannot be deleted");
        for (const auto& [sid, s] : state_->scenes) {
            bool used = s.scene->heightmapBase && *s.scene->heightmapBase == id;
            for (const auto& [alias, target] : s.scene->patterns)
                used = used || target == id;
            if (used)
                return makeError(ErrorCode::Conflict, "dermis::Service", "id",
                                 "pattern \"" + id + "\" is used by scene " + sid);
        }
    }
    if (auto s = state_->store->removeBlob("patterns", id); !s) return s;
    std::uint64_t contentId = 0;
    {
        std::unique_lock<std::shared_mutex> lock(state_->mutex);
        if (auto img = state_->images.find(id); img != state_->images.end()) contentId = img->second->contentId;
        state_->images.erase(id); // a render in flight keeps its copy alive
        state_->patterns.erase(id);
    }
    // Its GPU texture goes too (queued: never waits for a render).
    if (contentId) state_->renderer->forgetPattern(contentId);
    returnFreedMemory();
    return Ok{};
}

} // namespace dermis
