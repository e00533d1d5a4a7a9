// Test helper: a scene → a renderer request in one call (planFrame + frameRequest, and the CPU maps
// of the paper's "CPU" configuration), holding everything the request points to.
#pragma once

#include "core/frame_plan.hpp"
#include "gl/renderer.hpp"

#include <memory>
#include <optional>

namespace dermis::test {

struct SceneFrameOptions {
    std::optional<double> time;  ///< overrides pose.time
    bool cpuHeightMaps = false;  ///< bake the maps on the CPU and upload them
    bool readHeightMaps = false;
    bool profile = false;
};

struct SceneFrame {
    std::unique_ptr<FramePlan> plan; ///< what `request` points into
    FrameRequest request;
    std::unique_ptr<HeightMaps> cpuMaps;
};

inline Result<SceneFrame> makeSceneFrame(const Scene& scene, std::shared_ptr<const Model> model,
                                         const PatternImages& images,
                                         std::shared_ptr<const PatternImage> base,
                                         const SceneFrameOptions& options = {}) {
    if (!model) return makeError(ErrorCode::InvalidArgument, "makeSceneFrame", "/model", "no model");
    FrameOverrides o;
    o.time = options.time;
    auto plan = planFrame(scene, *model, images, std::move(base), o);
    if (!plan) return plan.error();
    SceneFrame out;
    out.plan = std::make_unique<FramePlan>(std::move(*plan));
    out.request = frameRequest(*out.plan, std::move(model));
    out.request.readHeightMaps = options.readHeightMaps;
    out.request.profile = options.profile;
    if (options.cpuHeightMaps) {
        auto maps = bakeHeightMaps(out.plan->heights);
        if (!maps) return maps.error();
        out.cpuMaps = std::make_unique<HeightMaps>(std::move(*maps));
        out.request.heights.reset();
        out.request.cpuMaps = out.cpuMaps.get();
    }
    return out;
}

} // namespace dermis::test
