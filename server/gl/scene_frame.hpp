// Dermis GL shell — from a scene document to a renderer request: evaluates the pose at a time,
// measures every placement's joint angle and fills a FrameRequest (GPU height pass) or, for the
// paper's "CPU" configuration, bakes the maps on the CPU first.
//
// Pure apart from the types of renderer.hpp (no GL calls). The returned request points into
// `images`, `base` and the returned holder: keep them alive while it is used.
#pragma once

#include "gl/renderer.hpp"

#include <memory>
#include <optional>

namespace dermis {

struct SceneFrameOptions {
    std::optional<double> time;   ///< overrides pose.time
    bool cpuHeightMaps = false;   ///< bake the maps on the CPU (threads: all cores) and upload them
    bool readHeightMaps = false;
    bool profile = false;
};

/// A request and the CPU maps it may point to.
struct SceneFrame {
    FrameRequest request;
    std::unique_ptr<HeightMaps> cpuMaps; ///< set when options.cpuHeightMaps
    double cpuBakeMs = 0.0;              ///< time of the CPU bake, when it ran
};

/// Fails like evaluatePose/resolvePlacements (unknown clip, joint or pattern; no UVs) with the
/// scene field named. A model without UVs but with placements fails at "/placements/0".
Result<SceneFrame> makeSceneFrame(const Scene& scene, std::shared_ptr<const Model> model,
                                  const PatternImages& images, const HeightImage* base,
                                  const SceneFrameOptions& options = {});

} // namespace dermis
