// Characters: upload (.glb, or .gltf with its files), list, describe, delete, UV layout,
// base-colour texture.
#include "service_state.hpp"

#include "core/model_derived.hpp"
#include "core/preview.hpp"
#include "core/uv_diagnosis.hpp"
#include "io/frame_io.hpp"
#include "io/gltf_loader.hpp"
#include "common/sha256.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>

namespace dermis {

using namespace detail;

GltfLimits detail::gltfLimitsOf(const ServerLimits& limits) {
    GltfLimits g;
    g.maxTriangles = limits.maxTriangles;
    g.maxJoints = limits.maxJoints;
    g.maxImageSide = limits.maxImageSide;
    const std::size_t side = static_cast<std::size_t>(std::max(limits.maxImageSide, 1));
    g.maxTextureBytes = 16 * side * side;
    return g;
}

namespace {

Error bodyTooLarge(const ServerLimits& limits, const char* where) {
    return makeError(ErrorCode::TooLarge, where, "body",
                     "larger than " + std::to_string(limits.maxUploadBytes) + " bytes");
}

/// An uploaded model must have triangles and stay within the triangle and joint limits.
Status checkModel(const Model& m, const ServerLimits& limits, const char* where) {
    if (m.parts.empty()) return makeError(ErrorCode::InvalidArgument, where, "/meshes", "no triangle meshes");
    if (m.triangleCount() > limits.maxTriangles)
        return makeError(ErrorCode::TooLarge, where, "/meshes",
                         std::to_string(m.triangleCount()) + " triangles, the limit is " +
                             std::to_string(limits.maxTriangles));
    if (m.joints.size() > limits.maxJoints)
        return makeError(ErrorCode::TooLarge, where, "/skins",
                         std::to_string(m.joints.size()) + " joints, the limit is " +
                             std::to_string(limits.maxJoints));
    return Ok{};
}

json modelSummary(const ModelEntry& e) {
    return {{"id", e.id},
            {"name", e.name},
            {"builtin", e.builtin},
            {"triangles", e.model->triangleCount()},
            {"joints", e.model->joints.size()},
            {"clips", e.model->clips.size()},
            {"joint_count", e.model->joints.size()},
            {"has_uvs", e.model->hasUVs()},
            {"has_texture", e.model->dominantBaseColorImage() >= 0},
            {"bytes", e.bytes}};
}

/// At most this many regions each region's "shares_with" names (the rest are counted).
constexpr std::size_t kSharesWithNames = 8;

/// x rounded to 1/scale (scale a power of ten: the decimal digits print as they read).
double roundedTo(double x, double scale) { return std::round(x * scale) / scale; }

/// The `uv` member of GET /models/{id}: the model's UV diagnosis (SPEC §8, core uv_diagnosis).
json uvSummary(const UvDiagnosis& d) {
    json sharing = json::array();
    std::vector<std::size_t> order;
    for (std::size_t r = 0; r < d.regions.size(); ++r)
        if (d.regions[r].sharedTexels > 0) order.push_back(r);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return d.regions[a].sharedTexels > d.regions[b].sharedTexels;
    });
    for (std::size_t r : order) {
        const UvRegion& region = d.regions[r];
        json with = json::array();
        for (std::size_t k = 0; k < region.sharesWith.size() && k < kSharesWithNames; ++k)
            with.push_back({{"region", d.regions[static_cast<std::size_t>(region.sharesWith[k].first)].name},
                            {"texels", region.sharesWith[k].second}});
        sharing.push_back({{"region", region.name},
                           {"part", region.part},
                           {"joint", region.joint.empty() ? json() : json(region.joint)},
                           {"texels", region.texels},
                           {"shared_texels", region.sharedTexels},
                           {"folded_texels", region.foldedTexels},
                           {"shares_with", std::move(with)},
                           {"shares_with_more", region.sharesWith.size() > kSharesWithNames
                                                    ? region.sharesWith.size() - kSharesWithNames
                                                    : 0}});
    }
    json mirrored = json::array();
    for (const UvMirroredPair& p : d.mirroredPairs)
        mirrored.push_back({{"regions", {d.regions[static_cast<std::size_t>(p.regionA)].name,
                                         d.regions[static_cast<std::size_t>(p.regionB)].name}},
                            {"islands", p.islandPairs},
                            {"triangles", {p.trianglesA, p.trianglesB}}});
    json density = json::array();
    for (const UvJointDensity& j : d.density)
        density.push_back({{"joint", j.joint},
                           {"triangles", j.triangles},
                           {"texels_per_unit", roundedTo(j.texelsPerUnit, 10.0)}});
    return {{"has_uvs", d.hasUVs},
            {"usable", d.usable()},
            {"resolution", d.resolution},
            {"used_fraction", roundedTo(d.usedFraction, 1e5)},
            {"overlap_fraction", roundedTo(d.overlapFraction, 1e5)},
            {"used_texels", d.usedTexels},
            {"overlap_texels", d.overlapTexels},
            {"islands", d.islands},
            {"triangles", d.triangles},
            {"missing", {{"parts", d.partsWithoutUvs}, {"triangles", d.missingTriangles}}},
            {"out_of_range", {{"vertices", d.outOfRangeVertices}, {"triangles", d.outOfRangeTriangles}}},
            {"summary", d.describeSharing()},
            {"sharing", std::move(sharing)},
            {"mirrored_pairs", std::move(mirrored)},
            {"density", std::move(density)}};
}

/// The content address of a .gltf with its files: the SHA-256 over the main file's name, then
/// each file in name order as name, NUL, decimal size, NUL, bytes.
std::string gltfFilesId(const GltfFiles& named, const std::string& gltfName) {
    Sha256 h;
    h.update("gltf-files\n" + gltfName + '\n');
    for (const auto& [name, bytes] : named) {
        h.update(name + '\0' + std::to_string(bytes.size()) + '\0');
        h.update(bytes.data(), bytes.size());
    }
    return Store::contentId("m", toHex(h.finish()));
}

} // namespace

Result<Model> detail::decodeModelBytes(const std::vector<std::uint8_t>& bytes, const ServerLimits& limits,
                                       const char* where, const std::string& field) {
    if (bytes.size() > limits.maxUploadBytes)
        return makeError(ErrorCode::TooLarge, where, field, "larger than " + std::to_string(limits.maxUploadBytes) + " bytes");
    // No base folder: no file of this machine is read. The limits are checked from the declared
    // sizes before anything big is allocated; checkModel below is the backstop.
    const GltfLimits gl = gltfLimitsOf(limits);
    auto parsed = parseGltf(bytes, "", gl);
    if (!parsed) return parsed.error();
    if (auto s = loadGltfResources(*parsed, gl); !s) return s.error();
    if (auto st = checkModel(parsed->model, limits, where); !st) return st.error();
    return std::move(parsed->model);
}

std::optional<json> Service::storedModel(const std::string& id) const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->models.find(id);
    if (it == state_->models.end()) return std::nullopt;
    return modelSummary(it->second);
}

json Service::listModels() const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    json out = json::array();
    for (const auto& [id, e] : state_->models)
        out.push_back(modelSummary(e));
    return {{"models", out}};
}

Result<json> Service::addModel(const std::vector<std::uint8_t>& glb, const std::string& name,
                               bool* existing) {
    const char* where = "dermis::Service::addModel";
    if (existing) *existing = false;
    if (glb.size() > limits_.maxUploadBytes) return bodyTooLarge(limits_, where);
    if (glb.size() < 12 || std::memcmp(glb.data(), "glTF", 4) != 0)
        return makeError(ErrorCode::Unsupported, where, "body",
                         "not a binary glTF (.glb); send a .gltf with its files as multipart/form-data");
    // Content-addressed: the same bytes again answer the stored model (two identical uploads at
    // the same moment may both store it: same id, same bytes, the later name kept).
    // The id of a .glb: "m_" + 16 hex digits of its SHA-256.
    const std::string digest = toHex(sha256(glb));
    const std::string id = Store::contentId("m", digest);
    if (auto known = storedModel(id)) {
        if (existing) *existing = true;
        return *known;
    }
    auto model = decodeModelBytes(glb, limits_, where, "body");
    if (!model) return model.error();
    ModelEntry e{id, sanitizeName(name), std::make_shared<const Model>(std::move(*model)), glb.size(),
                 false, digest};
    return state_->addModelEntry(std::move(e), [&](Store& store, const json& meta) {
        return store.putBlob("models", id, "glb", glb, meta);
    });
}

Result<json> Service::addModelFiles(const std::vector<UploadFile>& files, const std::string& gltfName,
                                    const std::string& name, bool* existing) {
    const char* where = "dermis::Service::addModelFiles";
    if (existing) *existing = false;
    std::size_t total = 0;
    for (const UploadFile& f : files) {
        total += f.bytes.size();
        if (total > limits_.maxUploadBytes) return bodyTooLarge(limits_, where);
    }
    GltfFiles named;
    for (const UploadFile& f : files) {
        if (!Store::isSafeFileName(f.name))
            return makeError(ErrorCode::InvalidArgument, where, "files/" + f.name,
                             "a file name must be plain ([A-Za-z0-9._ -], no folders)");
        if (!named.emplace(f.name, f.bytes).second)
            return makeError(ErrorCode::InvalidArgument, where, "files/" + f.name, "given twice");
    }
    if (gltfName.empty() || !named.count(gltfName))
        return makeError(ErrorCode::InvalidArgument, where, "gltf",
                         "no .gltf part (name the part \"gltf\" or give it a .gltf file name)");
    const std::string id = gltfFilesId(named, gltfName);
    if (auto known = storedModel(id)) {
        if (existing) *existing = true;
        return *known;
    }
    // Parsed from memory: the .gltf's URIs resolve to the uploaded files only.
    auto model = loadGltfFromFiles(named, gltfName, gltfLimitsOf(limits_));
    if (!model) return model.error();
    if (auto st = checkModel(*model, limits_, where); !st) return st.error();
    ModelEntry e{id, sanitizeName(name.empty() ? gltfName : name),
                 std::make_shared<const Model>(std::move(*model)), total, false, ""};
    return state_->addModelEntry(std::move(e), [&](Store& store, const json& meta) {
        return store.putBlobFolder("models", id, named, gltfName, meta);
    });
}

Result<json> Service::State::addModelEntry(ModelEntry e,
                                           const std::function<Status(Store&, const json&)>& write) {
    std::lock_guard<std::mutex> writer(writeMutex);
    if (auto s = write(*store, {{"name", e.name}, {"bytes", e.bytes}, {"created", nowSeconds()}}); !s)
        return withoutDataPath(s.error(), store->dir());
    json summary = modelSummary(e);
    std::unique_lock<std::shared_mutex> lock(mutex);
    models[e.id] = std::move(e);
    return summary;
}

Result<json> Service::getModel(const std::string& id) const {
    ModelEntry entry; // a copy (shared pointers): the diagnosis is built without the lock
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto it = state_->models.find(id);
        if (it == state_->models.end()) return notFound("id", "no model \"" + id + "\"");
        entry = it->second;
    }
    const Model& m = *entry.model;
    json out = modelSummary(entry);
    json joints = json::array();
    for (int n : m.joints) {
        const Node& node = m.nodes[static_cast<std::size_t>(n)];
        const int parent = m.parentJoint(n);
        const glm::quat& q = node.rotation;
        joints.push_back({{"name", node.name},
                          {"parent", parent >= 0 ? json(m.nodes[static_cast<std::size_t>(parent)].name) : json()},
                          {"rest_rotation", {q.x, q.y, q.z, q.w}}});
    }
    json clips = json::array();
    for (const Clip& c : m.clips)
        clips.push_back({{"name", c.name}, {"duration", c.duration}});
    std::size_t vertices = 0;
    for (const MeshPart& p : m.parts)
        vertices += p.positions.size();
    out["joints"] = std::move(joints);
    out["clips"] = std::move(clips);
    json morphs = json::array(); // by name, each once (pose.morphs sets every weight of a name)
    std::set<std::string> named;
    for (const MorphWeight& w : m.morphWeights)
        if (named.insert(w.name).second) morphs.push_back({{"name", w.name}, {"rest", w.rest}});
    out["morphs"] = std::move(morphs);
    // Parts by where their normal-map tangents come from (core/tangents.hpp generates them).
    std::size_t fromFile = 0, generated = 0, none = 0;
    for (const MeshPart& p : m.parts)
        (p.tangents.empty() ? none : p.tangentsGenerated ? generated : fromFile) += 1;
    out["tangents"] = {{"file", fromFile}, {"generated", generated}, {"none", none}};
    out["vertices"] = vertices;
    // Built once per model entry (ids are content addresses: cached by content), then shared
    // with lint and the picks.
    const auto derived = entry.derived ? entry.derived->get(entry.model) : std::make_shared<const ModelDerived>(entry.model);
    out["uv"] = uvSummary(derived->uvDiagnosis());
    return out;
}

Status Service::deleteModel(const std::string& id) {
    std::lock_guard<std::mutex> write(state_->writeMutex);
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto it = state_->models.find(id);
        if (it == state_->models.end()) return notFound("id", "no model \"" + id + "\"");
        if (it->second.builtin)
            return makeError(ErrorCode::Conflict, "dermis::Service", "id", "built-in models cannot be deleted");
        for (const auto& [sid, s] : state_->scenes)
            if (s.scene->model == id)
                return makeError(ErrorCode::Conflict, "dermis::Service", "id",
                                 "model \"" + id + "\" is used by scene " + sid);
    }
    if (auto s = state_->store->removeBlob("models", id); !s) return s;
    std::shared_ptr<const Model> model;
    {
        std::unique_lock<std::shared_mutex> lock(state_->mutex);
        model = state_->models[id].model;
        state_->models.erase(id); // renders that hold the model keep it alive until they finish
    }
    // Its GPU buffers and textures go too (queued: never waits for a render).
    state_->renderer->forgetModel(model);
    model.reset();
    returnFreedMemory();
    return Ok{};
}


Result<EncodedImage> Service::modelTexture(const std::string& id, std::optional<int> maxSide) const {
    if (maxSide && (*maxSide < 16 || *maxSide > 4096)) return bad("size", "must be in [16, 4096]");
    std::shared_ptr<const Model> model;
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto it = state_->models.find(id);
        if (it == state_->models.end()) return notFound("id", "no model \"" + id + "\"");
        model = it->second.model; // kept alive while encoding, without the lock
    }
    const int image = model->dominantBaseColorImage();
    if (image < 0) return notFound("texture", "model \"" + id + "\" has no base-colour texture");
    const Image8& src = model->images[static_cast<std::size_t>(image)];
    bool opaque = true;
    for (std::size_t k = 3; k < src.rgba.size() && opaque; k += 4) opaque = src.rgba[k] == 255;
    auto png = maxSide ? encodePng(downsizeImage(src, *maxSide), !opaque) : encodePng(src, !opaque);
    if (!png) return png.error();
    return EncodedImage{std::move(*png), "image/png", ""};
}

} // namespace dermis
