// Renders: frames of stored scenes, their height maps, and stateless batches. Each takes a
// snapshot under the shared lock and plans and renders without any lock held.
#include "service/service_state.hpp"

#include "core/normalmap.hpp"
#include "io/frame_io.hpp"
#include "io/image_io.hpp"

#include <cmath>

namespace dermis {

using namespace detail;

Result<FramePlan> Service::State::plan(const Snapshot& snap, const FrameParams& p) const {
    FrameOverrides o;
    o.width = p.width;
    o.height = p.height;
    o.msaa = p.msaa;
    o.yaw = p.yaw;
    o.pitch = p.pitch;
    o.distance = p.distance;
    o.time = p.time;
    RenderLimits rl;
    rl.maxSide = limits.maxRenderSide;
    auto planned = planFrame(snap.scene, *snap.model, snap.images, snap.base, o, rl);
    if (!planned) return detail::asParamError(planned.error(), p);
    return planned;
}

Result<EncodedImage> Service::State::render(const Snapshot& snap, const FrameParams& p) {
    auto plan = this->plan(snap, p);
    if (!plan) return plan.error();
    auto result = renderer->renderFrame(frameRequest(*plan, snap.model));
    if (!result) return result.error();
    EncodedImage out;
    out.backend = renderer->info().backend;
    auto bytes = p.format == "jpeg" ? encodeJpeg(result->image, 90) : encodePng(result->image, false);
    if (!bytes) return bytes.error();
    out.bytes = std::move(*bytes);
    out.contentType = p.format == "jpeg" ? "image/jpeg" : "image/png";
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

} // namespace detail

Result<EncodedImage> Service::frame(const std::string& id, const FrameParams& p) {
    if (p.format != "png" && p.format != "jpeg") return bad("format", "must be png or jpeg");
    QueueSlot slot(state_->inFlight, limits_.queueLength);
    if (!slot.ok()) return queueFull();
    auto snap = state_->snapshot(id);
    if (!snap) return snap.error();
    auto img = state_->render(*snap, p);
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
    auto plan = planFrame(snap->scene, *snap->model, snap->images, snap->base);
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
        State::Snapshot snap;
        std::optional<double> time;
    };
    auto items = std::make_shared<std::vector<Item>>();
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto base = state_->prepare(*sceneIt);
        if (!base) {
            Error e = base.error();
            e.field = "/scene" + e.field;
            e.message = "dermis::Service::batch: " + e.field + ": " + e.message;
            return e;
        }
        const State::Snapshot baseSnap = state_->snapshotOf(base->scene, base->model);
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
            auto prepared = state_->prepare(doc);
            if (!prepared) {
                Error e = prepared.error();
                e.field = (e.field.rfind("/pose", 0) == 0 ? f : "/scene") + e.field;
                e.message = "dermis::Service::batch: " + e.field + ": " + e.message;
                return e;
            }
            items->push_back({state_->snapshotOf(prepared->scene, prepared->model), time});
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
