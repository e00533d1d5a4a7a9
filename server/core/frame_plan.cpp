#include "frame_plan.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

Result<FramePlan> planFrame(const Scene& scene, const Model& model, const PatternImages& images,
                            std::shared_ptr<const PatternImage> base, const FrameOverrides& o,
                            const RenderLimits& limits) {
    const char* where = "dermis::planFrame";
    FramePlan plan;
    RenderSettings& r = plan.render;
    r = scene.render;
    if (o.width) r.size[0] = *o.width;
    if (o.height) r.size[1] = *o.height;
    if (o.msaa) {
        r.msaa = *o.msaa;
        r.aa = AntiAliasing::Msaa;
    }
    if (o.aa) r.aa = *o.aa;
    if (o.shading) r.shading = *o.shading;
    if (o.exposure) r.exposure = *o.exposure;
    if (o.toneMapping) r.toneMapping = *o.toneMapping;
    if (o.yaw) r.camera.yaw = *o.yaw;
    if (o.pitch) r.camera.pitch = *o.pitch;
    if (o.distance) r.camera.distance = *o.distance;
    if (o.target) r.camera.target = *o.target;
    if (auto s = validateRenderSettings(r, limits, where); !s) return s.error();
    if (o.time && !(std::isfinite(*o.time) && *o.time >= 0.0))
        return makeError(ErrorCode::InvalidArgument, where, "/pose/time", "must be a finite number >= 0");

    auto pose = evaluatePose(model, scene.pose, o.time);
    if (!pose) return pose.error();
    plan.world = worldMatrices(model, *pose);
    plan.view = o.view;
    if (!scene.placements.empty()) {
        auto placements = resolvePlacements(scene, model, *pose, images, o.layout.get());
        if (!placements) return placements.error();
        plan.heights.placements = std::move(*placements);
        for (const Placement& p : scene.placements)
            if (auto it = images.find(p.pattern); it != images.end()) plan.images.push_back(it->second);
    }
    plan.pose = std::move(*pose);
    plan.heights.width = scene.heightmapSize[0];
    plan.heights.height = scene.heightmapSize[1];
    plan.heights.layout = o.layout;
    const bool surface = std::any_of(plan.heights.placements.begin(), plan.heights.placements.end(),
                                     [](const BakePlacement& b) { return b.surface; });
    if (surface) {
        const int W = plan.heights.width, H = plan.heights.height;
        if (o.rest && o.rest->width == W && o.rest->height == H) {
            plan.heights.rest = o.rest;
        } else if (o.layout) {
            plan.heights.rest = std::make_shared<const RestSurfaceMap>(bakeRestSurface(model, *o.layout, W, H));
        } else {
            plan.heights.rest = std::make_shared<const RestSurfaceMap>(
                bakeRestSurface(model, modelTextureLayout(model), W, H));
        }
    }
    if (base) {
        plan.heights.base = &base->pixels;
        plan.heights.baseId = base->contentId;
        plan.images.push_back(std::move(base));
    }
    return plan;
}

namespace {

BakeSettings settingsOf(const HeightMapInput& in, int threads) {
    BakeSettings s;
    s.width = in.width;
    s.height = in.height;
    s.base = in.base;
    s.rest = in.rest.get();
    s.threads = threads;
    return s;
}

} // namespace

Result<HeightMaps> bakeHeightMaps(const HeightMapInput& in, int threads) {
    return bakeHeightMaps(in.placements, settingsOf(in, threads));
}

Status bakeHeightMapsInto(const HeightMapInput& in, HeightMaps& maps, int threads) {
    return bakeHeightMapsInto(in.placements, settingsOf(in, threads), maps);
}

} // namespace dermis
