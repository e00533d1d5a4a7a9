// Helpers shared by dermis-bench's parts (bench_main.cpp, bench_scaling.cpp,
// bench_encoders.cpp): timing, rounding, and the default scene loaded once.
#pragma once

#include "core/bake.hpp"
#include "core/frame_plan.hpp"
#include "core/model.hpp"
#include "core/scene.hpp"
#include "gl/renderer.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

namespace dermis::bench {

/// Median of `v` (upper median for even sizes). Precondition: not empty.
inline double medianMs(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

inline double round2(double v) { return std::round(v * 100) / 100; }

inline double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// The paper's "CPU" configuration for one frame: bakes `heights` into `maps` (storage reused)
/// and makes `request` upload them instead of running the GPU height pass. The bake's time in ms,
/// or its error.
inline Result<double> useCpuMaps(FrameRequest& request, const HeightMapInput& heights, HeightMaps& maps) {
    const auto t0 = std::chrono::steady_clock::now();
    if (auto s = bakeHeightMapsInto(heights, maps); !s) return s.error();
    request.heights.reset();
    request.cpuMaps = &maps;
    return msSince(t0);
}

/// models/default.scene.json with its first 15 placements, 1024² maps, the squat clip.
struct DefaultScene {
    Scene scene;
    std::shared_ptr<const Model> model;
    PatternImages images;
    double clipDuration = 1.0; ///< of "squat"
};

} // namespace dermis::bench
