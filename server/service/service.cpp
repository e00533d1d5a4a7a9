#include "service/service.hpp"

#include "core/bake.hpp"
#include "core/normalmap.hpp"
#include "core/frame_plan.hpp"
#include "io/frame_io.hpp"
#include "io/gltf_loader.hpp"
#include "io/image_io.hpp"
#include "io/scene_files.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>

namespace dermis {

using json = nlohmann::json;
namespace fs = std::filesystem;

json ServerLimits::toJson() const {
    return {{"max_upload_bytes", maxUploadBytes}, {"max_image_side", maxImageSide},
            {"max_map_side", maxMapSide},         {"max_render_side", maxRenderSide},
            {"max_triangles", maxTriangles},      {"max_joints", maxJoints},
            {"max_placements", maxPlacements},    {"queue_length", queueLength},
            {"request_timeout_seconds", requestTimeoutSeconds},
            {"max_batch_frames", maxBatchFrames}};
}

// --- subscriptions ------------------------------------------------------------------------------

std::optional<std::string> Subscription::next(int timeoutMs) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_for(lock, std::chrono::milliseconds(timeoutMs),
                 [&] { return closed_ || !events_.empty(); });
    if (events_.empty()) return std::nullopt;
    std::string e = std::move(events_.front());
    events_.pop_front();
    return e;
}

void Subscription::push(std::string event) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (closed_ || events_.size() > 1000) return; // a stalled reader does not grow memory
        events_.push_back(std::move(event));
    }
    cv_.notify_all();
}

void Subscription::close() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
    }
    cv_.notify_all();
}

bool Subscription::closed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_;
}

// --- state --------------------------------------------------------------------------------------

namespace {

constexpr const char* kBuiltinDefault = "builtin:default";

struct ModelEntry {
    std::string id, name;
    std::shared_ptr<const Model> model;
    std::size_t bytes = 0;
    bool builtin = false;
};

struct PatternEntry {
    std::string id, name;
    bool builtin = false;
    std::size_t bytes = 0;
    const PatternInfo* info = nullptr; ///< manifest entry of a built-in pattern
};

struct SceneEntry {
    json doc; ///< canonical document (toJson of scene)
    Scene scene;
    std::uint64_t revision = 1;
};

double nowSeconds() {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string sanitizeName(const std::string& name) {
    std::string out;
    for (char c : name)
        if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == ' ')
            out += c;
    if (out.size() > 64) out.resize(64);
    return out;
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

Error bad(const std::string& field, const std::string& what) {
    return makeError(ErrorCode::InvalidArgument, "dermis::Service", field, what);
}
Error notFound(const std::string& field, const std::string& what) {
    return makeError(ErrorCode::NotFound, "dermis::Service", field, what);
}

} // namespace

struct Service::State {
    std::optional<Store> store;
    std::unique_ptr<Renderer> renderer;
    PatternManifest manifest;
    json defaultSceneDoc;

    mutable std::shared_mutex mutex; ///< models, patterns metadata, scenes
    std::map<std::string, ModelEntry> models;
    std::map<std::string, PatternEntry> patterns;
    std::map<std::string, SceneEntry> scenes;

    /// Pattern images by id (built-in and uploaded). Renders read it under a shared lock of
    /// `imagesMutex`; uploads and deletions change it under an exclusive one, so a render never
    /// sees an image disappear. Lock order: mutex, then imagesMutex.
    mutable std::shared_mutex imagesMutex;
    PatternImages images;

    std::mutex subsMutex;
    std::multimap<std::string, std::shared_ptr<Subscription>> subs;

    std::atomic<int> inFlight{0};
    ServerLimits limits;

    /// The scene a document describes, validated against this server's models and patterns.
    struct Prepared {
        Scene scene;
        json canonical;
        std::shared_ptr<const Model> model;
    };
    Result<Prepared> prepare(const json& doc) const; // caller holds `mutex` (shared or exclusive)
    Scene resolved(const Scene& scene) const;        // placement patterns alias → id
    /// A copy of scene `id` and its model, taken under the shared lock (renders then run unlocked).
    struct Snapshot {
        Scene scene;
        std::shared_ptr<const Model> model;
    };
    Result<Snapshot> snapshot(const std::string& id) const;
    std::shared_ptr<const PatternImage> baseOf(const Scene& scene) const;
    void publish(const std::string& sceneId, const json& event);
    Result<json> commit(const std::string& id, const json& newDoc, const char* what, bool create);
    /// Locks, copies scene `id`'s document, lets `change` modify the copy, then commits it.
    Result<json> edit(const std::string& id, const char* what, const std::function<Status(json&)>& change);
    Result<EncodedImage> render(const Scene& scene, const std::shared_ptr<const Model>& model,
                                const FrameParams& p);
};

Result<Service::State::Prepared> Service::State::prepare(const json& docIn) const {
    if (!docIn.is_object()) return bad("", "a scene document must be a JSON object");
    json doc = docIn;
    // Uploaded pattern ids may be used directly as placement patterns: alias them to themselves.
    if (auto pl = doc.find("placements"); pl != doc.end() && pl->is_array()) {
        for (const json& p : *pl) {
            if (!p.is_object()) continue;
            auto pat = p.find("pattern");
            if (pat == p.end() || !pat->is_string()) continue;
            const std::string id = pat->get<std::string>();
            auto it = patterns.find(id);
            if (it == patterns.end() || it->second.builtin) continue;
            if (!doc.contains("patterns")) doc["patterns"] = json::object();
            if (doc["patterns"].is_object() && !doc["patterns"].contains(id)) doc["patterns"][id] = id;
        }
    }
    // Only ids: never a path of this machine.
    if (auto pm = doc.find("patterns"); pm != doc.end() && pm->is_object())
        for (auto it = pm->begin(); it != pm->end(); ++it) {
            const std::string field = "/patterns/" + jsonPointerEscape(it.key());
            if (!it->is_string()) continue; // parseScene reports the type
            const std::string v = it->get<std::string>();
            auto found = patterns.find(v);
            if (found == patterns.end() || found->second.builtin)
                return notFound(field, "must name an uploaded pattern id (p_…), got \"" + v + "\"");
        }
    if (auto hm = doc.find("heightmap"); hm != doc.end() && hm->is_object())
        if (auto base = hm->find("base"); base != hm->end() && base->is_string()) {
            const std::string v = base->get<std::string>();
            auto found = patterns.find(v);
            if (found == patterns.end() || found->second.builtin)
                return notFound("/heightmap/base", "must name an uploaded pattern id (p_…), got \"" + v + "\"");
        }
    auto scene = parseScene(doc, manifest);
    if (!scene) return scene.error();
    auto model = models.find(scene->model);
    if (model == models.end())
        return notFound("/model", "no model \"" + scene->model + "\" (use builtin:default or an uploaded id)");
    if (scene->placements.size() > limits.maxPlacements)
        return makeError(ErrorCode::TooLarge, "dermis::Service", "/placements",
                         "more than " + std::to_string(limits.maxPlacements) + " placements");
    for (int k = 0; k < 2; ++k) {
        if (scene->heightmapSize[static_cast<std::size_t>(k)] > limits.maxMapSide)
            return makeError(ErrorCode::TooLarge, "dermis::Service", "/heightmap/size/" + std::to_string(k),
                             "exceeds the server's limit " + std::to_string(limits.maxMapSide));
        if (scene->render.size[static_cast<std::size_t>(k)] > limits.maxRenderSide)
            return makeError(ErrorCode::TooLarge, "dermis::Service", "/render/size/" + std::to_string(k),
                             "exceeds the server's limit " + std::to_string(limits.maxRenderSide));
    }
    // The document must work on its model: clip and joints exist, patterns resolve, UVs present.
    const Model& m = *model->second.model;
    auto pose = evaluatePose(m, scene->pose);
    if (!pose) return pose.error();
    {
        std::shared_lock<std::shared_mutex> il(imagesMutex);
        auto placements = resolvePlacements(resolved(*scene), m, *pose, images);
        if (!placements) return placements.error();
    }
    Prepared out;
    out.canonical = toJson(*scene);
    out.scene = std::move(*scene);
    out.model = model->second.model;
    return out;
}

Result<Service::State::Snapshot> Service::State::snapshot(const std::string& id) const {
    std::shared_lock<std::shared_mutex> lock(mutex);
    auto it = scenes.find(id);
    if (it == scenes.end()) return notFound("id", "no scene \"" + id + "\"");
    return Snapshot{it->second.scene, models.at(it->second.scene.model).model};
}

Scene Service::State::resolved(const Scene& scene) const {
    Scene s = scene;
    for (Placement& p : s.placements)
        if (auto it = scene.patterns.find(p.pattern); it != scene.patterns.end()) p.pattern = it->second;
    return s;
}

std::shared_ptr<const PatternImage> Service::State::baseOf(const Scene& scene) const {
    if (!scene.heightmapBase) return nullptr;
    auto it = images.find(*scene.heightmapBase);
    return it == images.end() ? nullptr : it->second;
}

void Service::State::publish(const std::string& sceneId, const json& event) {
    const std::string text = "event: change\ndata: " + event.dump() + "\n\n";
    std::lock_guard<std::mutex> lock(subsMutex);
    auto [a, b] = subs.equal_range(sceneId);
    for (auto it = a; it != b; ++it)
        it->second->push(text);
}

/// Validates `newDoc`, writes it durably, swaps it in and announces it. Caller holds `mutex`
/// exclusively.
Result<json> Service::State::commit(const std::string& id, const json& newDoc, const char* what,
                                    bool create) {
    auto prepared = prepare(newDoc);
    if (!prepared) return prepared.error();
    const std::uint64_t revision = create ? 1 : scenes.at(id).revision + 1;
    if (auto s = store->putScene(id, revision, prepared->canonical); !s) return s.error();
    SceneEntry& e = scenes[id];
    e.doc = prepared->canonical;
    e.scene = std::move(prepared->scene);
    e.revision = revision;
    publish(id, {{"type", what}, {"scene", id}, {"revision", revision}});
    return json{{"id", id}, {"revision", revision}, {"scene", e.doc}};
}

Result<json> Service::State::edit(const std::string& id, const char* what,
                                  const std::function<Status(json&)>& change) {
    std::unique_lock<std::shared_mutex> lock(mutex);
    auto it = scenes.find(id);
    if (it == scenes.end()) return notFound("id", "no scene \"" + id + "\"");
    json doc = it->second.doc;
    if (auto s = change(doc); !s) return s.error();
    return commit(id, doc, what, false);
}

Result<EncodedImage> Service::State::render(const Scene& sceneIn,
                                            const std::shared_ptr<const Model>& model,
                                            const FrameParams& p) {
    Scene scene = resolved(sceneIn);
    FrameOverrides o;
    o.width = p.width;
    o.height = p.height;
    o.msaa = p.msaa;
    o.yaw = p.yaw;
    o.pitch = p.pitch;
    o.distance = p.distance;
    o.time = p.time;
    Result<FrameResult> result = makeError(ErrorCode::Internal, "dermis::Service", "", "not rendered");
    {
        std::shared_lock<std::shared_mutex> il(imagesMutex);
        RenderLimits rl;
        rl.maxSide = limits.maxRenderSide;
        auto plan = planFrame(scene, *model, images, baseOf(scene), o, rl);
        if (!plan) return plan.error();
        result = renderer->renderFrame(frameRequest(*plan, model));
    }
    if (!result) return result.error();
    EncodedImage out;
    out.backend = renderer->info().backend;
    auto bytes = p.format == "jpeg" ? encodeJpeg(result->image, 90) : encodePng(result->image, false);
    if (!bytes) return bytes.error();
    out.bytes = std::move(*bytes);
    out.contentType = p.format == "jpeg" ? "image/jpeg" : "image/png";
    return out;
}

// --- open ---------------------------------------------------------------------------------------

Result<std::unique_ptr<Service>> Service::open(const std::string& dataDir, GlBackend backend,
                                               const ServerLimits& limits) {
    std::unique_ptr<Service> svc(new Service());
    svc->limits_ = limits;
    svc->state_ = std::make_unique<State>();
    State& st = *svc->state_;
    st.limits = limits;
    auto store = Store::open(dataDir);
    if (!store) return store.error();
    st.store = std::move(*store);

    // Built-in content.
    auto manifest = loadBuiltinManifest();
    if (!manifest) return manifest.error();
    st.manifest = std::move(*manifest);
    for (const PatternInfo& info : st.manifest.patterns) {
        auto img = readHeightImage(dermisDataDir() + "/patterns/" + info.file);
        if (!img) return img.error();
        st.images[info.id] = makePatternImage(std::move(*img));
        st.patterns[info.id] = PatternEntry{info.id, info.id, true, 0, &info};
    }
    auto defaultModel = loadGltfFile(resolveModelPath(kBuiltinDefault, ""));
    if (!defaultModel) return defaultModel.error();
    st.models[kBuiltinDefault] =
        ModelEntry{kBuiltinDefault, "default", std::make_shared<const Model>(std::move(*defaultModel)), 0, true};
    if (auto bytes = Store::readFile(dermisDataDir() + "/models/default.scene.json"); bytes)
        st.defaultSceneDoc = json::parse(bytes->begin(), bytes->end(), nullptr, false);

    // Stored uploads and scenes.
    for (const Store::Blob& b : st.store->listBlobs("models", svc->warnings_)) {
        if (b.file.size() > 5 && b.file.compare(b.file.size() - 5, 5, ".gltf") == 0) {
            auto model = loadGltfFile(b.file); // a multi-file upload: resources beside it only
            if (!model) {
                svc->warnings_.push_back(b.file + ": " + model.error().message);
                continue;
            }
            st.models[b.id] = ModelEntry{b.id, b.meta.value("name", ""),
                                         std::make_shared<const Model>(std::move(*model)),
                                         b.meta.value("bytes", std::size_t{0}), false};
            continue;
        }
        auto bytes = Store::readFile(b.file);
        if (!bytes) {
            svc->warnings_.push_back(b.file + ": unreadable");
            continue;
        }
        auto parsed = parseGltf(*bytes, "");
        if (parsed) {
            if (auto s = loadGltfResources(*parsed); !s) parsed = s.error();
        }
        if (!parsed) {
            svc->warnings_.push_back(b.file + ": " + parsed.error().message);
            continue;
        }
        st.models[b.id] = ModelEntry{b.id, b.meta.value("name", ""),
                                     std::make_shared<const Model>(std::move(parsed->model)),
                                     bytes->size(), false};
    }
    for (const Store::Blob& b : st.store->listBlobs("patterns", svc->warnings_)) {
        auto bytes = Store::readFile(b.file);
        auto img = bytes ? readHeightImageFromMemory(*bytes) : Result<HeightImage>(bytes.error());
        if (!img) {
            svc->warnings_.push_back(b.file + ": " + img.error().message);
            continue;
        }
        st.images[b.id] = makePatternImage(std::move(*img));
        st.patterns[b.id] = PatternEntry{b.id, b.meta.value("name", ""), false, bytes->size(), nullptr};
    }
    for (const Store::SceneRecord& r : st.store->listScenes(svc->warnings_)) {
        auto prepared = st.prepare(r.doc);
        if (!prepared) {
            svc->warnings_.push_back("scene " + r.id + ": " + prepared.error().message);
            continue;
        }
        st.scenes[r.id] = SceneEntry{prepared->canonical, std::move(prepared->scene), r.revision};
    }

    auto renderer = Renderer::create(backend);
    if (!renderer) return renderer.error();
    st.renderer = std::move(*renderer);
    return svc;
}

Service::~Service() {
    if (state_) closeSubscriptions();
}

json Service::info() const {
    const RendererInfo& r = state_->renderer->info();
    return {{"name", "dermis-server"},
            {"version", "0.1.0"},
            {"api", "/api/v1"},
            {"backend", r.backend},
            {"device", r.device},
            {"gl", {{"vendor", r.vendor}, {"renderer", r.renderer}, {"version", r.version}}},
            {"limits", limits_.toJson()},
            {"render_queue", state_->inFlight.load()}};
}

// --- models -------------------------------------------------------------------------------------

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
            {"has_uvs", e.model->hasUVs()},
            {"bytes", e.bytes}};
}

} // namespace

json Service::listModels() const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    json out = json::array();
    for (const auto& [id, e] : state_->models)
        out.push_back(modelSummary(e));
    return {{"models", out}};
}

Result<json> Service::addModel(const std::vector<std::uint8_t>& glb, const std::string& name) {
    const char* where = "dermis::Service::addModel";
    if (glb.size() > limits_.maxUploadBytes) return bodyTooLarge(limits_, where);
    if (glb.size() < 12 || std::memcmp(glb.data(), "glTF", 4) != 0)
        return makeError(ErrorCode::Unsupported, where, "body",
                         "not a binary glTF (.glb); send a .gltf with its files as multipart/form-data");
    auto parsed = parseGltf(glb, ""); // no base folder: no file of this machine is read
    if (!parsed) return parsed.error();
    if (auto s = loadGltfResources(*parsed); !s) return s.error();
    Model& m = parsed->model;
    if (auto st = checkModel(m, limits_, where); !st) return st.error();
    ModelEntry e;
    e.id = Store::newId("m");
    e.name = sanitizeName(name);
    e.bytes = glb.size();
    e.model = std::make_shared<const Model>(std::move(m));
    std::unique_lock<std::shared_mutex> lock(state_->mutex);
    if (auto s = state_->store->putBlob("models", e.id, "glb", glb,
                                        {{"name", e.name}, {"bytes", e.bytes}, {"created", nowSeconds()}});
        !s)
        return s.error();
    json summary = modelSummary(e);
    state_->models[e.id] = std::move(e);
    return summary;
}

Result<json> Service::addModelFiles(const std::vector<UploadFile>& files, const std::string& gltfName,
                                    const std::string& name) {
    const char* where = "dermis::Service::addModelFiles";
    std::size_t total = 0;
    std::set<std::string> names;
    for (const UploadFile& f : files) {
        total += f.bytes.size();
        if (!Store::isSafeFileName(f.name))
            return makeError(ErrorCode::InvalidArgument, where, "files/" + f.name,
                             "a file name must be plain ([A-Za-z0-9._ -], no folders)");
        if (!names.insert(f.name).second)
            return makeError(ErrorCode::InvalidArgument, where, "files/" + f.name, "given twice");
    }
    if (total > limits_.maxUploadBytes) return bodyTooLarge(limits_, where);
    if (gltfName.empty() || !names.count(gltfName))
        return makeError(ErrorCode::InvalidArgument, where, "gltf",
                         "no .gltf part (name the part \"gltf\" or give it a .gltf file name)");
    // Parse from a private scratch folder: the loader reads external URIs only inside it.
    const fs::path scratch = fs::path(state_->store->dir()) / ("upload.tmp." + Store::newId("u"));
    std::error_code ec;
    fs::create_directories(scratch, ec);
    if (ec) return makeError(ErrorCode::Io, where, "", "cannot create a scratch folder: " + ec.message());
    struct Cleanup {
        fs::path p;
        ~Cleanup() {
            std::error_code e;
            fs::remove_all(p, e);
        }
    } cleanup{scratch};
    for (const UploadFile& f : files)
        if (auto s = Store::writeFileDurably((scratch / f.name).string(), f.bytes); !s) return s.error();
    auto model = loadGltfFile((scratch / gltfName).string());
    if (!model) return model.error();
    if (auto st = checkModel(*model, limits_, where); !st) return st.error();
    ModelEntry e;
    e.id = Store::newId("m");
    e.name = sanitizeName(name.empty() ? gltfName : name);
    e.bytes = total;
    e.model = std::make_shared<const Model>(std::move(*model));
    std::vector<std::pair<std::string, std::vector<std::uint8_t>>> stored;
    for (const UploadFile& f : files)
        stored.emplace_back(f.name, f.bytes);
    std::unique_lock<std::shared_mutex> lock(state_->mutex);
    if (auto s = state_->store->putBlobFolder("models", e.id, stored, gltfName,
                                              {{"name", e.name}, {"bytes", e.bytes}, {"created", nowSeconds()}});
        !s)
        return s.error();
    json summary = modelSummary(e);
    state_->models[e.id] = std::move(e);
    return summary;
}

Result<json> Service::getModel(const std::string& id) const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->models.find(id);
    if (it == state_->models.end()) return notFound("id", "no model \"" + id + "\"");
    const Model& m = *it->second.model;
    json out = modelSummary(it->second);
    json joints = json::array();
    for (int n : m.joints) {
        const Node& node = m.nodes[static_cast<std::size_t>(n)];
        int parent = node.parent;
        while (parent >= 0 && std::find(m.joints.begin(), m.joints.end(), parent) == m.joints.end())
            parent = m.nodes[static_cast<std::size_t>(parent)].parent;
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
    out["joint_count"] = m.joints.size();
    out["clips"] = std::move(clips);
    out["vertices"] = vertices;
    return out;
}

Status Service::deleteModel(const std::string& id) {
    std::unique_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->models.find(id);
    if (it == state_->models.end()) return notFound("id", "no model \"" + id + "\"");
    if (it->second.builtin)
        return makeError(ErrorCode::Conflict, "dermis::Service", "id", "built-in models cannot be deleted");
    for (const auto& [sid, s] : state_->scenes)
        if (s.scene.model == id)
            return makeError(ErrorCode::Conflict, "dermis::Service", "id",
                             "model \"" + id + "\" is used by scene " + sid);
    if (auto s = state_->store->removeBlob("models", id); !s) return s;
    state_->models.erase(it);
    return Ok{};
}

Result<json> Service::uvLayout(const std::string& id) const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->models.find(id);
    if (it == state_->models.end()) return notFound("id", "no model \"" + id + "\"");
    const Model& m = *it->second.model;
    if (!m.hasUVs()) return bad("id", "model \"" + id + "\" has no TEXCOORD_0");
    json edges = json::array();
    std::size_t count = 0;
    for (const MeshPart& p : m.parts) {
        std::set<std::pair<std::uint32_t, std::uint32_t>> seen;
        for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3)
            for (int k = 0; k < 3; ++k) {
                std::uint32_t a = p.indices[t + static_cast<std::size_t>(k)],
                              b = p.indices[t + static_cast<std::size_t>((k + 1) % 3)];
                if (a > b) std::swap(a, b);
                if (b >= p.uvs.size() || !seen.insert({a, b}).second) continue;
                for (std::uint32_t v : {a, b}) {
                    edges.push_back(std::round(p.uvs[v].x * 1e5) / 1e5);
                    edges.push_back(std::round(p.uvs[v].y * 1e5) / 1e5);
                }
                ++count;
            }
    }
    return json{{"id", id}, {"edge_count", count}, {"edges", std::move(edges)},
                {"convention", "u right, v down; each edge is u0, v0, u1, v1"}};
}

Result<EncodedImage> Service::uvLayoutPng(const std::string& id, int size) const {
    if (size < 16 || size > limits_.maxRenderSide)
        return bad("size", "must be in [16, " + std::to_string(limits_.maxRenderSide) + "]");
    auto layout = uvLayout(id);
    if (!layout) return layout.error();
    Image8 img;
    img.width = img.height = size;
    img.rgba.assign(static_cast<std::size_t>(size) * size * 4, 0);
    const json& e = (*layout)["edges"];
    for (std::size_t i = 0; i + 3 < e.size(); i += 4) {
        const double x0 = e[i].get<double>() * size, y0 = e[i + 1].get<double>() * size;
        const double x1 = e[i + 2].get<double>() * size, y1 = e[i + 3].get<double>() * size;
        const int steps = static_cast<int>(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0)))) + 1;
        for (int s = 0; s <= steps; ++s) {
            const double f = static_cast<double>(s) / steps;
            const int x = static_cast<int>(x0 + (x1 - x0) * f), y = static_cast<int>(y0 + (y1 - y0) * f);
            if (x < 0 || y < 0 || x >= size || y >= size) continue;
            std::uint8_t* px = &img.rgba[(static_cast<std::size_t>(y) * size + x) * 4];
            px[0] = px[1] = px[2] = px[3] = 255;
        }
    }
    auto png = encodePng(img, true);
    if (!png) return png.error();
    return EncodedImage{std::move(*png), "image/png", ""};
}

// --- patterns -----------------------------------------------------------------------------------

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

} // namespace

json Service::listPatterns() const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    std::shared_lock<std::shared_mutex> il(state_->imagesMutex);
    json out = json::array();
    for (const auto& [id, e] : state_->patterns) {
        auto img = state_->images.find(id);
        out.push_back(patternSummary(e, img == state_->images.end() ? nullptr : &img->second->pixels));
    }
    return {{"patterns", out}};
}

Result<json> Service::addPattern(const std::vector<std::uint8_t>& bytes, const std::string& name) {
    const char* where = "dermis::Service::addPattern";
    if (bytes.size() > limits_.maxUploadBytes) return bodyTooLarge(limits_, where);
    auto img = readHeightImageFromMemory(bytes);
    if (!img) return img.error();
    if (img->width > limits_.maxImageSide || img->height > limits_.maxImageSide)
        return makeError(ErrorCode::TooLarge, where, "body",
                         "image is " + std::to_string(img->width) + "x" + std::to_string(img->height) +
                             ", the limit is " + std::to_string(limits_.maxImageSide) + " per side");
    PatternEntry e;
    e.id = Store::newId("p");
    e.name = sanitizeName(name);
    e.bytes = bytes.size();
    std::unique_lock<std::shared_mutex> lock(state_->mutex);
    if (auto s = state_->store->putBlob("patterns", e.id, sniffExtension(bytes), bytes,
                                        {{"name", e.name}, {"bytes", e.bytes}, {"created", nowSeconds()}});
        !s)
        return s.error();
    std::unique_lock<std::shared_mutex> il(state_->imagesMutex);
    auto stored = makePatternImage(std::move(*img));
    state_->images[e.id] = stored;
    json summary = patternSummary(e, &stored->pixels);
    state_->patterns[e.id] = std::move(e);
    return summary;
}

Result<EncodedImage> Service::patternImage(const std::string& id, int size) const {
    if (size < 1 || size > 2048) return bad("size", "must be in [1, 2048]");
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    std::shared_lock<std::shared_mutex> il(state_->imagesMutex);
    auto it = state_->images.find(id);
    if (it == state_->images.end() || !state_->patterns.count(id)) return notFound("id", "no pattern \"" + id + "\"");
    const HeightImage& src = it->second->pixels;
    const int w = size, h = std::max(1, static_cast<int>(std::lround(double(size) * src.height / src.width)));
    Image8 img;
    img.width = w;
    img.height = h;
    img.rgba.resize(static_cast<std::size_t>(w) * h * 4);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const float L = sampleBilinear(src, (i + 0.5) / w, (j + 0.5) / h);
            const auto g = static_cast<std::uint8_t>(std::lround(std::clamp((L + 1.0f) * 0.5f, 0.0f, 1.0f) * 255.0f));
            std::uint8_t* px = &img.rgba[(static_cast<std::size_t>(j) * w + i) * 4];
            px[0] = px[1] = px[2] = g;
            px[3] = 255;
        }
    auto png = encodePng(img, false);
    if (!png) return png.error();
    return EncodedImage{std::move(*png), "image/png", ""};
}

Status Service::deletePattern(const std::string& id) {
    std::unique_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->patterns.find(id);
    if (it == state_->patterns.end()) return notFound("id", "no pattern \"" + id + "\"");
    if (it->second.builtin)
        return makeError(ErrorCode::Conflict, "dermis::Service", "id", "built-in patterns cannot be deleted");
    for (const auto& [sid, s] : state_->scenes) {
        bool used = s.scene.heightmapBase && *s.scene.heightmapBase == id;
        for (const auto& [alias, target] : s.scene.patterns)
            used = used || target == id;
        if (used)
            return makeError(ErrorCode::Conflict, "dermis::Service", "id",
                             "pattern \"" + id + "\" is used by scene " + sid);
    }
    if (auto s = state_->store->removeBlob("patterns", id); !s) return s;
    std::unique_lock<std::shared_mutex> il(state_->imagesMutex);
    state_->images.erase(id);
    state_->patterns.erase(it);
    return Ok{};
}

// --- scenes -------------------------------------------------------------------------------------

json Service::listScenes() const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    json out = json::array();
    for (const auto& [id, e] : state_->scenes)
        out.push_back({{"id", id}, {"revision", e.revision}, {"model", e.scene.model},
                       {"placements", e.scene.placements.size()}});
    return {{"scenes", out}};
}

Result<json> Service::createScene(const json& body) {
    if (!body.is_object()) return bad("", "a scene document must be a JSON object");
    json doc = body;
    if (auto dp = doc.find("default_patterns"); dp != doc.end()) {
        if (!dp->is_boolean()) return bad("/default_patterns", "must be true or false");
        const bool wanted = dp->get<bool>();
        doc.erase("default_patterns");
        if (wanted) {
            if (doc.value("model", std::string(kBuiltinDefault)) != kBuiltinDefault)
                return bad("/default_patterns", "the default pattern set exists only for builtin:default");
            if (!state_->defaultSceneDoc.is_object())
                return makeError(ErrorCode::Unavailable, "dermis::Service", "/default_patterns",
                                 "the default pattern set is not installed");
            json base = state_->defaultSceneDoc;
            for (auto it = doc.begin(); it != doc.end(); ++it)
                base[it.key()] = it.value();
            doc = std::move(base);
        }
    }
    std::unique_lock<std::shared_mutex> lock(state_->mutex);
    return state_->commit(Store::newId("s"), doc, "created", true);
}

Result<json> Service::getScene(const std::string& id) const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->scenes.find(id);
    if (it == state_->scenes.end()) return notFound("id", "no scene \"" + id + "\"");
    return json{{"id", id}, {"revision", it->second.revision}, {"scene", it->second.doc}};
}

Result<json> Service::replaceScene(const std::string& id, const json& doc) {
    return state_->edit(id, "replaced", [&](json& d) -> Status {
        d = doc;
        return Ok{};
    });
}

Status Service::deleteScene(const std::string& id) {
    std::unique_lock<std::shared_mutex> lock(state_->mutex);
    if (!state_->scenes.count(id)) return notFound("id", "no scene \"" + id + "\"");
    if (auto s = state_->store->removeScene(id); !s) return s;
    state_->scenes.erase(id);
    state_->publish(id, {{"type", "deleted"}, {"scene", id}});
    std::lock_guard<std::mutex> sl(state_->subsMutex);
    auto [a, b] = state_->subs.equal_range(id);
    for (auto it = a; it != b; ++it)
        it->second->close();
    state_->subs.erase(id);
    return Ok{};
}

namespace {

/// Index of placement `pid` in doc["placements"], or −1.
int placementIndex(const json& doc, const std::string& pid) {
    const json& pl = doc["placements"];
    for (std::size_t i = 0; i < pl.size(); ++i)
        if (pl[i].value("id", "") == pid) return static_cast<int>(i);
    return -1;
}

} // namespace

Result<json> Service::addPlacement(const std::string& id, const json& placement) {
    if (!placement.is_object()) return bad("", "a placement must be a JSON object");
    return state_->edit(id, "placement_added", [&](json& doc) -> Status {
        json p = placement;
        if (!p.contains("id")) { // a fresh id that no other placement has
            std::string pid;
            for (int k = static_cast<int>(doc["placements"].size());; ++k) {
                pid = "p" + std::to_string(k);
                if (placementIndex(doc, pid) < 0) break;
            }
            p["id"] = pid;
        }
        doc["placements"].push_back(p);
        return Ok{};
    });
}

Result<json> Service::patchPlacement(const std::string& id, const std::string& pid, const json& patch) {
    if (!patch.is_object()) return bad("", "a placement patch must be a JSON object");
    if (auto i = patch.find("id"); i != patch.end() && (!i->is_string() || i->get<std::string>() != pid))
        return bad("/id", "a placement's id cannot be changed");
    return state_->edit(id, "placement_updated", [&](json& doc) -> Status {
        const int k = placementIndex(doc, pid);
        if (k < 0) return notFound("pid", "no placement \"" + pid + "\" in scene " + id);
        doc["placements"][static_cast<std::size_t>(k)].merge_patch(patch);
        return Ok{};
    });
}

Result<json> Service::deletePlacement(const std::string& id, const std::string& pid) {
    return state_->edit(id, "placement_deleted", [&](json& doc) -> Status {
        const int k = placementIndex(doc, pid);
        if (k < 0) return notFound("pid", "no placement \"" + pid + "\" in scene " + id);
        doc["placements"].erase(static_cast<std::size_t>(k));
        return Ok{};
    });
}

Result<json> Service::reorderPlacements(const std::string& id, const json& order) {
    if (!order.is_array()) return bad("", "the order must be an array of placement ids");
    return state_->edit(id, "placements_reordered", [&](json& doc) -> Status {
        const json& old = doc["placements"];
        if (order.size() != old.size())
            return bad("", "the order must list each of the " + std::to_string(old.size()) + " placements once");
        json reordered = json::array();
        std::set<std::string> seen;
        for (std::size_t i = 0; i < order.size(); ++i) {
            const std::string f = "/" + std::to_string(i);
            if (!order[i].is_string()) return bad(f, "must be a placement id");
            const std::string pid = order[i].get<std::string>();
            const int k = placementIndex(doc, pid);
            if (k < 0) return notFound(f, "no placement \"" + pid + "\"");
            if (!seen.insert(pid).second) return bad(f, "placement \"" + pid + "\" listed twice");
            reordered.push_back(old[static_cast<std::size_t>(k)]);
        }
        doc["placements"] = std::move(reordered);
        return Ok{};
    });
}

Result<json> Service::putPose(const std::string& id, const json& pose) {
    if (!pose.is_object()) return bad("/pose", "a pose must be a JSON object");
    return state_->edit(id, "pose", [&](json& doc) -> Status {
        doc["pose"] = pose;
        return Ok{};
    });
}

Result<json> Service::patchPose(const std::string& id, const json& patch) {
    if (!patch.is_object()) return bad("/pose", "a pose patch must be a JSON object");
    return state_->edit(id, "pose", [&](json& doc) -> Status {
        json& pose = doc["pose"];
        if (!pose.is_object()) pose = json::object();
        for (auto e = patch.begin(); e != patch.end(); ++e) {
            if (e.key() == "joints" && e->is_object()) {
                if (!pose["joints"].is_object()) pose["joints"] = json::object();
                for (auto j = e->begin(); j != e->end(); ++j) {
                    if (j->is_null()) pose["joints"].erase(j.key());
                    else pose["joints"][j.key()] = *j;
                }
            } else if (e->is_null()) {
                pose.erase(e.key());
            } else {
                pose[e.key()] = *e;
            }
        }
        return Ok{};
    });
}

// --- renders ------------------------------------------------------------------------------------

namespace {

/// Counts renders waiting for or using the GL thread; refuses beyond the queue length.
class QueueSlot {
public:
    QueueSlot(std::atomic<int>& n, int limit) : n_(n) { ok_ = n_.fetch_add(1) < limit; }
    ~QueueSlot() { n_.fetch_sub(1); }
    bool ok() const { return ok_; }

private:
    std::atomic<int>& n_;
    bool ok_ = false;
};

Error queueFull() {
    return makeError(ErrorCode::Unavailable, "dermis::Service", "",
                     "the render queue is full; retry shortly");
}

} // namespace

namespace {

/// A frame's query parameters name the render settings they override: an error in an overridden
/// setting names the parameter ("width"), not the document field ("/render/size/0").
Error asParamError(Error e, const FrameParams& p) {
    const struct {
        const char* field;
        const char* param;
        bool given;
    } map[] = {{"/render/size/0", "width", p.width.has_value()},
               {"/render/size/1", "height", p.height.has_value()},
               {"/render/msaa", "msaa", p.msaa.has_value()},
               {"/render/camera/yaw", "yaw", p.yaw.has_value()},
               {"/render/camera/pitch", "pitch", p.pitch.has_value()},
               {"/render/camera/distance", "distance", p.distance.has_value()},
               {"/pose/time", "time", p.time.has_value()}};
    for (const auto& m : map)
        if (m.given && e.field == m.field) {
            const std::string what = e.message.substr(e.message.rfind(": ") + 2);
            return makeError(e.code, "dermis::Service::frame", m.param, what);
        }
    return e;
}

} // namespace

Result<EncodedImage> Service::frame(const std::string& id, const FrameParams& p) {
    if (p.format != "png" && p.format != "jpeg") return bad("format", "must be png or jpeg");
    QueueSlot slot(state_->inFlight, limits_.queueLength);
    if (!slot.ok()) return queueFull();
    auto snap = state_->snapshot(id);
    if (!snap) return snap.error();
    auto img = state_->render(snap->scene, snap->model, p);
    if (!img) return asParamError(img.error(), p);
    return img;
}

Result<EncodedImage> Service::heightmap(const std::string& id, const std::string& which,
                                        const std::string& format) {
    if (which != "bump" && which != "displacement" && which != "normal")
        return notFound("map", "no height map \"" + which + "\" (bump, displacement or normal)");
    const bool normal = which == "normal";
    if (normal ? (format != "png" && format != "exr") : (format != "png16" && format != "exr" && format != "f32"))
        return bad("format", normal ? "must be png or exr" : "must be png16, exr or f32");
    QueueSlot slot(state_->inFlight, limits_.queueLength);
    if (!slot.ok()) return queueFull();
    auto snap = state_->snapshot(id);
    if (!snap) return snap.error();
    const Scene scene = state_->resolved(snap->scene);
    const std::shared_ptr<const Model>& model = snap->model;
    Result<HeightMaps> maps = makeError(ErrorCode::Internal, "dermis::Service", "", "not baked");
    {
        std::shared_lock<std::shared_mutex> il(state_->imagesMutex);
        auto plan = planFrame(scene, *model, state_->images, state_->baseOf(scene));
        if (!plan) return plan.error();
        maps = state_->renderer->bakeHeightMaps(plan->heights);
    }
    if (!maps) return maps.error();
    const HeightImage& map = which == "displacement" ? maps->displacement : maps->bump;
    EncodedImage out;
    out.backend = state_->renderer->info().backend;
    if (normal) {
        auto n = normalMapFromBump(map, 0.01 * scene.render.bumpStrength * map.width);
        if (!n) return n.error();
        const Image8 img = encodeNormalMap8(*n);
        auto bytes = encodeFrame(img, format == "png" ? FrameFormat::Png : FrameFormat::Exr);
        if (!bytes) return bytes.error();
        out.bytes = std::move(*bytes);
        out.contentType = format == "png" ? "image/png" : "image/x-exr";
        return out;
    }
    if (format == "f32") {
        out.bytes.resize(map.data.size() * sizeof(float));
        std::memcpy(out.bytes.data(), map.data.data(), out.bytes.size());
        out.contentType = "application/octet-stream";
        return out;
    }
    // png16 / exr through the image library, via a private temp file.
    const std::string tmp = (fs::path(state_->store->dir()) /
                             (Store::newId("tmp") + (format == "exr" ? ".exr" : ".png"))).string();
    Status s = format == "exr" ? writeFloatImage(tmp, map) : writeHeight16Png(tmp, map);
    if (!s) return s.error();
    auto bytes = Store::readFile(tmp);
    std::error_code ec;
    fs::remove(tmp, ec);
    if (!bytes) return bytes.error();
    out.bytes = std::move(*bytes);
    out.contentType = format == "exr" ? "image/x-exr" : "image/png";
    return out;
}

Result<Service::BatchJob> Service::batch(const json& body) {
    if (!body.is_object()) return bad("", "the batch must be a JSON object");
    auto sceneIt = body.find("scene");
    if (sceneIt == body.end()) return bad("/scene", "missing scene document");
    auto framesIt = body.find("frames");
    if (framesIt == body.end() || !framesIt->is_array() || framesIt->empty())
        return bad("/frames", "must be a non-empty array of {time} or {pose}");
    if (framesIt->size() > limits_.maxBatchFrames)
        return makeError(ErrorCode::TooLarge, "dermis::Service", "/frames",
                         "more than " + std::to_string(limits_.maxBatchFrames) + " frames");
    FrameParams params;
    if (auto f = body.find("format"); f != body.end()) {
        if (!f->is_string() || (*f != "png" && *f != "jpeg")) return bad("/format", "must be png or jpeg");
        params.format = f->get<std::string>();
    }
    struct Item {
        Scene scene;
        std::optional<double> time;
    };
    auto items = std::make_shared<std::vector<Item>>();
    std::shared_ptr<const Model> model;
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto base = state_->prepare(*sceneIt);
        if (!base) {
            Error e = base.error();
            e.field = "/scene" + e.field;
            e.message = "dermis::Service::batch: " + e.field + ": " + e.message;
            return e;
        }
        model = base->model;
        for (std::size_t k = 0; k < framesIt->size(); ++k) {
            const json& fr = (*framesIt)[k];
            const std::string f = "/frames/" + std::to_string(k);
            if (!fr.is_object()) return bad(f, "must be an object with time or pose");
            std::optional<double> time;
            if (auto t = fr.find("time"); t != fr.end()) {
                if (!t->is_number() || !std::isfinite(t->get<double>()) || t->get<double>() < 0.0)
                    return bad(f + "/time", "must be a number >= 0");
                time = t->get<double>();
            }
            auto p = fr.find("pose");
            if (p == fr.end()) {
                if (!time) return bad(f, "needs time or pose");
                items->push_back({base->scene, time});
                continue;
            }
            json doc = *sceneIt;
            doc["pose"] = *p;
            auto prepared = state_->prepare(doc);
            if (!prepared) {
                Error e = prepared.error();
                e.field = (e.field.rfind("/pose", 0) == 0 ? f : "/scene") + e.field;
                e.message = "dermis::Service::batch: " + e.field + ": " + e.message;
                return e;
            }
            items->push_back({std::move(prepared->scene), time});
        }
    }
    BatchJob job;
    job.frames = items->size();
    job.render = [this, items, model, params](std::size_t k) -> Result<EncodedImage> {
        QueueSlot slot(state_->inFlight, limits_.queueLength + 1);
        if (!slot.ok()) return queueFull();
        FrameParams p = params;
        p.time = (*items)[k].time;
        return state_->render((*items)[k].scene, model, p);
    };
    return job;
}

// --- events -------------------------------------------------------------------------------------

Result<std::shared_ptr<Subscription>> Service::subscribe(const std::string& id) {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->scenes.find(id);
    if (it == state_->scenes.end()) return notFound("id", "no scene \"" + id + "\"");
    auto sub = std::make_shared<Subscription>();
    sub->push("event: hello\ndata: " +
              json{{"type", "hello"}, {"scene", id}, {"revision", it->second.revision}}.dump() + "\n\n");
    std::lock_guard<std::mutex> sl(state_->subsMutex);
    state_->subs.emplace(id, sub);
    return sub;
}

void Service::unsubscribe(const std::string& id, const std::shared_ptr<Subscription>& s) {
    std::lock_guard<std::mutex> sl(state_->subsMutex);
    auto [a, b] = state_->subs.equal_range(id);
    for (auto it = a; it != b; ++it)
        if (it->second == s) {
            state_->subs.erase(it);
            break;
        }
}

void Service::closeSubscriptions() {
    std::lock_guard<std::mutex> sl(state_->subsMutex);
    for (auto& [id, s] : state_->subs)
        s->close();
    state_->subs.clear();
}

} // namespace dermis
