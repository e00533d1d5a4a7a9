// The service's life: opening (built-in content, stored uploads and scenes), info, and the
// document checks every scene change goes through.
#include "service_state.hpp"

#include "io/atomic_file.hpp"
#include "io/gltf_loader.hpp"
#include "io/image_io.hpp"
#include "common/sha256.hpp"
#include "io/scene_files.hpp"

#include <chrono>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <filesystem>
#include <iterator>
#include <set>

namespace dermis {

json ServerLimits::toJson() const {
    return {{"max_upload_bytes", maxUploadBytes}, {"max_image_side", maxImageSide},
            {"max_map_side", maxMapSide},         {"max_render_side", maxRenderSide},
            {"max_triangles", maxTriangles},      {"max_joints", maxJoints},
            {"max_placements", maxPlacements},    {"queue_length", queueLength},
            {"request_timeout_seconds", requestTimeoutSeconds},
            {"max_batch_frames", maxBatchFrames},
            {"content_cache_bytes", contentCacheBytes},
            {"presence_seconds", presenceSeconds},
            {"history_keep", historyKeep.text()}};
}

namespace detail {

Error bad(const std::string& field, const std::string& what) {
    return makeError(ErrorCode::InvalidArgument, "dermis::Service", field, what);
}

Error notFound(const std::string& field, const std::string& what) {
    return makeError(ErrorCode::NotFound, "dermis::Service", field, what);
}

Error queueFull() {
    return makeError(ErrorCode::Unavailable, "dermis::Service", "", "the render queue is full; retry shortly");
}

void returnFreedMemory() {
#ifdef __GLIBC__
    malloc_trim(0);
#endif
}

void keepLargeBuffersMapped() {
#ifdef __GLIBC__
    // A fixed threshold: glibc's default one rises to 32 MB after the first large free, and from
    // then on the decode buffers of large uploads are carved from the HTTP threads' arenas, where
    // they stay resident after they are freed (issue #12: RSS over upload/delete cycles).
    mallopt(M_MMAP_THRESHOLD, 4 << 20);
#endif
}

double nowSeconds() {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

Error withoutDataPath(Error e, const std::string& dataDir) {
    if (dataDir.empty()) return e;
    for (std::string* text : {&e.message, &e.field})
        for (std::size_t at = text->find(dataDir); at != std::string::npos;
             at = text->find(dataDir, at + 6))
            text->replace(at, dataDir.size(), "<data>");
    return e;
}

std::string sanitizeName(const std::string& name) {
    std::string out;
    for (char c : name)
        if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == ' ')
            out += c;
    if (out.size() > 64) out.resize(64);
    return out;
}

} // namespace detail

using namespace detail;

// --- document checks ------------------------------------------------------------------------

Result<Service::State::Prepared> Service::State::prepare(const json& docIn, bool withLimits,
                                                        const ContentOverlay* overlay) const {
    if (!docIn.is_object()) return bad("", "a scene document must be a JSON object");
    json doc = docIn;
    const auto overlayImage = [&](const std::string& v) {
        return overlay && overlay->images.count(v) ? overlay->images.at(v) : nullptr;
    };
    // Uploaded pattern ids (and, in a batch, content addresses) may be used directly as placement
    // patterns: alias them to themselves (an address to "sha256_<hex>", a valid pattern id).
    if (auto pl = doc.find("placements"); pl != doc.end() && pl->is_array()) {
        for (json& p : *pl) {
            if (!p.is_object()) continue;
            auto pat = p.find("pattern");
            if (pat == p.end() || !pat->is_string()) continue;
            std::string id = pat->get<std::string>();
            auto it = patterns.find(id);
            if ((it == patterns.end() || it->second.builtin) && !overlayImage(id)) continue;
            if (!doc.contains("patterns")) doc["patterns"] = json::object();
            if (isContentAddress(id)) { // "sha256:…" is no pattern id: alias "sha256_…" to it
                std::string alias = "sha256_" + id.substr(7);
                *pat = alias;
                if (doc["patterns"].is_object() && !doc["patterns"].contains(alias)) doc["patterns"][alias] = id;
                continue;
            }
            if (doc["patterns"].is_object() && !doc["patterns"].contains(id)) doc["patterns"][id] = id;
        }
    }
    // Only ids: never a path of this machine.
    if (auto pm = doc.find("patterns"); pm != doc.end() && pm->is_object())
        for (auto it = pm->begin(); it != pm->end(); ++it) {
            const std::string field = "/patterns/" + jsonPointerEscape(it.key());
            if (!it->is_string()) continue; // parseScene reports the type
            const std::string v = it->get<std::string>();
            if (overlayImage(v)) continue;
            auto found = patterns.find(v);
            if (found == patterns.end() || found->second.builtin)
                return notFound(field, "must name an uploaded pattern id (p_…), got \"" + v + "\"" +
                                           (isContentAddress(v) ? " (content addresses are for POST /render)" : ""));
        }
    if (auto hm = doc.find("heightmap"); hm != doc.end() && hm->is_object())
        if (auto base = hm->find("base"); base != hm->end() && base->is_string()) {
            const std::string v = base->get<std::string>();
            auto found = patterns.find(v);
            if ((found == patterns.end() || found->second.builtin) && !overlayImage(v))
                return notFound("/heightmap/base", "must name an uploaded pattern id (p_…), got \"" + v + "\"");
        }
    auto scene = parseScene(doc, manifest);
    if (!scene) return scene.error();
    if (const std::string& env = scene->render.environment;
        !env.empty() && env != kBuiltinStudioEnvironment && !environments.count(env) &&
        !(overlay && overlay->environments.count(env)))
        return notFound("/render/environment", "no environment \"" + env +
                                                   "\" (use builtin:studio or an id from POST /environments)");
    // A (valid) alias no placement names is dropped (issue #12.5): it would otherwise keep its
    // pattern "in use" after the last placement using it went, and DELETE /patterns/{id} answer 409.
    std::set<std::string> named;
    for (const Placement& p : scene->placements) named.insert(p.pattern);
    for (auto it = scene->patterns.begin(); it != scene->patterns.end();)
        it = named.count(it->first) ? std::next(it) : scene->patterns.erase(it);
    std::shared_ptr<const Model> modelPtr;
    if (overlay)
        if (auto it = overlay->models.find(scene->model); it != overlay->models.end()) modelPtr = it->second;
    if (!modelPtr) {
        auto model = models.find(scene->model);
        if (model == models.end())
            return notFound("/model", "no model \"" + scene->model + "\" (use builtin:default or an uploaded id)");
        modelPtr = model->second.model;
    }
    if (withLimits && scene->placements.size() > limits.maxPlacements)
        return makeError(ErrorCode::TooLarge, "dermis::Service", "/placements",
                         "more than " + std::to_string(limits.maxPlacements) + " placements");
    for (std::size_t k = 0; k < 2; ++k)
        if (withLimits && scene->heightmapSize[k] > limits.maxMapSide)
            return makeError(ErrorCode::TooLarge, "dermis::Service", "/heightmap/size/" + std::to_string(k),
                             "exceeds the server's limit " + std::to_string(limits.maxMapSide));
    // The document must work on its model: render settings within this server's limits, clip and
    // joints exist, patterns resolve, UVs present — the same plan a frame makes.
    const Model& m = *modelPtr;
    RenderLimits rl;
    if (withLimits) rl.maxSide = limits.maxRenderSide;
    PatternImages merged;
    if (overlay && !overlay->images.empty()) {
        merged = images;
        for (const auto& [address, img] : overlay->images) merged[address] = img;
    }
    // The height-map layout and rest map the frames will use (SPEC §8), from the model entry's
    // derived data (a listed model) so that its caches serve the frames after this check.
    std::shared_ptr<const ModelDerived> derived;
    if (auto entry = models.find(scene->model);
        entry != models.end() && entry->second.model == modelPtr && entry->second.derived)
        derived = entry->second.derived->get(modelPtr);
    else
        derived = std::make_shared<const ModelDerived>(modelPtr);
    FrameOverrides o;
    const Scene resolvedScene = resolved(*scene);
    if (auto s = withLayout(resolvedScene, *derived, o); !s) return s.error();
    auto plan = planFrame(resolvedScene, m, merged.empty() ? images : merged, nullptr, o, rl);
    if (!plan) return plan.error();
    Prepared out;
    out.canonical = toJson(*scene);
    out.scene = std::move(*scene);
    out.model = std::move(modelPtr);
    return out;
}

Scene Service::State::resolved(const Scene& scene) const {
    Scene s = scene;
    for (Placement& p : s.placements)
        if (auto it = scene.patterns.find(p.pattern); it != scene.patterns.end()) p.pattern = it->second;
    return s;
}

Service::State::Snapshot Service::State::snapshotOf(const Scene& scene, std::shared_ptr<const Model> model,
                                                    const ContentOverlay* overlay) const {
    Snapshot snap;
    snap.scene = resolved(scene);
    snap.model = std::move(model);
    const auto find = [&](const std::string& id) -> std::shared_ptr<const PatternImage> {
        if (overlay)
            if (auto it = overlay->images.find(id); it != overlay->images.end()) return it->second;
        auto it = images.find(id);
        return it == images.end() ? nullptr : it->second;
    };
    for (const Placement& p : snap.scene.placements)
        if (auto img = find(p.pattern)) snap.images.emplace(p.pattern, std::move(img));
    if (snap.scene.heightmapBase) snap.base = find(*snap.scene.heightmapBase);
    if (overlay)
        if (auto it = overlay->environments.find(scene.render.environment); it != overlay->environments.end())
            snap.environment = it->second;
    // The model's derived data (layout, rest maps, UV index…): its entry's, built once per model;
    // for a batch's content-addressed model the one the content cache keeps with it.
    if (auto entry = models.find(scene.model);
        entry != models.end() && entry->second.model == snap.model && entry->second.derived)
        snap.derived = entry->second.derived->get(snap.model);
    if (!snap.derived && overlay)
        for (const auto& [address, m] : overlay->models)
            if (m == snap.model)
                if (auto d = overlay->derived.find(address); d != overlay->derived.end() && d->second) snap.derived = d->second;
    if (!snap.derived) snap.derived = std::make_shared<const ModelDerived>(snap.model);
    return snap;
}

Result<Service::State::Snapshot> Service::State::snapshot(const std::string& id) const {
    std::shared_lock<std::shared_mutex> lock(mutex);
    auto it = scenes.find(id);
    if (it == scenes.end()) return notFound("id", "no scene \"" + id + "\"");
    return snapshotOf(*it->second.scene, models.at(it->second.scene->model).model);
}

// --- open -----------------------------------------------------------------------------------

Status Service::State::loadContent() {
    auto m = loadBuiltinManifest(contentDir);
    if (!m) return m.error();
    manifest = std::move(*m);
    for (const PatternInfo& info : manifest.patterns) {
        auto img = readHeightImage(contentDir + "/patterns/" + info.file);
        if (!img) return img.error();
        images[info.id] = makePatternImage(std::move(*img));
        patterns[info.id] = PatternEntry{info.id, info.id, true, 0, &info, ""};
    }
    auto defaultModel = loadGltfFile(resolveModelPath(kBuiltinDefault, "", contentDir));
    if (!defaultModel) return defaultModel.error();
    models[kBuiltinDefault] = ModelEntry{kBuiltinDefault, "default",
                                         std::make_shared<const Model>(std::move(*defaultModel)), 0, true, ""};
    // The default pattern set is optional content; present but unusable is an error, not a silence.
    const std::string setPath = contentDir + "/models/default.scene.json";
    std::error_code ec;
    if (!std::filesystem::exists(setPath, ec)) return Ok{};
    const char* where = "dermis::Service::open";
    auto bytes = readWholeFile(setPath);
    if (!bytes)
        return makeError(ErrorCode::Io, where, setPath, "cannot read the default pattern set: " + bytes.error().message);
    json doc = json::parse(bytes->begin(), bytes->end(), nullptr, false);
    if (doc.is_discarded() || !doc.is_object())
        return makeError(ErrorCode::Parse, where, setPath, "the default pattern set is not a JSON object");
    if (auto ok = prepare(doc, false); !ok)
        return makeError(ok.error().code, where, setPath,
                         "the default pattern set does not validate: " + ok.error().message);
    defaultSceneDoc = std::move(doc);
    return Ok{};
}

void Service::State::loadStored(std::vector<std::string>& warnings) {
    // Stored models are loaded under the same limits as uploads, checked before allocating: a
    // file past them (stored by an older server or configured limits since lowered) is skipped
    // with a warning, quickly.
    const GltfLimits gl = detail::gltfLimitsOf(limits);
    for (const Store::Blob& b : store->listBlobs("models", warnings)) {
        Result<Model> model = makeError(ErrorCode::Internal, "", "", "");
        std::size_t bytesLen = b.meta.value("bytes", std::size_t{0});
        std::string digest; // a .glb's content address (a multi-file upload has none)
        if (b.file.size() > 5 && b.file.compare(b.file.size() - 5, 5, ".gltf") == 0) {
            model = loadGltfFile(b.file, gl); // a multi-file upload: resources beside it only
        } else {
            auto bytes = readWholeFile(b.file);
            if (!bytes) {
                warnings.push_back(b.file + ": unreadable");
                continue;
            }
            bytesLen = bytes->size();
            digest = toHex(sha256(*bytes));
            auto parsed = parseGltf(*bytes, "", gl);
            if (parsed)
                if (auto s = loadGltfResources(*parsed, gl); !s) parsed = s.error();
            if (parsed) model = std::move(parsed->model);
            else model = parsed.error();
        }
        if (!model) {
            warnings.push_back(b.file + ": " + model.error().message);
            continue;
        }
        models[b.id] = ModelEntry{b.id, b.meta.value("name", ""),
                                  std::make_shared<const Model>(std::move(*model)), bytesLen, false, digest};
    }
    for (const Store::Blob& b : store->listBlobs("patterns", warnings)) {
        auto bytes = readWholeFile(b.file);
        auto img = bytes ? readHeightImageFromMemory(*bytes) : Result<HeightImage>(bytes.error());
        if (!img) {
            warnings.push_back(b.file + ": " + img.error().message);
            continue;
        }
        images[b.id] = makePatternImage(std::move(*img));
        patterns[b.id] = PatternEntry{b.id, b.meta.value("name", ""), false, bytes->size(), nullptr,
                                      toHex(sha256(*bytes))};
    }
    // Environments before scenes (a scene may name one). Decoded when a frame needs one.
    for (const Store::Blob& b : store->listBlobs("environments", warnings)) {
        EnvironmentEntry e;
        e.id = b.id;
        e.name = b.meta.value("name", "");
        e.file = b.file;
        e.bytes = b.meta.value("bytes", std::size_t(0));
        e.width = b.meta.value("width", 0);
        e.height = b.meta.value("height", 0);
        environments[b.id] = std::move(e);
    }
    for (const Store::SceneRecord& r : store->listScenes(warnings)) {
        auto prepared = prepare(r.doc);
        if (!prepared) {
            warnings.push_back("scene " + r.id + ": " + prepared.error().message);
            continue;
        }
        auto history = store->loadHistory(r.id, r.revision, r.doc);
        if (!history) {
            warnings.push_back("scene " + r.id + ": " + history.error().message);
            continue;
        }
        SceneEntry& e = scenes[r.id];
        e.history = std::move(history->revisions);
        e.droppedBefore = history->droppedBefore;
        e.setCurrent({r.revision, std::make_shared<const json>(std::move(prepared->canonical)),
                      std::make_shared<const Scene>(std::move(prepared->scene))});
        applyRetention(r.id); // the window moved while the server was down (--history-keep 30d)
    }
}

Result<std::unique_ptr<Service>> Service::open(const ServiceConfig& config,
                                               std::unique_ptr<FrameRenderer> renderer) {
    if (!renderer)
        return makeError(ErrorCode::InvalidArgument, "dermis::Service::open", "renderer", "no renderer");
    std::unique_ptr<Service> svc(new Service());
    svc->limits_ = config.limits;
    svc->state_ = std::make_unique<State>();
    State& st = *svc->state_;
    st.limits = config.limits;
    st.contentDir = config.contentDir.empty() ? dermisContentDir() : config.contentDir;
    st.renderer = std::move(renderer);
    st.content = std::make_unique<ContentCache>(config.limits.contentCacheBytes);
    st.decodeBudget = std::make_unique<DecodeBudget>(config.limits.decodeBudgetBytes);
    keepLargeBuffersMapped();
    auto store = Store::open(config.dataDir);
    if (!store) return store.error();
    st.store = std::move(*store);
    st.layouts = makeLayoutCache(st.store->dir() + "/cache/layouts");
    // Single-threaded until returned: no locks needed.
    if (auto s = st.loadContent(); !s) return s.error();
    st.loadStored(svc->warnings_);
    return svc;
}

Result<std::unique_ptr<Service>> Service::open(const std::string& dataDir, GlBackend backend,
                                               const ServerLimits& limits) {
    auto renderer = Renderer::create(backend);
    if (!renderer) return renderer.error();
    ServiceConfig config;
    config.dataDir = dataDir;
    config.contentDir = dermisContentDir();
    config.limits = limits;
    return open(config, std::move(*renderer));
}

Service::~Service() {
    if (state_) closeSubscriptions();
}

json Service::info() const {
    const RendererInfo& r = state_->renderer->info();
    json out = {{"name", "dermis-server"},
                {"version", "0.1.0"},
                {"api", "/api/v1"},
                {"backend", r.backend},
                {"device", r.device},
                {"gl", {{"vendor", r.vendor}, {"renderer", r.renderer}, {"version", r.version}}},
                // What the default render settings' aa ("auto") resolves to on this renderer.
                {"aa_auto", resolveAntiAliasing(RenderSettings{}, r.software, r.maxSamples).label()},
                {"limits", limits_.toJson()},
                {"render_queue", state_->inFlight.load()}};
    if (auto c = state_->renderer->cacheStats())
        out["gpu_cache"] = {{"textures", c->textures},         {"texture_bytes", c->textureBytes},
                            {"models", c->models},             {"model_bytes", c->modelBytes},
                            {"budget_bytes", c->budgetBytes},  {"evictions", c->evictions},
                            {"forgotten", c->forgotten}};
    const ContentCache::Stats c = state_->content->stats();
    out["content_cache"] = {{"entries", c.entries},       {"bytes", c.bytes},       {"budget_bytes", c.budget},
                            {"hits", c.hits},             {"misses", c.misses},     {"insertions", c.insertions},
                            {"evictions", c.evictions}, {"rest_surface_builds", c.restSurfaceBuilds}};
    return out;
}

} // namespace dermis
