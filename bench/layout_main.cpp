// dermis-layoutbench — prints JSON figures for the generated height-map layout (core
// generateTextureLayout, SPEC §8 `uv_layout: generated`): time per model size and what the layout
// is like. Usage: dermis-layoutbench [--repeat N] [--model PATH]…
//   (default 5 repetitions after one unmeasured run; models: the built-in default character and
//   ../shared's CesiumMan, RiggedFigure and KayKit Barbarian, each also subdivided once (×4
//   triangles, core subdivideModel), and the default character subdivided twice (×16, ≈ 69k
//   triangles) — or the --model files given, as they are)
//
// Per model: triangles, parts, the median and the smallest of the generation times (ms, the
// final verification included), charts, splits, degenerate triangles, texel density, and the
// layout's check at 1024² (used fraction of [0,1]², overlapping texels, smallest gutter, area
// stretch and conformal distortion, chart density spread). Single-threaded, like the generator.
#include "core/layout_gen.hpp"
#include "core/subdivide.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

using namespace dermis;
using json = nlohmann::json;

namespace {

double round3(double v) { return std::round(v * 1000) / 1000; }

json benchModel(const std::string& label, const Model& model, int repeat) {
    std::vector<double> ms;
    Result<GeneratedLayout> made = generateTextureLayoutWithReport(model); // unmeasured
    for (int r = 0; r < repeat && made; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        made = generateTextureLayoutWithReport(model);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                         .count());
    }
    json out = {{"model", label}, {"triangles", model.triangleCount()},
                {"parts", model.parts.size()}};
    if (!made) {
        out["error"] = made.error().message;
        return out;
    }
    std::sort(ms.begin(), ms.end());
    const LayoutCheck& c = made->check;
    out["median_ms"] = round3(ms[ms.size() / 2]);
    out["min_ms"] = round3(ms.front());
    out["charts"] = made->charts;
    out["splits"] = made->splits;
    out["degenerate"] = made->degenerate;
    out["texels_per_metre"] = round3(made->texelsPerMetre);
    out["check_1024"] = {{"used_fraction", round3(c.usedFraction)},
                         {"overlap_texels", c.overlapTexels},
                         {"min_gutter_texels", c.minGutterTexels},
                         {"flipped", c.flipped},
                         {"area_stretch", round3(c.areaStretch)},
                         {"conformal", round3(c.conformal)},
                         {"chart_density_min", round3(c.chartDensityMin)},
                         {"chart_density_max", round3(c.chartDensityMax)}};
    return out;
}

Model load(const std::string& path) {
    auto m = loadGltfFile(path);
    if (!m) {
        std::cerr << "dermis-layoutbench: " << path << ": " << m.error().message << "\n";
        std::exit(1);
    }
    return std::move(*m);
}

Model subdivided(const Model& m, int levels) {
    auto s = subdivideModel(m, levels);
    if (!s) {
        std::cerr << "dermis-layoutbench: subdivide: " << s.error().message << "\n";
        std::exit(1);
    }
    return std::move(*s);
}

} // namespace

int main(int argc, char** argv) {
    int repeat = 5;
    std::vector<std::string> paths;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
            repeat = std::max(1, std::atoi(argv[++i]));
        } else if (std::strcmp(argv[i], "--model") == 0 && i + 1 < argc) {
            paths.emplace_back(argv[++i]);
        } else {
            std::cerr << "usage: dermis-layoutbench [--repeat N] [--model PATH]…\n";
            return 2;
        }
    }
    json results = json::array();
    if (!paths.empty()) {
        for (const std::string& p : paths)
            results.push_back(benchModel(p, load(p), repeat));
    } else {
        const std::string shared = std::string(DERMIS_SHARED_DIR) + "/models/";
        const std::vector<std::pair<std::string, std::string>> models = {
            {"default", resolveModelPath("builtin:default", "", dermisContentDir())},
            {"CesiumMan", shared + "CesiumMan/CesiumMan.glb"},
            {"RiggedFigure", shared + "RiggedFigure/RiggedFigure.glb"},
            {"KayKitBarbarian", shared + "KayKitBarbarian/Barbarian.glb"}};
        for (const auto& [label, path] : models) {
            if (!std::filesystem::exists(path)) continue;
            const Model m = load(path);
            results.push_back(benchModel(label, m, repeat));
            results.push_back(benchModel(label + " ×4", subdivided(m, 1), repeat));
            if (label == "default") results.push_back(benchModel(label + " ×16", subdivided(m, 2), repeat));
        }
    }
    std::cout << json{{"layout", results}, {"repetitions", repeat}}.dump(2) << "\n";
    return 0;
}
