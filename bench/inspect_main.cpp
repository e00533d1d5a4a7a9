// dermis-inspectbench — prints JSON figures (milliseconds) for the Service's inspection routes that
// read per-model derived data (UV index, symmetry plane, clip ranges, UV diagnosis): lint, pick by
// UV, mirror, a model's details (GET /models/{id}).
// Usage: dermis-inspectbench [--repeat N] [--model PATH]…
//   (default 15 repetitions; models: the built-in default character, tests/models' CesiumMan and
//   KayKit Barbarian when present, or the --model files given)
//
// The Service is opened on a temporary data folder with a renderer that renders nothing (these
// routes never render). For each model one scene is stored: the default pattern set on the
// built-in character, examples/cesiumman.scene.json's placements on CesiumMan, and on any other
// model a pair of placements on the first joint with a mirror twin (by name) and that twin, at
// the texture point where that joint's skin weight is largest. Per route it reports the first call on a freshly
// opened service (`first_ms`: whatever the route builds per model on a cold start) and the median
// of the next N calls (`median_ms`); `core` times building the UV index, the symmetry plane and
// the UV diagnosis (with the rest skin and plane it reads) alone (median of min(N, 5)). Lint's
// first call builds the UV diagnosis (its uv_overlap); the model's details then read it. Mirror adds a placement (a durable edit, fsync included);
// the twin is deleted again after each (`delete_placement`: that durable edit alone) so the
// scene stays the same.
#include "BuildPaths.hpp"
#include "bench_common.hpp"

#include "core/mirror.hpp"
#include "core/uv_diagnosis.hpp"
#include "core/uv_lookup.hpp"
#include "io/atomic_file.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"
#include "service/service.hpp"

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

using namespace dermis;
using namespace dermis::bench;
using json = nlohmann::json;

namespace {

/// A renderer for routes that never render: every render fails.
class NoRenderer final : public FrameRenderer {
public:
    NoRenderer() {
        info_.backend = "none";
        info_.renderer = "no renderer (dermis-inspectbench)";
    }
    const RendererInfo& info() const override { return info_; }
    Result<HeightMaps> bakeHeightMaps(const HeightPassInput&) override { return refused(); }
    Result<FrameResult> renderFrame(const FrameRequest&) override { return refused(); }

private:
    static Error refused() {
        return makeError(ErrorCode::Unsupported, "dermis-inspectbench", "",
                         "this benchmark does not render");
    }
    RendererInfo info_;
};

/// One model's scene: the document (its "model" filled in by the caller), the placement that
/// mirror and pick by UV use.
struct BenchScene {
    json doc;
    std::string placement;
    std::string twin; ///< the placement's twin in `doc` (deleted first: a mirror onto it is a 409)
    double u = 0.5, v = 0.5;
};

/// A scene for a model without a prepared one: `placement` on the first joint with a twin by
/// name, at the UV grid point where that joint's skin weight is largest, and the twin's
/// placement at the mirrored point (found by core mirrorPlacement).
Result<BenchScene> generatedScene(const Model& m) {
    const UvLookup lookup(m);
    for (int node : m.joints) {
        const std::string name = m.nodes[static_cast<std::size_t>(node)].name;
        if (mirrorJointName(m, name).empty()) continue;
        float best = 0.0f;
        glm::dvec2 at{0.5, 0.5};
        for (int j = 0; j < 64; ++j)
            for (int i = 0; i < 64; ++i) {
                const glm::dvec2 uv{(i + 0.5) / 64.0, (j + 0.5) / 64.0};
                if (auto hit = lookup.find(uv))
                    if (float w = lookup.weightOf(*hit, node); w > best) {
                        best = w;
                        at = uv;
                    }
            }
        if (best < 0.5f) continue;
        Placement p;
        p.id = "a";
        p.pattern = "crease";
        p.center = {at.x, at.y};
        p.scale = {0.05, 0.05};
        p.joint = name;
        p.axis = {1.0, 0.0, 0.0};
        p.axisName = "x";
        p.thetaMin = 0;
        p.thetaMax = 90;
        auto twin = mirrorPlacement(p, m, lookup, symmetryPlane(m));
        if (!twin) continue;
        twin->id = "b";
        Scene s;
        s.placements = {p, *twin};
        BenchScene out;
        out.doc = toJson(s);
        out.placement = "a";
        out.twin = "b";
        out.u = at.x;
        out.v = at.y;
        return out;
    }
    return makeError(ErrorCode::NotFound, "dermis-inspectbench", "",
                     "no joint with a twin by name");
}

template <class F> double timeMs(F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    return msSince(t0);
}

template <class T> T checked(Result<T> r, const std::string& what) {
    if (!r) {
        std::cerr << "dermis-inspectbench: " << what << ": " << r.error().message << "\n";
        std::exit(1);
    }
    return std::move(*r);
}

/// The three routes on one model, on a freshly opened service (so `first_ms` is a cold start).
json benchModel(const std::string& label, const std::string& path, int repeat,
                const std::filesystem::path& dataDir) {
    std::filesystem::remove_all(dataDir);
    ServiceConfig config;
    config.dataDir = dataDir.string();
    config.contentDir = dermisContentDir();
    auto svc = checked(Service::open(config, std::make_unique<NoRenderer>()), "open");

    BenchScene bs;
    std::string modelId = "builtin:default";
    if (path.empty()) {
        bs.doc = {{"default_patterns", true}};
        bs.placement = "elbow_l";
        bs.twin = "elbow_r";
    } else {
        auto bytes = checked(readWholeFile(path), path);
        modelId = checked(svc->addModel(bytes, label), "upload " + path)["id"].get<std::string>();
        if (label == "CesiumMan") {
            bs.doc =
                json::parse(std::ifstream(dermisContentDir() + "/examples/cesiumman.scene.json"));
            bs.placement = "knee_l";
            bs.twin = "knee_r";
        } else {
            const Model m = checked(loadGltfFile(path), path);
            bs = checked(generatedScene(m), label);
        }
    }
    bs.doc["model"] = modelId;
    const std::string id = checked(svc->createScene(bs.doc), "scene")["id"].get<std::string>();
    // Mirroring onto an existing twin is a 409: the twin goes first, each mirror below makes it
    // again and the loop deletes it after each. So lint sees the scene without that twin (one
    // mirror pair fewer than before mirrors refused to stack).
    checked(svc->deletePlacement(id, bs.twin, {}), "delete the twin");
    const json scene = checked(svc->getScene(id), "scene")["scene"];
    if (bs.placement == "elbow_l" || bs.placement == "knee_l")
        for (const json& p : scene["placements"])
            if (p["id"] == bs.placement) {
                bs.u = p["center"][0].get<double>();
                bs.v = p["center"][1].get<double>();
            }

    json out = {{"model", label},
                {"triangles", 0},
                {"placements", scene["placements"].size()},
                {"mirror_placement", bs.placement}};
    const json listed = svc->listModels();
    for (const json& m : listed["models"])
        if (m["id"] == modelId) out["triangles"] = m["triangles"];

    auto lint = [&] { checked(svc->lint(id), "lint"); };
    auto pick = [&] {
        if (!checked(svc->pickUv(id, bs.u, bs.v), "pick-uv")["hit"].get<bool>()) {
            std::cerr << "dermis-inspectbench: pick-uv missed on " << label << "\n";
            std::exit(1);
        }
    };
    std::string twin;
    auto mirror = [&] {
        twin = checked(svc->mirrorPlacement(id, bs.placement, {}), "mirror")["scene"]["placements"]
                   .back()["id"];
    };
    auto undoMirror = [&] { checked(svc->deletePlacement(id, twin, {}), "delete twin"); };
    auto details = [&] { checked(svc->getModel(modelId), "model"); };

    // Each route's first call on its own fresh service would need three opens per model; the
    // routes share what they build, so the first of the three (lint) would pay for the others.
    // Instead: first calls in the order pick, mirror, lint, each the first of its kind.
    json routes = json::object();
    const double pickFirst = timeMs(pick);
    const double mirrorFirst = timeMs(mirror);
    undoMirror();
    const double lintFirst = timeMs(lint);
    const double detailsFirst = timeMs(details);
    std::vector<double> lintMs, pickMs, mirrorMs, editMs, detailsMs;
    for (int r = 0; r < repeat; ++r) {
        lintMs.push_back(timeMs(lint));
        pickMs.push_back(timeMs(pick));
        mirrorMs.push_back(timeMs(mirror));
        editMs.push_back(timeMs(undoMirror));
        detailsMs.push_back(timeMs(details));
    }
    routes["pick_uv"] = {{"first_ms", round2(pickFirst)}, {"median_ms", round2(medianMs(pickMs))}};
    routes["mirror"] = {{"first_ms", round2(mirrorFirst)},
                        {"median_ms", round2(medianMs(mirrorMs))}};
    routes["lint"] = {{"first_ms", round2(lintFirst)}, {"median_ms", round2(medianMs(lintMs))}};
    routes["model_details"] = {{"first_ms", round2(detailsFirst)}, {"median_ms", round2(medianMs(detailsMs))}};
    // The durable edit alone (deleting the twin again), which mirror also pays.
    routes["delete_placement"] = {{"median_ms", round2(medianMs(editMs))}};
    out["routes"] = routes;
    // What the routes rebuilt per request before the per-model cache, timed alone (core).
    const std::string file =
        path.empty() ? resolveModelPath("builtin:default", "", dermisContentDir()) : path;
    const Model model = checked(loadGltfFile(file), file);
    std::vector<double> lookupMs, planeMs, diagnosisMs;
    for (int r = 0; r < std::min(repeat, 5); ++r) {
        lookupMs.push_back(timeMs([&] { const UvLookup lookup(model); }));
        planeMs.push_back(timeMs([&] { (void)symmetryPlane(model); }));
        diagnosisMs.push_back(timeMs([&] { (void)diagnoseUvs(model); }));
    }
    out["core"] = {{"uv_lookup_build_ms", round2(medianMs(lookupMs))},
                   {"symmetry_plane_ms", round2(medianMs(planeMs))},
                   {"uv_diagnosis_ms", round2(medianMs(diagnosisMs))}};
    out["repetitions"] = repeat;
    return out;
}

} // namespace

int main(int argc, char** argv) {
    int repeat = 15;
    std::vector<std::string> models;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
            repeat = std::max(1, std::atoi(argv[++i]));
        } else if (std::strcmp(argv[i], "--model") == 0 && i + 1 < argc) {
            models.emplace_back(argv[++i]);
        } else {
            std::cerr << "usage: dermis-inspectbench [--repeat N] [--model PATH]…\n";
            return 2;
        }
    }
    std::vector<std::pair<std::string, std::string>> cases; // label, path ("" = built-in)
    if (models.empty()) {
        cases.emplace_back("builtin:default", "");
        const std::string dir = dermis::build::testModelsDir();
        for (auto [label, rel] :
             {std::pair{"CesiumMan", "/CesiumMan/CesiumMan.glb"},
              std::pair{"KayKitBarbarian", "/KayKitBarbarian/Barbarian.glb"}})
            if (std::filesystem::exists(dir + rel)) cases.emplace_back(label, dir + rel);
    } else {
        for (const std::string& m : models)
            cases.emplace_back(std::filesystem::path(m).stem().string(), m);
    }

    std::error_code ec;
    const auto dataDir = std::filesystem::temp_directory_path(ec) /
                         ("dermis-inspectbench-" + std::to_string(static_cast<long>(::getpid())));
    json results = json::array();
    for (const auto& [label, path] : cases)
        results.push_back(benchModel(label, path, repeat, dataDir));
    std::filesystem::remove_all(dataDir, ec);
    std::cout << json{{"inspect", results}}.dump(2) << "\n";
    return 0;
}
