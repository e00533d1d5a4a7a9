// dermis-bench — prints JSON figures (median milliseconds) for the paper's headline scenario.
// Usage: dermis-bench [--repeat N] [--gl auto|egl-device|egl-surfaceless|osmesa] [--no-gpu]
//                     [--no-cpu] [--scaling | --only-scaling] [--frame SHADING/SIZE/AA]
//   (--no-gpu: only the CPU cases; --no-cpu: only the frames; default 15 repetitions after one
//   warm-up run; --scaling adds part 4, --only-scaling runs only part 4; --frame runs only that
//   case of part 2 with GPU maps and no key light, e.g. pbr/1024/post, and nothing else)
//
// 1. cpu_heightmaps: 15 placements in texture space, CPU height maps at 1024² and 2048², one
//    thread and all threads. Patterns are synthetic 512² smooth height fields (the built-in
//    library's size); footprints cover 0.08–0.3 of the UV square each, rotated.
// 2. frame: the paper's per-frame loop on the default character (~4.3k triangles, ~50 joints)
//    with the first 15 placements of models/default.scene.json and 1024² maps, the pose moving
//    along the squat clip: height pass, skin pass, post-process AA, readback, PNG encode and
//    total, at 512² and 1024², anti-aliasing off, post (render.aa "post") and MSAA 4x, legacy and
//    pbr and skin shading (render.shading; GPU maps only; at 1024² without AA also with the
//    key light, render.key_light, unshadowed and shadowed, and both with the pose still and the
//    camera turning, "…_orbit", whose shadow map is reused: "key_light"), with GPU
//    height maps and with CPU height maps (the paper's "CPU" configuration). Stages are
//    separated by glFinish. "aa_quality": SSIM of one 1024² frame per mode against MSAA 4x and
//    against a supersampled frame (2048² MSAA 4x, 2×2 blocks averaged).
// 3. encoders (JSON "encoders"): PNG, JPEG, lossless WebP and EXR encode time and size of a
//    512² and a 1024² frame of that scene (bench_encoders.cpp). "heightmap_fetch": the height-map
//    route's work at 1024² (bake after a pose change, bake of the same inputs = read-back only,
//    f32 and 16-bit PNG encodes; bench_encoders.cpp).
// 4. scaling (JSON "scaling"): frame time against placements, map size, triangles and joints,
//    GPU and CPU height maps (bench_scaling.cpp; bench/plot_scaling.py draws docs/scaling.png).
#include "core/heightmap.hpp"
#include "gl/renderer.hpp"
#include "core/frame_plan.hpp"
#include "core/image_similarity.hpp"
#include "io/frame_io.hpp"
#include "io/scene_files.hpp"
#include "bench_common.hpp"
#include "bench_parts.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <random>
#include <string_view>
#include <thread>

#include <sys/resource.h>

using namespace dermis;
using namespace dermis::bench;

namespace {

HeightImage makePattern(int n, unsigned seed) {
    HeightImage img(n, n);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> f(2, 9), ph(0, 6.28);
    const double fx = f(rng), fy = f(rng), p = ph(rng);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x = (i + 0.5) / n, y = (j + 0.5) / n;
            const double window = std::sin(M_PI * x) * std::sin(M_PI * y);
            img.at(i, j) = static_cast<float>(window * std::sin(fx * x * 6.28 + p) *
                                              std::cos(fy * y * 3.14));
        }
    return img;
}


} // namespace

Result<DefaultScene> dermis::bench::loadDefaultScene() {
    auto loaded = loadSceneFile(dermisContentDir() + "/models/default.scene.json");
    if (!loaded) return loaded.error();
    DefaultScene ds;
    ds.scene = loaded->scene;
    if (ds.scene.placements.size() > 15) ds.scene.placements.resize(15);
    ds.scene.heightmapSize = {1024, 1024};
    ds.scene.pose.animation = "squat";
    ds.images = loaded->images;
    auto model = std::make_shared<const Model>(std::move(loaded->model));
    const int clip = model->findClip("squat");
    ds.clipDuration = clip >= 0 ? model->clips[static_cast<std::size_t>(clip)].duration : 1.0;
    ds.model = std::move(model);
    return ds;
}

namespace {

/// CPU time of the whole process so far (every thread: llvmpipe's raster threads too), ms.
double processCpuMs() {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    const auto ms = [](const timeval& t) {
        return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_usec) / 1e3;
    };
    return ms(ru.ru_utime) + ms(ru.ru_stime);
}

/// One case of part 2 ("--frame pbr/1024/post"); empty: all of them.
struct FrameFilter {
    std::string shading, aa;
    int size = 0;
    bool empty() const { return size == 0; }
};

/// The per-frame loop on the default character; appends one result per configuration.
int benchFrames(Renderer& renderer, const DefaultScene& ds, int repeat, const FrameFilter& only,
                nlohmann::json& cases) {
    Scene scene = ds.scene;
    const auto& model = ds.model;
    const double duration = ds.clipDuration;
    HeightMaps cpuHeights; // reused: no per-frame allocation
    for (bool cpuMaps : {false, true})
        for (const Shading shading : {Shading::Legacy, Shading::Pbr, Shading::Skin})
        for (int size : {512, 1024})
            for (const AntiAliasing aa : {AntiAliasing::None, AntiAliasing::Post, AntiAliasing::Msaa})
            for (const char* key : {"none", "unshadowed", "shadowed", "unshadowed_orbit", "shadowed_orbit"}) {
                // The pbr and skin shadings' cost is measured with GPU maps only; the key light's
                // (render.key_light, with and without its shadow map) at 1024² without AA.
                if (cpuMaps && shading != Shading::Legacy) continue;
                const bool keyLight = std::string_view(key) != "none";
                // "…_orbit": the pose still and the camera turning, as when orbiting the view in
                // the editor: the shadow map is drawn once and reused (the unshadowed orbit is
                // its baseline: the same pictures without the map).
                const std::string_view keyName(key);
                const bool orbit = keyName.size() > 6 && keyName.substr(keyName.size() - 6) == "_orbit";
                if (keyLight && (shading == Shading::Legacy || size != 1024 || aa != AntiAliasing::None)) continue;
                if (!only.empty() && (cpuMaps || keyLight || toString(shading) != only.shading ||
                                      size != only.size || toString(aa) != only.aa))
                    continue;
                scene.render.keyLight.reset();
                if (keyLight) {
                    scene.render.keyLight = KeyLight{};
                    scene.render.keyLight->shadow = keyName.rfind("shadowed", 0) == 0;
                }
                // Off, the post-process edge pass (render.aa "post"), MSAA 4x.
                const int msaa = aa == AntiAliasing::Msaa ? 4 : 1;
                scene.render.shading = shading;
                scene.render.size = {size, size};
                scene.render.msaa = msaa;
                scene.render.aa = aa;
                std::vector<double> height, skinMs, postAa, readback, encode, staged, total;
                double cpuStart = 0.0, cpuMs = 0.0; // the unprofiled loop's process CPU time
                // Two loops: with glFinish between stages (per-stage figures), then without
                // (the frame time a client sees: pose → encoded frame).
                for (bool profile : {true, false})
                    for (int r = 0; r <= repeat; ++r) {
                        const auto t0 = std::chrono::steady_clock::now();
                        FrameOverrides overrides;
                        overrides.time = orbit ? duration * 0.5 : duration * (r % 8) / 8.0; // the pose moves every frame
                        if (orbit) overrides.yaw = 15.0 * r;
                        auto plan = planFrame(scene, *model, ds.images, nullptr, overrides);
                        if (!plan) {
                            std::cerr << plan.error().message << "\n";
                            return 1;
                        }
                        FrameRequest request = frameRequest(*plan, model);
                        request.profile = profile;
                        double cpuBakeMs = 0.0;
                        if (cpuMaps) { // the paper's "CPU" configuration: bake, then upload
                            auto ms = useCpuMaps(request, plan->heights, cpuHeights);
                            if (!ms) {
                                std::cerr << ms.error().message << "\n";
                                return 1;
                            }
                            cpuBakeMs = *ms;
                        }
                        auto result = renderer.renderFrame(request);
                        if (!result) {
                            std::cerr << result.error().message << "\n";
                            return 1;
                        }
                        const auto te = std::chrono::steady_clock::now();
                        auto png = encodePng(result->image, false);
                        if (!png) {
                            std::cerr << png.error().message << "\n";
                            return 1;
                        }
                        if (r == 0) { // warm-up: uploads, allocation
                            if (!profile) cpuStart = processCpuMs();
                            continue;
                        }
                        if (!profile) {
                            total.push_back(msSince(t0));
                            if (r == repeat) cpuMs = processCpuMs() - cpuStart;
                            continue;
                        }
                        height.push_back(cpuMaps ? cpuBakeMs + result->timings.heightMs
                                                 : result->timings.heightMs);
                        skinMs.push_back(result->timings.skinMs);
                        postAa.push_back(result->timings.postAaMs);
                        readback.push_back(result->timings.readbackMs);
                        encode.push_back(msSince(te));
                        staged.push_back(msSince(t0));
                    }
                cases.push_back({{"name", "frame"},
                                 {"heightmaps", cpuMaps ? "cpu" : "gpu"},
                                 {"shading", toString(shading)},
                                 {"key_light", key},
                                 {"moves", orbit ? "camera" : "pose"},
                                 {"frame_size", size},
                                 {"map_size", 1024},
                                 {"aa", toString(aa)},
                                 {"msaa", msaa},
                                 {"placements", scene.placements.size()},
                                 {"triangles", model->triangleCount()},
                                 {"joints", model->joints.size()},
                                 {"height_ms", round2(medianMs(height))},
                                 {"skin_ms", round2(medianMs(skinMs))},
                                 {"post_aa_ms", round2(medianMs(postAa))},
                                 {"readback_ms", round2(medianMs(readback))},
                                 {"png_encode_ms", round2(medianMs(encode))},
                                 {"total_ms", round2(medianMs(total))},
                                 {"total_with_stage_syncs_ms", round2(medianMs(staged))},
                                 {"cpu_ms_per_frame", round2(cpuMs / std::max(1, repeat))},
                                 {"repetitions", total.size()}});
            }
    if (!only.empty() && cases.empty()) {
        std::cerr << "dermis-bench: --frame " << only.shading << "/" << only.size << "/" << only.aa
                  << " names no case (shading legacy|pbr|skin, size 512|1024, aa none|post|msaa)\n";
        return 2;
    }
    return 0;
}

/// SSIM of the squat at t = 0.5 s, 1024², with each anti-aliasing mode against MSAA 4x and
/// against a supersampled frame (2048² with MSAA 4x, each 2×2 block averaged: 16 samples).
int benchAaQuality(Renderer& renderer, const DefaultScene& ds, nlohmann::json& out) {
    const auto frame = [&](AntiAliasing aa, int size) -> Result<Image8> {
        Scene scene = ds.scene;
        scene.render.size = {size, size};
        scene.render.aa = aa;
        scene.render.msaa = 4;
        FrameOverrides overrides;
        overrides.time = ds.clipDuration * 0.5;
        auto plan = planFrame(scene, *ds.model, ds.images, nullptr, overrides);
        if (!plan) return plan.error();
        auto result = renderer.renderFrame(frameRequest(*plan, ds.model));
        if (!result) return result.error();
        return std::move(result->image);
    };
    auto big = frame(AntiAliasing::Msaa, 2048);
    auto msaa = frame(AntiAliasing::Msaa, 1024), post = frame(AntiAliasing::Post, 1024),
         none = frame(AntiAliasing::None, 1024);
    for (const auto* r : {&big, &msaa, &post, &none})
        if (!*r) {
            std::cerr << r->error().message << "\n";
            return 1;
        }
    auto truth = boxDownsample(*big, 2);
    if (!truth) {
        std::cerr << truth.error().message << "\n";
        return 1;
    }
    const auto s = [](const Image8& a, const Image8& b) { return std::round(*ssim(a, b) * 10000) / 10000; };
    out = {{"frame_size", 1024},
           {"vs_msaa4", {{"none", s(*none, *msaa)}, {"post", s(*post, *msaa)}}},
           {"vs_supersampled", {{"none", s(*none, *truth)}, {"post", s(*post, *truth)}, {"msaa4", s(*msaa, *truth)}}}};
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    int repeat = 15;
    bool gpu = true, cpu = true, scaling = false;
    FrameFilter only;
    GlBackend backend = GlBackend::Auto;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
            repeat = std::max(1, std::atoi(argv[++i]));
        } else if (std::strcmp(argv[i], "--gl") == 0 && i + 1 < argc) {
            auto b = glBackendFromString(argv[++i]);
            if (!b) {
                std::cerr << "dermis-bench: unknown --gl backend " << argv[i] << "\n";
                return 2;
            }
            backend = *b;
        } else if (std::strcmp(argv[i], "--no-gpu") == 0) {
            gpu = false;
        } else if (std::strcmp(argv[i], "--no-cpu") == 0) {
            cpu = false;
        } else if (std::strcmp(argv[i], "--scaling") == 0) {
            scaling = true;
        } else if (std::strcmp(argv[i], "--only-scaling") == 0) {
            scaling = true;
            gpu = cpu = false;
        } else if (std::strcmp(argv[i], "--frame") == 0 && i + 1 < argc) {
            const std::string spec = argv[++i];
            const auto a = spec.find('/'), b = spec.rfind('/');
            if (a == std::string::npos || a == b || std::atoi(spec.c_str() + a + 1) <= 0) {
                std::cerr << "dermis-bench: --frame wants SHADING/SIZE/AA, e.g. pbr/1024/post\n";
                return 2;
            }
            only = {spec.substr(0, a), spec.substr(b + 1), std::atoi(spec.c_str() + a + 1)};
            cpu = false;
        } else {
            std::cerr << "usage: dermis-bench [--repeat N] [--gl BACKEND] [--no-gpu] [--no-cpu] "
                         "[--scaling | --only-scaling] [--frame SHADING/SIZE/AA]\n";
            return 2;
        }
    }

    std::vector<HeightImage> patterns;
    for (unsigned k = 0; k < 8; ++k) patterns.push_back(makePattern(512, k + 1));
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(0.15, 0.85), sc(0.08, 0.3), rot(-90, 90), t(0.2, 1.0);
    std::vector<BakePlacement> placements;
    for (int k = 0; k < 15; ++k) {
        BakePlacement p;
        p.pattern = &patterns[k % patterns.size()];
        p.footprint.center = {u(rng), u(rng)};
        p.footprint.scale = {sc(rng), sc(rng)};
        p.footprint.rotationDeg = rot(rng);
        p.model = k % 5 == 4 ? DeformModel::Bias : DeformModel::Scale;
        p.target = k % 4 == 3 ? Target::Displacement : Target::Bump;
        p.t = t(rng);
        placements.push_back(p);
    }

    const int hw = std::max(1u, std::thread::hardware_concurrency());
    nlohmann::json cases = nlohmann::json::array();
    for (int size : {1024, 2048})
        for (int threads : {1, hw}) {
            if (!cpu) break;
            BakeSettings s;
            s.width = s.height = size;
            s.threads = threads;
            // Steady state of a per-frame loop: the maps' storage is reused (bakeHeightMapsInto),
            // so the figure is the bake itself, not the allocator's page faults.
            std::vector<double> ms;
            HeightMaps maps;
            for (int r = 0; r <= repeat; ++r) {
                const auto t0 = std::chrono::steady_clock::now();
                auto status = bakeHeightMapsInto(placements, s, maps);
                const auto t1 = std::chrono::steady_clock::now();
                if (!status) {
                    std::cerr << status.error().message << "\n";
                    return 1;
                }
                if (r > 0) ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
            }
            cases.push_back({{"name", "cpu_heightmaps"},
                             {"size", size},
                             {"placements", placements.size()},
                             {"threads", threads},
                             {"median_ms", std::round(medianMs(ms) * 100) / 100},
                             {"min_ms", std::round(*std::min_element(ms.begin(), ms.end()) * 100) / 100},
                             {"repetitions", ms.size()}});
        }
    nlohmann::json gpuInfo = nullptr;
    nlohmann::json encoders = nullptr, scalingOut = nullptr, aaQuality = nullptr, heightmapFetch = nullptr;
    if (gpu || scaling) {
        auto renderer = Renderer::create(backend);
        if (!renderer) {
            std::cerr << renderer.error().message << "\n";
            return 1;
        }
        const RendererInfo& info = (*renderer)->info();
        gpuInfo = {{"backend", info.backend}, {"gl_renderer", info.renderer}, {"gl_version", info.version}};
        auto ds = loadDefaultScene();
        if (!ds) {
            std::cerr << ds.error().message << "\n";
            return 1;
        }
        if (gpu) {
            if (int rc = benchFrames(**renderer, *ds, repeat, only, cases); rc != 0) return rc;
        }
        if (gpu && only.empty()) {
            if (int rc = benchAaQuality(**renderer, *ds, aaQuality); rc != 0) return rc;
            encoders = nlohmann::json::array();
            if (int rc = benchEncoders(**renderer, *ds, std::max(5, repeat), encoders); rc != 0)
                return rc;
            if (int rc = benchHeightmapFetch(**renderer, *ds, repeat, heightmapFetch); rc != 0) return rc;
        }
        if (scaling) {
            scalingOut = nlohmann::json::array();
            if (int rc = benchScaling(**renderer, *ds, scalingOut); rc != 0) return rc;
        }
    }
    nlohmann::json out = {{"benchmark", "dermis"},
                          {"hardware_threads", hw},
                          {"gl", gpuInfo},
                          {"results", cases},
                          {"aa_quality", aaQuality},
                          {"encoders", encoders},
                          {"heightmap_fetch", heightmapFetch},
                          {"scaling", scalingOut}};
    std::cout << out.dump(2) << "\n";
    return 0;
}
