// dermis-proposebench — prints JSON figures for SPEC §8 proposals and transfer (issue #23: ≤ 2 s
// for a 50k-triangle model with 60 joints): per model, the time of the body map, the
// range-of-motion analysis, the proposals and a transfer of the default set onto it.
// Usage: dermis-proposebench [--repeat N]
//   (default 3 repetitions, median and smallest reported; models: the built-in default character,
//   the default character subdivided twice with joints added up to 60 (≈ 75k triangles: over the
//   issue's 50k), and tests/models' CesiumMan, RiggedFigure and KayKit Barbarian)
//
// Single-threaded, like the server's analysis (built once per model, on the first propose or
// pick). Wall time and the thread's CPU time (nearer an idle machine's on a busy one).
#include "BuildPaths.hpp"
#include "core/body_map.hpp"
#include "core/model_derived.hpp"
#include "core/motion.hpp"
#include "core/propose.hpp"
#include "core/subdivide.hpp"
#include "core/transfer.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include <time.h>

using namespace dermis;
using json = nlohmann::json;

namespace {

double threadSeconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

double ms(double s) { return std::round(s * 1e4) / 10.0; }

} // namespace

int main(int argc, char** argv) {
    int repeat = 3;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
        else {
            std::cerr << "usage: dermis-proposebench [--repeat N]\n";
            return 2;
        }
    }
    const std::string testModels = dermis::build::testModelsDir();
    auto source = loadSceneFile(dermisContentDir() + "/models/default.scene.json");
    if (!source) {
        std::cerr << source.error().message << "\n";
        return 1;
    }
    const auto sourceModel = std::make_shared<const Model>(source->model);
    ModelDerived from(sourceModel);
    const TransferModel src{*sourceModel, from.restSkin(), from.bodyMap(), &from.uvLookup(), sourceModel.get()};

    std::vector<std::pair<std::string, Model>> models;
    models.push_back({"default", source->model});
    {
        auto big = subdivideModel(source->model, 2);
        if (big) big = withSyntheticJoints(*big, 60);
        if (big) models.push_back({"default x16, 60 joints", std::move(*big)});
    }
    for (const char* rel : {"/CesiumMan/CesiumMan.glb", "/RiggedFigure/RiggedFigure.glb",
                            "/KayKitBarbarian/Barbarian.glb"}) {
        auto m = loadGltfFile(testModels + rel);
        if (m) models.push_back({rel, std::move(*m)});
        else std::cerr << rel << ": " << m.error().message << "\n";
    }
    json out = json::array();
    for (auto& [name, model] : models) {
        const auto held = std::make_shared<const Model>(model);
        std::vector<double> wall, cpu, body, motion, propose, transfer;
        std::size_t proposals = 0, mapped = 0, samples = 0;
        for (int r = 0; r < repeat; ++r) {
            ModelDerived d(held);
            d.restSkin();
            d.symmetryPlane(); // shared with the mirror and lint: not counted
            const auto t0 = std::chrono::steady_clock::now();
            const double c0 = threadSeconds();
            const BodyMap b = mapBody(model, d.restSkin(), d.symmetryPlane());
            const auto t1 = std::chrono::steady_clock::now();
            const MotionAnalysis m = analyzeMotion(model, d.restSkin(), b);
            const auto t2 = std::chrono::steady_clock::now();
            const auto p = proposePatterns(model, d.restSkin(), d.symmetryPlane(), b, m);
            const auto t3 = std::chrono::steady_clock::now();
            const double c1 = threadSeconds();
            const TransferModel dst{model, d.restSkin(), b, nullptr, nullptr};
            const TransferResult tr = transferPlacements(source->scene.placements, src, dst);
            const auto t4 = std::chrono::steady_clock::now();
            const auto sec = [](auto a, auto b2) { return std::chrono::duration<double>(b2 - a).count(); };
            body.push_back(sec(t0, t1));
            motion.push_back(sec(t1, t2));
            propose.push_back(sec(t2, t3));
            wall.push_back(sec(t0, t3));
            cpu.push_back(c1 - c0);
            transfer.push_back(sec(t3, t4));
            proposals = p.size();
            mapped = tr.mapped.size();
            samples = m.samples.size();
        }
        out.push_back({{"model", name},
                       {"triangles", model.triangleCount()},
                       {"joints", model.joints.size()},
                       {"clips", model.clips.size()},
                       {"samples", samples},
                       {"proposals", proposals},
                       {"propose_ms", {{"median", ms(median(wall))}, {"min", ms(*std::min_element(wall.begin(), wall.end()))},
                                       {"thread_cpu_median", ms(median(cpu))}}},
                       {"parts_ms", {{"body_map", ms(median(body))}, {"motion", ms(median(motion))}, {"proposals", ms(median(propose))}}},
                       {"transfer_default_set", {{"mapped", mapped}, {"of", source->scene.placements.size()}, {"ms", ms(median(transfer))}}}});
    }
    std::cout << json{{"bench", "propose"}, {"repeat", repeat}, {"models", out}}.dump(2) << "\n";
    return 0;
}
