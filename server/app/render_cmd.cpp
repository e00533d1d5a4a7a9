#include "app/render_cmd.hpp"

#include "app/cli_common.hpp"
#include "core/frame_plan.hpp"
#include "core/frame_range.hpp"
#include "core/layout_gen.hpp"
#include "gl/renderer.hpp"
#include "io/atomic_file.hpp"
#include "io/farm_manifest.hpp"
#include "io/frame_io.hpp"
#include "io/frame_queue.hpp"
#include "io/image_io.hpp"
#include "io/scene_files.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <iostream>
#include <mutex>

namespace dermis::app {
namespace fs = std::filesystem;

namespace {

std::string withoutExtension(const std::string& path) {
    const fs::path p(path);
    return (p.parent_path() / p.stem()).string();
}

} // namespace

namespace {

/// --key-light and --no-shadows over the scene's render.key_light (RenderArgs::keyLight); the
/// light then by validateRenderSettings, errors naming the option.
Status applyKeyLightOptions(const RenderArgs& a, RenderSettings& render) {
    const char* where = "dermis-server render";
    if (a.keyLight == "off") {
        render.keyLight.reset();
    } else if (!a.keyLight.empty()) {
        double v[4] = {0.0, 0.0, 0.0, -1.0};
        char tail = 0;
        const int n = std::sscanf(a.keyLight.c_str(), "%lf,%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &v[3], &tail);
        if (n != 3 && n != 4)
            return makeError(ErrorCode::InvalidArgument, where, "--key-light",
                             "expected X,Y,Z or X,Y,Z,INTENSITY (numbers) or off, got \"" + a.keyLight + "\"");
        KeyLight k = render.keyLight.value_or(KeyLight{});
        k.direction = {v[0], v[1], v[2]};
        if (n == 4) k.intensity = v[3];
        render.keyLight = k;
    }
    if (a.noShadows && render.keyLight) render.keyLight->shadow = false;
    if (auto s = validateRenderSettings(render, {}, where); !s) {
        Error e = s.error();
        if (!a.keyLight.empty() && e.field.rfind("/render/key_light", 0) == 0) {
            const std::string prefix = std::string(where) + ": ";
            if (e.message.rfind(prefix, 0) == 0) e.message.erase(0, prefix.size());
            e.message = prefix + "--key-light: " + e.message;
            e.field = "--key-light";
        }
        return e;
    }
    return Ok{};
}

} // namespace

int runRender(const RenderArgs& a) {
    const char* where = "dermis-server render";
    auto t0 = std::chrono::steady_clock::now();
    const auto format = frameFormatFromPath(a.out);
    if (!format)
        return fail(makeError(ErrorCode::InvalidArgument, where, "--out",
                              "the file name must end in .png, .jpg, .jpeg, .webp or .exr"));
    const bool animation = !a.frames.empty();
    FrameRange range;
    std::vector<int> frames{0}; // the frame numbers this run renders
    if (animation) {
        auto r = parseFrameRange(a.frames);
        if (!r) return fail(r.error());
        range = *r;
        if (range.count > 1 && !hasFrameField(a.out))
            return fail(makeError(ErrorCode::InvalidArgument, where, "--out",
                                  "a frame range needs a %04d-style field in the file name"));
    }
    Shard shard;
    const bool sharded = !a.shard.empty();
    if (sharded) {
        if (!animation)
            return fail(makeError(ErrorCode::InvalidArgument, where, "--shard",
                                  "--shard splits a range: give --frames A:B:STEP"));
        auto s = parseShard(a.shard, [](const char* name) { return std::getenv(name); });
        if (!s) return fail(s.error());
        shard = *s;
    }
    if (animation) frames = shardFrames(range, shard);
    const bool skipComplete = sharded || a.resume;
    FrameOverrides overrides;
    overrides.view = frameViewFromString(a.view).value_or(FrameView::Shaded); // checked by CLI11
    if (a.msaa) overrides.msaa = a.msaa;
    if (!a.aa.empty()) overrides.aa = antiAliasingFromString(a.aa);
    if (!a.shading.empty()) overrides.shading = shadingFromString(a.shading);
    if (!a.toneMapping.empty()) overrides.toneMapping = toneMappingFromString(a.toneMapping);
    if (a.exposure >= 0.0) overrides.exposure = a.exposure;
    if (!a.size.empty()) {
        int w = 0, h = 0;
        char tail = 0;
        if (std::sscanf(a.size.c_str(), "%dx%d%c", &w, &h, &tail) != 2)
            return fail(makeError(ErrorCode::InvalidArgument, where, "--size",
                                  "expected WxH, got \"" + a.size + "\""));
        overrides.width = w;
        overrides.height = h;
    }
    const auto pathOf = [&](int k) { return animation ? framePath(a.out, k) : a.out; };
    // Frames already complete (their file exists: files appear by rename only) are not rendered
    // again; their manifest entries are computed from the files.
    std::vector<ManifestEntry> entries;
    std::mutex entriesLock;
    std::vector<int> todo;
    for (int k : frames) {
        std::error_code ec;
        if (skipComplete && fs::is_regular_file(pathOf(k), ec)) {
            if (sharded) {
                auto e = manifestEntryOfFile(k, pathOf(k));
                if (!e) return fail(e.error());
                entries.push_back(*e);
            }
            continue;
        }
        todo.push_back(k);
    }
    const std::size_t skipped = frames.size() - todo.size();
    if (todo.empty()) {
        if (sharded) {
            if (auto s = writeShardManifest(a.out, a.frames, shard, entries); !s) return fail(s.error());
        }
        std::cout << "all " << frames.size() << " frames" << (sharded ? " of shard " + a.shard : "")
                  << " are complete; nothing rendered (" << static_cast<int>(msSince(t0)) << " ms)\n";
        return 0;
    }

    // The GL context starts (EGL, shader compilation) on the renderer's thread while this thread
    // loads and parses the scene, its model and patterns: the two take similar time cold.
    nlohmann::json timings = nlohmann::json::object();
    timings["args_ms"] = msSince(t0);
    auto rendererStart = std::async(std::launch::async, [&] { return Renderer::create(backendOf(a.gl)); });
    auto tLoad = std::chrono::steady_clock::now();
    auto loaded = loadSceneFile(a.scene, a.content.empty() ? dermisContentDir() : a.content);
    timings["scene_load_ms"] = msSince(tLoad);
    if (!loaded) return fail(loaded.error());
    if (auto s = applyKeyLightOptions(a, loaded->scene.render); !s) return fail(s.error());
    // SPEC §8: the height-map layout by the service's rule (core textureLayoutFor) and its
    // rest-surface map, baked once for every frame when a surface placement needs it — still
    // while the renderer starts.
    auto tLayout = std::chrono::steady_clock::now();
    auto model = std::make_shared<const Model>(std::move(loaded->model));
    auto layout = textureLayoutFor(*model, loaded->scene.uvLayout);
    if (!layout) return fail(layout.error());
    overrides.layout = std::make_shared<const TextureLayout>(std::move(*layout));
    for (const Placement& p : loaded->scene.placements)
        if (p.enabled && p.projection == Projection::Surface && !overrides.layout->empty()) {
            overrides.rest = std::make_shared<const RestSurfaceMap>(
                bakeRestSurface(*model, *overrides.layout, loaded->scene.heightmapSize[0],
                                loaded->scene.heightmapSize[1]));
            break;
        }
    timings["layout_ms"] = msSince(tLayout);
    tLoad = std::chrono::steady_clock::now();
    auto renderer = rendererStart.get();
    timings["renderer_wait_ms"] = msSince(tLoad);
    if (!renderer) return fail(renderer.error());
    const double stillTime = a.hasTime ? a.time : loaded->scene.pose.time;
    // The one range check of render settings (size included) runs in planFrame; "--size" is named
    // when the size it set is out of range.
    auto checkSize = [&](Error e) {
        if (!a.size.empty() && e.field.rfind("/render/size", 0) == 0) {
            e.field = "--size";
            e.message = std::string(where) + ": --size: " + e.message;
        }
        return e;
    };

    timings["context_ms"] = (*renderer)->info().contextMs;
    timings["programs_ms"] = (*renderer)->info().programsMs;
    RenderSettings used;
    // Frames are encoded and written on a worker while the next one renders (at most two waiting:
    // bounded memory). Each file's bytes are those of the sequential path (deterministic encoders).
    FrameWriteQueue writer(1, 2);
    // --environment, else the scene's `render.environment` (a path relative to the document;
    // builtin:studio or none: the default studio).
    std::shared_ptr<const EnvironmentImage> environment;
    std::string environmentFile = a.environment;
    if (const std::string& named = loaded->scene.render.environment;
        environmentFile.empty() && !named.empty() && named != kBuiltinStudioEnvironment)
        environmentFile = (std::filesystem::path(loaded->baseDir) / named).lexically_normal().string();
    if (!environmentFile.empty()) {
        auto env = readEnvironmentImage(environmentFile);
        if (!env) {
            Error e = env.error();
            if (a.environment.empty()) e.field = "/render/environment";
            return fail(e);
        }
        environment = std::make_shared<const EnvironmentImage>(std::move(*env));
    }
    for (int k : todo) {
        const bool first = k == todo.front();
        const auto tFrame = std::chrono::steady_clock::now();
        overrides.time = animation ? range.time(k) : stillTime;
        auto plan = planFrame(loaded->scene, *model, loaded->images, loaded->base, overrides);
        if (!plan) return fail(checkSize(plan.error()));
        FrameRequest request = frameRequest(*plan, model);
        request.readHeightMaps = a.heightmaps;
        request.environment = environment;
        request.profile = a.timings && first; // a GL sync between stages: per-stage figures
        used = plan->render;
        auto result = (*renderer)->renderFrame(request);
        if (!result) return fail(result.error());
        if (a.timings && first) {
            const FrameTimings& ft = result->timings;
            timings["first_frame"] = {{"aa", result->antiAliasing}, {"height_ms", ft.heightMs},
                                      {"skin_ms", ft.skinMs},       {"post_aa_ms", ft.postAaMs},
                                      {"readback_ms", ft.readbackMs}, {"total_ms", msSince(tFrame)}};
        }
        const std::string path = pathOf(k);
        auto frame = std::make_shared<FrameResult>(std::move(*result));
        const bool heightmaps = a.heightmaps;
        const FrameFormat f = *format;
        auto job = [&, path, frame, heightmaps, f, k]() -> Status {
            if (auto s = createFolderOf(path); !s) return s;
            auto bytes = encodeFrame(frame->image, f);
            if (!bytes) return bytes.error();
            if (auto s = writeFileAtomically(path, *bytes, Durability::Atomic, "dermis::writeFrame"); !s)
                return s;
            if (sharded) {
                std::lock_guard<std::mutex> lock(entriesLock);
                entries.push_back(manifestEntry(k, path, *bytes));
            }
            if (heightmaps && frame->maps) {
                const std::string stem = withoutExtension(path);
                if (auto s = writeFloatImage(stem + ".bump.exr", frame->maps->bump); !s) return s;
                if (auto s = writeFloatImage(stem + ".displacement.exr", frame->maps->displacement); !s)
                    return s;
            }
            return Ok{};
        };
        const auto tWrite = std::chrono::steady_clock::now();
        if (auto s = todo.size() == 1 ? job() : writer.push(std::move(job)); !s)
            return fail(s.error());
        if (todo.size() == 1) timings["encode_write_ms"] = msSince(tWrite);
    }
    if (auto s = writer.finish(); !s) return fail(s.error());
    if (sharded) {
        if (auto s = writeShardManifest(a.out, a.frames, shard, entries); !s) return fail(s.error());
    }
    std::cout << "rendered " << todo.size() << (todo.size() == 1 ? " frame" : " frames");
    if (skipped) std::cout << " (" << skipped << " already complete)";
    if (sharded) std::cout << " of shard " << shard.index << "/" << shard.count;
    std::cout << " of " << used.size[0] << "x" << used.size[1] << " with "
              << (*renderer)->info().backend << " (" << (*renderer)->info().renderer << ") to "
              << (animation ? pathOf(todo.front()) + " …" : a.out) << " ("
              << static_cast<int>(msSince(t0)) << " ms)\n";
    if (a.timings) {
        timings["frames"] = todo.size();
        timings["total_ms"] = msSince(t0);
        for (auto& [key, value] : timings.items())
            if (value.is_number_float()) value = std::round(value.get<double>() * 10) / 10;
        for (auto& [key, value] : timings["first_frame"].items())
            if (value.is_number_float()) value = std::round(value.get<double>() * 10) / 10;
        std::cerr << nlohmann::json{{"timings", timings}}.dump() << "\n";
    }
    return 0;
}

int runFarmVerify(const FarmVerifyArgs& a) {
    const char* where = "dermis-server farm-verify";
    auto range = parseFrameRange(a.frames);
    if (!range) return fail(range.error());
    std::string pattern = a.out;
    std::error_code ec;
    if (fs::is_directory(a.out, ec)) {
        // A folder: the frame names come from its manifests ("out"), frame_%04d.png otherwise.
        pattern.clear();
        for (const auto& e : fs::directory_iterator(a.out, ec)) {
            const std::string name = e.path().filename().string();
            if (name.rfind("manifest.shard-", 0) != 0 || e.path().extension() != ".json") continue;
            auto bytes = readWholeFile(e.path().string(), std::size_t(64) << 20, where);
            if (!bytes) return fail(bytes.error());
            auto doc = nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false);
            if (doc.is_object() && doc.contains("out") && doc["out"].is_string()) {
                pattern = (fs::path(a.out) / doc["out"].get<std::string>()).string();
                break;
            }
        }
        if (pattern.empty()) pattern = (fs::path(a.out) / "frame_%04d.png").string();
    }
    if (range->count > 1 && !hasFrameField(pattern))
        return fail(makeError(ErrorCode::InvalidArgument, where, "OUT",
                              "expected a folder or a pattern with a %04d-style field"));
    auto report = verifyFarm(pattern, *range);
    if (!report) return fail(report.error());
    if (a.json) {
        std::cout << report->toJson().dump(1) << "\n";
    } else {
        for (const std::string& p : report->problems) std::cout << p << "\n";
        std::cout << (report->complete() ? "complete: " : "INCOMPLETE: ") << report->ok.size()
                  << " of " << report->expected << " frames ok, " << report->missing.size()
                  << " missing, " << report->corrupt.size() << " corrupt";
        if (!report->unlisted.empty())
            std::cout << " (" << report->unlisted.size() << " in no manifest but decodable)";
        std::cout << "; " << report->manifests.size() << " manifests\n";
    }
    return report->complete() ? 0 : 1;
}

} // namespace dermis::app
