// dermis-layoutbench — prints JSON figures for the generated height-map layout (core
// generateTextureLayout, SPEC §8 `uv_layout: generated`): time per model size and what the layout
// is like. Usage: dermis-layoutbench [--repeat N] [--cone DEGREES] [--png DIR]
//                                    [--model PATH [--subdivide L]]…
//   (default 5 repetitions after one unmeasured run; models: the built-in default character and
//   tests/models' CesiumMan, RiggedFigure and KayKit Barbarian, each also subdivided once (×4
//   triangles, core subdivideModel), and the default character subdivided twice (×16, ≈ 69k
//   triangles) — or the --model files given, subdivided L times with --subdivide (×4^L triangles);
//   --cone sets LayoutGenOptions::coneDegrees; --png writes DIR/layout-<model>.png,
//   each chart filled in a colour of its own, 1024²)
//
// Per model: triangles, parts, the median and the smallest of the generation times (ms, the
// final verification included; also the median CPU time of the thread, which on a busy machine is
// nearer to what an idle one takes), charts, splits, degenerate triangles, texel density, and the
// layout's check at 1024² (used fraction of [0,1]², overlapping texels, smallest gutter, area
// stretch and conformal distortion, chart density spread). Single-threaded, like the generator.
#include "BuildPaths.hpp"
#include "core/layout_gen.hpp"
#include "core/subdivide.hpp"
#include "io/frame_io.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <time.h>

using namespace dermis;
using json = nlohmann::json;

namespace {

double round3(double v) {
    return std::round(v * 1000) / 1000;
}

/// A picture of the layout: each chart's triangles filled in a colour of its own (texel centres
/// inside), on black.
void writePicture(const Model& model, const GeneratedLayout& g, const std::string& path) {
    const int n = 1024;
    Image8 img;
    img.width = img.height = n;
    img.rgba.assign(static_cast<std::size_t>(n) * n * 4, 0);
    for (std::size_t k = 0; k < model.parts.size(); ++k) {
        const PartLayout& pl = g.layout.parts[k];
        for (std::size_t t = 0; t < pl.indices.size() / 3; ++t) {
            const std::uint32_t c = g.chartOf[k][t];
            const std::uint32_t h = (c + 1) * 2654435761u;
            const std::uint8_t rgb[3] = {static_cast<std::uint8_t>(64 + (h & 127)),
                                         static_cast<std::uint8_t>(64 + ((h >> 8) & 127)),
                                         static_cast<std::uint8_t>(64 + ((h >> 16) & 127))};
            glm::dvec2 q[3];
            for (int i = 0; i < 3; ++i)
                q[i] =
                    glm::dvec2(pl.uvs[pl.indices[3 * t + static_cast<std::size_t>(i)]]) * double(n);
            const glm::dvec2 lo = glm::min(q[0], glm::min(q[1], q[2])),
                             hi = glm::max(q[0], glm::max(q[1], q[2]));
            for (int y = std::max(0, int(lo.y)); y <= std::min(n - 1, int(hi.y)); ++y)
                for (int x = std::max(0, int(lo.x)); x <= std::min(n - 1, int(hi.x)); ++x) {
                    const glm::dvec2 p(x + 0.5, y + 0.5);
                    auto side = [&](int e) {
                        const glm::dvec2 a = q[e], b = q[(e + 1) % 3];
                        return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
                    };
                    if (side(0) > 0 || side(1) > 0 || side(2) > 0) continue;
                    std::uint8_t* px =
                        &img.rgba[(static_cast<std::size_t>(y) * n + static_cast<std::size_t>(x)) *
                                  4];
                    px[0] = rgb[0];
                    px[1] = rgb[1];
                    px[2] = rgb[2];
                    px[3] = 255;
                }
        }
    }
    auto png = encodePng(img, false);
    if (png) {
        std::ofstream out(path, std::ios::binary);
        out.write(reinterpret_cast<const char*>(png->data()),
                  static_cast<std::streamsize>(png->size()));
    }
}

std::string pictureDir;
LayoutGenOptions options;

/// CPU time of this thread, ms (the generator is single-threaded: on a busy machine this is
/// what the wall time would be on an idle one, near enough).
double threadCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

json benchModel(const std::string& label, const Model& model, int repeat) {
    std::vector<double> ms, cpu;
    Result<GeneratedLayout> made = generateTextureLayoutWithReport(model, options); // unmeasured
    for (int r = 0; r < repeat && made; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        const double c0 = threadCpuMs();
        made = generateTextureLayoutWithReport(model, options);
        cpu.push_back(threadCpuMs() - c0);
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count());
    }
    json out = {
        {"model", label}, {"triangles", model.triangleCount()}, {"parts", model.parts.size()}};
    if (!made) {
        out["error"] = made.error().message;
        return out;
    }
    if (!pictureDir.empty()) {
        std::string name = label;
        for (char& ch : name)
            if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
        writePicture(model, *made, pictureDir + "/layout-" + name + ".png");
    }
    std::sort(ms.begin(), ms.end());
    std::sort(cpu.begin(), cpu.end());
    const LayoutCheck& c = made->check;
    out["median_ms"] = round3(ms[ms.size() / 2]);
    out["min_ms"] = round3(ms.front());
    out["median_cpu_ms"] = round3(cpu[cpu.size() / 2]);
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
    int repeat = 5, levels = 0;
    std::vector<std::string> paths;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
            repeat = std::max(1, std::atoi(argv[++i]));
        } else if (std::strcmp(argv[i], "--subdivide") == 0 && i + 1 < argc) {
            levels = std::atoi(argv[++i]);
        } else if (std::strcmp(argv[i], "--cone") == 0 && i + 1 < argc) {
            options.coneDegrees = std::atof(argv[++i]);
        } else if (std::strcmp(argv[i], "--png") == 0 && i + 1 < argc) {
            pictureDir = argv[++i];
        } else if (std::strcmp(argv[i], "--model") == 0 && i + 1 < argc) {
            paths.emplace_back(argv[++i]);
        } else {
            std::cerr << "usage: dermis-layoutbench [--repeat N] [--cone DEGREES] [--png DIR] "
                         "[--model PATH [--subdivide L]]…\n";
            return 2;
        }
    }
    json results = json::array();
    if (!paths.empty()) {
        for (const std::string& p : paths)
            results.push_back(benchModel(levels ? p + " ×" + std::to_string(1 << (2 * levels)) : p,
                                         subdivided(load(p), levels), repeat));
    } else {
        const std::string shared = std::string(dermis::build::testModelsDir()) + "/";
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
            if (label == "default")
                results.push_back(benchModel(label + " ×16", subdivided(m, 2), repeat));
        }
    }
    std::cout << json{{"layout", results}, {"repetitions", repeat}}.dump(2) << "\n";
    return 0;
}
