// Renders: frames of stored scenes, their height maps, and stateless batches. Each takes a
// snapshot under the shared lock and plans and renders without any lock held.
#include "service_state.hpp"

#include "core/bake.hpp"
#include "core/normalmap.hpp"
#include "io/frame_io.hpp"
#include "io/image_io.hpp"
#include "io/webp_encode.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

using namespace detail;

Result<FramePlan> Service::State::plan(const Snapshot& snap, const FrameParams& p) const {
    FrameOverrides o;
    o.width = p.width;
    o.height = p.height;
    o.msaa = p.msaa;
    o.aa = p.aa;
    o.shading = p.shading;
    o.exposure = p.exposure;
    o.toneMapping = p.toneMapping;
    o.yaw = p.yaw;
    o.pitch = p.pitch;
    o.distance = p.distance;
    o.target = p.target;
    o.time = p.time;
    o.view = p.view;
    RenderLimits rl;
    rl.maxSide = limits.maxRenderSide;
    if (auto s = withLayout(snap.scene, *derivedOf(snap), o); !s) return s.error();
    auto planned = planFrame(snap.scene, *snap.model, snap.images, snap.base, o, rl);
    if (!planned) return detail::asParamError(planned.error(), p);
    // key_light: on keeps the scene's light or adds the default one; off takes it away.
    if (p.keyLight) {
        if (!*p.keyLight) planned->render.keyLight.reset();
        else if (!planned->render.keyLight) planned->render.keyLight = KeyLight{};
    }
    return planned;
}

namespace {

/// The outlines `p` asks for, from the snapshot's placements (previews applied): the highlighted
/// ones as selected, the hovered one, the brushes. A surface placement is outlined as its decal on
/// the rest surface (core surfaceFrameOf: the frame the bake uses). Unknown ids fail (field
/// highlight / hover).
Result<std::vector<FrameOutline>> outlinesOf(const Scene& scene, const FrameParams& p) {
    std::vector<FrameOutline> out;
    auto add = [&](const std::string& pid, FrameOutline::Kind kind, const char* field) -> Status {
        for (const Placement& pl : scene.placements)
            if (pl.id == pid) {
                if (pl.projection == Projection::Surface) {
                    BakePlacement b;
                    if (!surfaceFrameOf(pl, b)) return Ok{}; // a degenerate anchor: nothing to draw
                    FrameOutline o;
                    o.kind = kind;
                    o.shape = FrameOutline::SurfaceRect;
                    o.anchor = glm::vec3(b.anchorPosition);
                    o.normal = glm::vec3(b.anchorNormal);
                    o.tangent = glm::vec3(b.anchorTangent);
                    o.size = glm::vec2(b.size);
                    o.depth = static_cast<float>(b.depth);
                    out.push_back(o);
                    return Ok{};
                }
                out.push_back({glm::vec2(static_cast<float>(pl.center[0]), static_cast<float>(pl.center[1])),
                               glm::vec2(static_cast<float>(pl.scale[0]), static_cast<float>(pl.scale[1])),
                               static_cast<float>(pl.rotation), kind});
                return Ok{};
            }
        return bad(field, "no placement \"" + pid + "\" in the scene");
    };
    for (const std::string& pid : p.highlight)
        if (auto s = add(pid, FrameOutline::Selected, "highlight"); !s) return s.error();
    if (!p.hover.empty())
        if (auto s = add(p.hover, FrameOutline::Hovered, "hover"); !s) return s.error();
    if (p.brush) {
        const auto& b = *p.brush;
        out.push_back({glm::vec2(static_cast<float>(b[0]), static_cast<float>(b[1])),
                       glm::vec2(static_cast<float>(b[2]), static_cast<float>(b[3])),
                       static_cast<float>(b[4]), FrameOutline::Brush});
    }
    if (p.surfaceBrush) {
        const auto& b = *p.surfaceBrush;
        const glm::dvec3 n = glm::normalize(glm::dvec3(b[3], b[4], b[5]));
        // Any tangent: a circle has no orientation (the dashes start somewhere).
        const glm::dvec3 t = glm::normalize(std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1, 0, 0))
                                                               : glm::cross(n, glm::dvec3(0, 1, 0)));
        FrameOutline o;
        o.kind = FrameOutline::Brush;
        o.shape = FrameOutline::SurfaceCircle;
        o.anchor = glm::vec3(static_cast<float>(b[0]), static_cast<float>(b[1]), static_cast<float>(b[2]));
        o.normal = glm::vec3(n);
        o.tangent = glm::vec3(t);
        o.size = glm::vec2(static_cast<float>(b[6]));
        o.depth = static_cast<float>(b[6] * 0.5);
        out.push_back(o);
    }
    return out;
}

} // namespace

Result<Image8> Service::State::renderImage(const Snapshot& snap, const FrameParams& p,
                                           std::optional<std::array<double, 4>>* camera,
                                           std::string* antiAliasing) {
    auto plan = this->plan(snap, p);
    if (!plan) return plan.error();
    auto outlines = outlinesOf(snap.scene, p);
    if (!outlines) return outlines.error();
    FrameRequest request = frameRequest(*plan, snap.model);
    request.outlines = std::move(*outlines);
    // The scene's environment, where the frame's light is image-based (legacy frames never
    // decode it): a batch's by content address, else the one its id names.
    const bool imageBased = request.render.shading != Shading::Legacy || request.view == FrameView::Lighting ||
                            request.view == FrameView::BaseColor;
    if (imageBased && snap.environment) {
        request.environment = snap.environment;
    } else if (imageBased) {
        auto env = environmentImage(request.render.environment);
        if (!env) return env.error();
        request.environment = std::move(*env);
    }
    auto result = renderer->renderFrame(request);
    if (!result) return result.error();
    if (camera)
        *camera = std::array<double, 4>{result->cameraDistance, result->cameraTarget.x,
                                        result->cameraTarget.y, result->cameraTarget.z};
    if (antiAliasing) *antiAliasing = result->antiAliasing;
    return std::move(result->image);
}

Result<Service::State::Snapshot> Service::State::frameSnapshot(const std::string& id,
                                                              const FrameParams& p) const {
    Result<Snapshot> snap = makeError(ErrorCode::Internal, "", "", "");
    const bool preview = p.preview.is_object() && !p.preview.empty();
    if (p.revision || preview) {
        std::uint64_t current = 0;
        json doc;
        {
            std::shared_lock<std::shared_mutex> lock(mutex);
            auto it = scenes.find(id);
            if (it == scenes.end()) return notFound("id", "no scene \"" + id + "\"");
            const SceneEntry& e = it->second;
            current = e.revision;
            if (p.revision && (*p.revision == 0 || *p.revision > current))
                return notFound("revision",
                                "scene " + id + " has no revision " + std::to_string(*p.revision));
            if (p.revision)
                if (auto s = keptRevision(id, e, *p.revision, limits.historyKeep.flag()); !s) return s.error();
            const SceneVersion* v = e.recentVersion(p.revision ? *p.revision : current);
            // The current revision, or a recent one whose model and patterns are all still here,
            // renders from the scene validated at its commit: nothing to parse or check again.
            if (v && !preview && cachedRenders(*v->scene)) {
                snap = snapshotOf(*v->scene, models.at(v->scene->model).model);
            } else if (v) {
                doc = *v->doc;
            }
        }
        if (snap) return withCompare(std::move(*snap), id, p);
        if (doc.is_null()) {
            auto old = store->readRevision(id, *p.revision);
            if (!old) return old.error();
            doc = std::move(*old);
        }
        if (preview) {
            // The rules of a placement edit (mergePlacementPatch), every refusal on "preview".
            for (auto it = p.preview.begin(); it != p.preview.end(); ++it)
                if (auto s = mergePlacementPatch(doc, id, it.key(), it.value()); !s)
                    return bad("preview", "\"" + it.key() + "\": " + s.error().message);
        }
        std::shared_lock<std::shared_mutex> lock(mutex);
        framesPrepared.fetch_add(1, std::memory_order_relaxed);
        auto prepared = prepare(doc, false);
        if (!prepared) {
            if (preview)
                return bad("preview", "the previewed document is not valid: " + prepared.error().message);
            return makeError(ErrorCode::Conflict, "dermis::Service", "revision",
                             "revision " + std::to_string(*p.revision) +
                                 " no longer renders: " + prepared.error().message);
        }
        snap = snapshotOf(prepared->scene, prepared->model);
    } else {
        snap = snapshot(id);
    }
    if (!snap) return snap;
    return withCompare(std::move(*snap), id, p);
}

bool Service::State::cachedRenders(const Scene& scene) const {
    if (!models.count(scene.model)) return false;
    const auto present = [&](const std::string& pattern) {
        auto alias = scene.patterns.find(pattern);
        return images.count(alias == scene.patterns.end() ? pattern : alias->second) > 0;
    };
    for (const Placement& pl : scene.placements)
        if (!present(pl.pattern)) return false;
    return !scene.heightmapBase || present(*scene.heightmapBase);
}

Result<Service::State::Snapshot> Service::State::withCompare(Snapshot snap, const std::string& id,
                                                             const FrameParams& p) const {
    for (const std::string& pid : p.only) {
        bool known = false;
        for (const Placement& pl : snap.scene.placements) known = known || pl.id == pid;
        if (!known) return bad("only", "no placement \"" + pid + "\" in scene " + id);
    }
    for (Placement& pl : snap.scene.placements) {
        if (p.patternsOff) pl.enabled = false;
        if (!p.only.empty() && std::find(p.only.begin(), p.only.end(), pl.id) == p.only.end())
            pl.enabled = false;
    }
    return snap;
}

Result<EncodedImage> Service::State::render(const Snapshot& snap, const FrameParams& p) {
    EncodedImage out;
    auto image = renderImage(snap, p, &out.camera, &out.antiAliasing);
    if (!image) return image.error();
    out.backend = renderer->info().backend;
    auto bytes = p.format == "jpeg"   ? encodeJpeg(*image, 90)
                 : p.format == "webp" ? encodeWebpLossless(*image, false)
                                      : encodePng(*image, false);
    if (!bytes) return bytes.error();
    out.bytes = std::move(*bytes);
    out.contentType = p.format == "jpeg"   ? "image/jpeg"
                      : p.format == "webp" ? "image/webp"
                                           : "image/png";
    return out;
}

namespace detail {

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
               {"/render/exposure", "exposure", p.exposure.has_value()},
               {"/render/camera/yaw", "yaw", p.yaw.has_value()},
               {"/render/camera/pitch", "pitch", p.pitch.has_value()},
               {"/render/camera/distance", "distance", p.distance.has_value()},
               {"/render/camera/target", "target", p.target.has_value()},
               {"/pose/time", "time", p.time.has_value()}};
    for (const auto& m : map)
        if (m.given && e.field == m.field) {
            const std::string what = e.message.substr(e.message.rfind(": ") + 2);
            return makeError(e.code, "dermis::Service::frame", m.param, what);
        }
    return e;
}

} // namespace detail

std::uint64_t Service::framesPrepared() const {
    return state_->framesPrepared.load(std::memory_order_relaxed);
}

std::optional<std::uint64_t> parseRevisionNumber(const std::string& text) {
    if (text.empty() || text.size() > 18) return std::nullopt;
    std::uint64_t n = 0;
    for (char c : text) {
        if (c < '0' || c > '9') return std::nullopt;
        n = n * 10 + static_cast<std::uint64_t>(c - '0');
    }
    if (n == 0) return std::nullopt;
    return n;
}

Result<EncodedImage> Service::frame(const std::string& id, const FrameParams& p) {
    if (!isFrameFormat(p.format)) return bad("format", "must be png, jpeg or webp");
    QueueSlot slot(state_->inFlight, limits_.queueLength);
    if (!slot.ok()) return queueFull();
    auto snap = state_->frameSnapshot(id, p);
    if (!snap) return snap.error();
    auto img = state_->render(*snap, p);
    if (!img) return asParamError(img.error(), p);
    return img;
}

Result<EncodedImage> Service::frameDiff(const std::string& id, const FrameParams& given,
                                        const std::string& against) {
    FrameParams p = given; // a heat map of the patterns: outlines would only add noise
    p.highlight.clear();
    p.hover.clear();
    p.brush.reset();
    p.surfaceBrush.reset();
    FrameParams other = p;
    if (against == "off") {
        other.patternsOff = true;
    } else {
        const auto n = parseRevisionNumber(against);
        if (!n) return bad("against", "must be off or a revision number");
        other.revision = *n;
        other.patternsOff = false;
        other.only.clear();
    }
    QueueSlot slot(state_->inFlight, limits_.queueLength);
    if (!slot.ok()) return queueFull();
    auto a = state_->frameSnapshot(id, p);
    if (!a) return a.error();
    auto b = state_->frameSnapshot(id, other);
    if (!b) { // the revision compared against is `against` (this request has no `revision` of its own there)
        Error e = b.error();
        if (e.field == "revision" && against != "off") e.field = "against";
        return e;
    }
    std::optional<std::array<double, 4>> camera;
    auto ia = state_->renderImage(*a, p, &camera);
    if (!ia) return asParamError(ia.error(), p);
    auto ib = state_->renderImage(*b, other);
    if (!ib) return asParamError(ib.error(), other);
    Image8 heat;
    heat.width = ia->width;
    heat.height = ia->height;
    heat.rgba.assign(ia->rgba.size(), 0);
    std::int64_t changed = 0;
    for (std::size_t k = 0; k + 3 < ia->rgba.size() && k + 3 < ib->rgba.size(); k += 4) {
        int d = 0;
        for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(ia->rgba[k + c]) - int(ib->rgba[k + c])));
        if (d > 0) ++changed;
        const double t = d / 255.0; // black → red → yellow → white
        heat.rgba[k + 0] = static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(3.0 * t, 0.0, 1.0)));
        heat.rgba[k + 1] = static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(3.0 * t - 1.0, 0.0, 1.0)));
        heat.rgba[k + 2] = static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(3.0 * t - 2.0, 0.0, 1.0)));
        heat.rgba[k + 3] = 255;
    }
    auto bytes = encodePng(heat, false);
    if (!bytes) return bytes.error();
    EncodedImage out;
    out.bytes = std::move(*bytes);
    out.contentType = "image/png";
    out.backend = state_->renderer->info().backend;
    out.changedPixels = changed;
    out.camera = camera;
    return out;
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
    FrameOverrides o;
    if (auto s = state_->withLayout(snap->scene, *state_->derivedOf(*snap), o); !s) return s.error();
    auto plan = planFrame(snap->scene, *snap->model, snap->images, snap->base, o);
    if (!plan) return plan.error();
    auto maps = state_->renderer->bakeHeightMaps(plan->heights);
    if (!maps) return maps.error();
    const HeightImage& map = which == "displacement" ? maps->displacement : maps->bump;
    EncodedImage out;
    out.backend = state_->renderer->info().backend;
    if (normal) {
        auto n = normalMapFromBump(map, normalMapStrength(snap->scene.render.bumpStrength, map.width));
        if (!n) return n.error();
        const Image8 img = encodeNormalMap8(*n);
        auto bytes = encodeFrame(img, format == "png" ? FrameFormat::Png : FrameFormat::Exr);
        if (!bytes) return bytes.error();
        out.bytes = std::move(*bytes);
        out.contentType = format == "png" ? "image/png" : "image/x-exr";
        return out;
    }
    auto bytes = format == "f32" ? encodeF32(map) : format == "exr" ? encodeFloatExr(map) : encodeHeight16Png(map);
    if (!bytes) return bytes.error();
    out.bytes = std::move(*bytes);
    out.contentType = format == "f32" ? "application/octet-stream" : format == "exr" ? "image/x-exr" : "image/png";
    return out;
}

Result<Service::BatchJob> Service::batch(const json& body,
                                         const std::map<std::string, std::vector<std::uint8_t>>& content) {
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
        if (!f->is_string() || !isFrameFormat(f->get<std::string>()))
            return bad("/format", "must be png, jpeg or webp");
        params.format = f->get<std::string>();
    }
    if (auto v = body.find("view"); v != body.end()) {
        auto view = v->is_string() ? frameViewFromString(v->get<std::string>()) : std::nullopt;
        if (!view) return bad("/view", "must be shaded, bump, displacement, normal, basecolor or lighting");
        params.view = *view;
    }
    struct Item {
        State::Snapshot snap;
        std::optional<double> time;
    };
    auto overlay = state_->resolveContent(*sceneIt, content);
    if (!overlay) return overlay.error();
    auto items = std::make_shared<std::vector<Item>>();
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto base = state_->prepare(*sceneIt, true, &*overlay);
        if (!base) {
            Error e = base.error();
            e.field = "/scene" + e.field;
            e.message = "dermis::Service::batch: " + e.field + ": " + e.message;
            return e;
        }
        const State::Snapshot baseSnap = state_->snapshotOf(base->scene, base->model, &*overlay);
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
                items->push_back({baseSnap, time});
                continue;
            }
            json doc = *sceneIt;
            doc["pose"] = *p;
            auto prepared = state_->prepare(doc, true, &*overlay);
            if (!prepared) {
                Error e = prepared.error();
                e.field = (e.field.rfind("/pose", 0) == 0 ? f : "/scene") + e.field;
                e.message = "dermis::Service::batch: " + e.field + ": " + e.message;
                return e;
            }
            items->push_back({state_->snapshotOf(prepared->scene, prepared->model, &*overlay), time});
        }
    }
    BatchJob job;
    job.frames = items->size();
    job.render = [this, items, params](std::size_t k) -> Result<EncodedImage> {
        QueueSlot slot(state_->inFlight, limits_.queueLength + 1);
        if (!slot.ok()) return queueFull();
        FrameParams p = params;
        p.time = (*items)[k].time;
        return state_->render((*items)[k].snap, p);
    };
    return job;
}

} // namespace dermis
