#include "gl/scene_frame.hpp"

#include <chrono>

namespace dermis {

Result<SceneFrame> makeSceneFrame(const Scene& scene, std::shared_ptr<const Model> model,
                                  const PatternImages& images, const HeightImage* base,
                                  const SceneFrameOptions& options) {
    if (!model)
        return makeError(ErrorCode::InvalidArgument, "dermis::makeSceneFrame", "/model", "no model");
    auto pose = evaluatePose(*model, scene.pose, options.time);
    if (!pose) return pose.error();
    SceneFrame out;
    FrameRequest& req = out.request;
    req.world = worldMatrices(*model, *pose);
    req.render = scene.render;
    req.readHeightMaps = options.readHeightMaps;
    req.profile = options.profile;
    HeightPassInput in;
    if (!scene.placements.empty()) {
        auto placements = resolvePlacements(scene, *model, *pose, images);
        if (!placements) return placements.error();
        in.placements = std::move(*placements);
    }
    in.images = &images;
    in.base = base;
    in.width = scene.heightmapSize[0];
    in.height = scene.heightmapSize[1];
    if (options.cpuHeightMaps) {
        const auto t0 = std::chrono::steady_clock::now();
        BakeSettings bs;
        bs.width = in.width;
        bs.height = in.height;
        bs.base = base;
        out.cpuMaps = std::make_unique<HeightMaps>();
        if (auto s = bakeHeightMapsInto(in.placements, bs, *out.cpuMaps); !s) return s.error();
        out.cpuBakeMs = std::chrono::duration<double, std::milli>(
                            std::chrono::steady_clock::now() - t0).count();
        req.cpuMaps = out.cpuMaps.get();
    } else {
        req.heights = std::move(in);
    }
    req.model = std::move(model);
    return out;
}

} // namespace dermis
