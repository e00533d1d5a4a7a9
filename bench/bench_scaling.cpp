// dermis-bench part 4: how the frame time grows with the work (issue #13 "Scaling").
//
// One series per variable, the others at the default (15 placements, 1024² maps, the default
// character ≈ 4.3k triangles and its joints, 1024² frame, MSAA off), each with GPU height maps
// (the renderer's height pass: the GL pass, or on a software rasterizer the CPU bake when the
// footprints cover more than two map areas, see RendererOptions) and CPU height maps
// (bakeHeightMapsInto on all hardware threads, then uploaded):
//   placements 15, 100, 1000 — synthetic placements built from the scene's 15 (same patterns and
//     footprint sizes, centres and rotations spread over the UV square, every one active, its t
//     moving every frame), given to the renderer directly: more than a scene document allows
//     (kMaxPlacements); the coverage of the map grows with the count (Σ footprint areas ≈ 0.07 map
//     areas at 15, ≈ 4.8 at 1000);
//   map size 512², 1024², 2048², 4096²;
//   triangles: the character midpoint-subdivided 0–3 times (≈ 4.3k, 17k, 69k, 276k);
//   joints: the character's, 200 (withSyntheticJoints).
// Frame time = pose + plan + height maps + skin pass + readback (no encode: see "encoders"), the
// pose moving along the squat clip so the height pass never hits its cache. Median of 7
// repetitions after a warm-up (3 for the big cases), so the run stays within a few minutes on two
// cores with llvmpipe.
#include "bench_parts.hpp"

#include "core/subdivide.hpp"

#include <cmath>
#include <iostream>
#include <map>
#include <random>
#include <string>

namespace dermis::bench {

namespace {

struct Case {
    std::string series;
    int placements = 15, mapSize = 1024, subdivisions = 0, joints = 0; ///< joints 0 = the model's
};

/// `n` placements made from the plan's (patterns, footprint sizes, model, target), spread over
/// the UV square, all active with t moving with `frame`.
std::vector<BakePlacement> synthesize(const std::vector<BakePlacement>& from, int n, int frame) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.05, 0.95), rot(-180, 180);
    std::vector<BakePlacement> out;
    out.reserve(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) {
        BakePlacement p = from[static_cast<std::size_t>(k) % from.size()];
        p.footprint.center = {u(rng), u(rng)};
        p.footprint.rotationDeg = rot(rng);
        const double phase = std::fmod(k * 0.618 + frame * 0.1, 1.0);
        p.t = 0.2 + 0.6 * phase;
        out.push_back(p);
    }
    return out;
}

} // namespace

int benchScaling(Renderer& renderer, const DefaultScene& ds, nlohmann::json& out) {
    std::vector<Case> cases;
    for (int n : {15, 100, 1000}) cases.push_back({"placements", n, 1024, 0, 0});
    for (int m : {512, 1024, 2048, 4096}) cases.push_back({"map_size", 15, m, 0, 0});
    for (int s : {0, 1, 2, 3}) cases.push_back({"triangles", 15, 1024, s, 0});
    for (int j : {0, 200}) cases.push_back({"joints", 15, 1024, 0, j});

    std::map<std::pair<int, int>, std::shared_ptr<const Model>> models; // (subdivisions, joints)
    HeightMaps cpuHeights;
    for (const Case& c : cases) {
        auto& model = models[{c.subdivisions, c.joints}];
        if (!model) {
            auto sub = subdivideModel(*ds.model, c.subdivisions);
            if (!sub) {
                std::cerr << sub.error().message << "\n";
                return 1;
            }
            if (c.joints > 0) {
                auto more = withSyntheticJoints(*sub, c.joints);
                if (!more) {
                    std::cerr << more.error().message << "\n";
                    return 1;
                }
                sub = std::move(*more);
            }
            model = std::make_shared<const Model>(std::move(*sub));
        }
        Scene scene = ds.scene;
        scene.render.size = {1024, 1024};
        scene.render.msaa = 1;
        scene.heightmapSize = {c.mapSize, c.mapSize};
        const bool big = c.placements >= 1000 || c.mapSize >= 4096 || c.subdivisions >= 3;
        const int repeat = big ? 3 : 7;
        for (bool cpuMaps : {false, true}) {
            std::vector<double> total, heights;
            const std::size_t onCpuBefore = renderer.stats().heightPassesOnCpu;
            for (int r = 0; r <= repeat; ++r) {
                const auto t0 = std::chrono::steady_clock::now();
                FrameOverrides overrides;
                overrides.time = ds.clipDuration * (r % 8) / 8.0;
                auto plan = planFrame(scene, *model, ds.images, nullptr, overrides);
                if (!plan) {
                    std::cerr << plan.error().message << "\n";
                    return 1;
                }
                plan->heights.placements = synthesize(plan->heights.placements, c.placements, r);
                FrameRequest request = frameRequest(*plan, model);
                double heightMs = 0.0;
                if (cpuMaps) { // the paper's "CPU" configuration: bake, then upload
                    auto ms = useCpuMaps(request, plan->heights, cpuHeights);
                    if (!ms) {
                        std::cerr << ms.error().message << "\n";
                        return 1;
                    }
                    heightMs = *ms;
                }
                auto result = renderer.renderFrame(request);
                if (!result) {
                    std::cerr << result.error().message << "\n";
                    return 1;
                }
                if (r == 0) continue; // warm-up: uploads, allocation
                total.push_back(msSince(t0));
                if (cpuMaps) heights.push_back(heightMs);
            }
            nlohmann::json row = {{"series", c.series},
                                  {"heightmaps", cpuMaps ? "cpu" : "gpu"},
                                  {"placements", c.placements},
                                  {"map_size", c.mapSize},
                                  {"triangles", model->triangleCount()},
                                  {"joints", model->joints.size()},
                                  {"frame_size", 1024},
                                  {"frame_ms", round2(medianMs(total))},
                                  {"repetitions", total.size()}};
            if (cpuMaps) row["cpu_bake_ms"] = round2(medianMs(heights));
            // GPU rows on a software rasterizer: whether the renderer baked the big passes on the
            // CPU (RendererOptions::softwareCpuBakeCoverage).
            else row["gl_pass_baked_on_cpu"] = renderer.stats().heightPassesOnCpu > onCpuBefore;
            out.push_back(row);
            std::cerr << "scaling: " << row.dump() << "\n";
        }
    }
    return 0;
}

} // namespace dermis::bench
