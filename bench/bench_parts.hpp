// The parts of dermis-bench after the CPU height maps: each appends JSON objects to `out` and
// returns 0, or prints the error to stderr and returns 1.
#pragma once

#include "bench_common.hpp"
#include "core/result.hpp"
#include "gl/renderer.hpp"

#include <nlohmann/json.hpp>

namespace dermis::bench {

/// The default scene (bench_main.cpp).
Result<DefaultScene> loadDefaultScene();

/// Encode time (median of `repeat`) and size of one frame per format and frame size
/// (bench_encoders.cpp).
int benchEncoders(Renderer& renderer, const DefaultScene& ds, int repeat, nlohmann::json& out);

/// The height-map route's work (GET /scenes/{id}/heightmaps/{map}, 1024² maps): a bake whose pose
/// changed (height pass and read-back), a bake of the same inputs (read-back only), and the f32 and
/// 16-bit PNG encodes; medians of `repeat` (bench_encoders.cpp).
int benchHeightmapFetch(Renderer& renderer, const DefaultScene& ds, int repeat, nlohmann::json& out);

/// Frame time against placements, map size, triangles and joints (bench_scaling.cpp).
int benchScaling(Renderer& renderer, const DefaultScene& ds, nlohmann::json& out);

} // namespace dermis::bench
