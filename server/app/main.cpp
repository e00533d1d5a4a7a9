// dermis-server — command line entry point. The offline commands:
//   dermis-server bake   --scene S.json --out DIR [--time T] [--threads N] [--png] [--gpu] [--normals] [--gl B]
//   dermis-server render --scene S.json --out frame.png [--time T | --frames A:B:STEP] [--size WxH] [--msaa N] [--aa M]
//                        [--view V] [--heightmaps] [--gl B]
//   dermis-server render … --frames A:B:STEP --shard I/N|auto/N [--resume]   (a farm shard)
//   dermis-server farm-verify OUT --frames A:B:STEP [--json]
//   dermis-server info   [--gl B]
//   dermis-server [serve] [--bind 127.0.0.1] [--port 8080] [--data DIR] [--token T] [--gl B]
//                         [--gpu-cache-mb MB] [--content-cache-mb MB] [limits]
// Errors go to stderr as "dermis-server: error: <message>" with exit code 1 (2 for usage).
#include "app/cli_common.hpp"
#include "app/render_cmd.hpp"
#include "core/frame_plan.hpp"
#include "core/layout_gen.hpp"
#include "core/normalmap.hpp"
#include "gl/gl_backend.hpp"
#include "gl/renderer.hpp"
#include "io/frame_io.hpp"
#include "io/frame_queue.hpp"
#include "io/image_io.hpp"
#include "io/scene_files.hpp"
#include "http/api.hpp"
#include "service/service.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <iostream>
#include <regex>
#include <csignal>
#include <thread>

namespace {

using namespace dermis::app;

// --- bake ------------------------------------------------------------------------------------

struct BakeArgs {
    std::string scene, out, gl = "auto", content;
    double time = -1.0;
    bool hasTime = false;
    int threads = 0;
    bool png = false, gpu = false, normals = false;
};

int runBake(const BakeArgs& a) {
    using namespace dermis;
    auto t0 = std::chrono::steady_clock::now();
    auto loaded = loadSceneFile(a.scene, a.content.empty() ? dermisContentDir() : a.content);
    if (!loaded) return fail(loaded.error());
    FrameOverrides overrides;
    if (a.hasTime) overrides.time = a.time;
    // SPEC §8: the maps live in the layout the scene names (as on the server).
    auto layout = textureLayoutFor(loaded->model, loaded->scene.uvLayout);
    if (!layout) return fail(layout.error());
    overrides.layout = std::make_shared<const TextureLayout>(std::move(*layout));
    auto plan = planFrame(loaded->scene, loaded->model, loaded->images, loaded->base, overrides);
    if (!plan) return fail(plan.error());
    HeightMaps maps;
    std::string how = "CPU";
    if (a.gpu) {
        auto renderer = Renderer::create(backendOf(a.gl));
        if (!renderer) return fail(renderer.error());
        auto gpuMaps = (*renderer)->bakeHeightMaps(plan->heights);
        if (!gpuMaps) return fail(gpuMaps.error());
        maps = std::move(*gpuMaps);
        how = "GPU (" + (*renderer)->info().backend + ", " + (*renderer)->info().renderer + ")";
    } else {
        auto cpuMaps = bakeHeightMaps(plan->heights, a.threads);
        if (!cpuMaps) return fail(cpuMaps.error());
        maps = std::move(*cpuMaps);
    }
    std::error_code ec;
    std::filesystem::create_directories(a.out, ec);
    if (ec)
        return fail(makeError(ErrorCode::Io, "dermis-server bake", a.out,
                              "cannot create the output folder: " + ec.message()));
    if (auto s = writeFloatImage(a.out + "/bump.exr", maps.bump); !s) return fail(s.error());
    if (auto s = writeFloatImage(a.out + "/displacement.exr", maps.displacement); !s)
        return fail(s.error());
    if (a.png) {
        if (auto s = writeHeight16Png(a.out + "/bump.png", maps.bump); !s) return fail(s.error());
        if (auto s = writeHeight16Png(a.out + "/displacement.png", maps.displacement); !s)
            return fail(s.error());
    }
    if (a.normals) {
        auto normal = normalMapFromBump(
            maps.bump, normalMapStrength(plan->render.bumpStrength, maps.bump.width));
        if (!normal) return fail(normal.error());
        if (auto s = writeFrame(a.out + "/normal.png", encodeNormalMap8(*normal)); !s)
            return fail(s.error());
    }
    std::cout << "baked " << maps.bump.width << "x" << maps.bump.height << " maps of "
              << loaded->scene.placements.size() << " placements on the " << how << " into "
              << a.out << " (" << static_cast<int>(msSince(t0)) << " ms)\n";
    return 0;
}

// --- info ------------------------------------------------------------------------------------

int runInfo(const std::string& gl) {
    using namespace dermis;
    auto renderer = Renderer::create(backendOf(gl));
    if (!renderer) return fail(renderer.error());
    const RendererInfo& i = (*renderer)->info();
    nlohmann::json j = {{"dermis_version", "0.1.0"},
                        {"backend", i.backend},
                        {"device", i.device},
                        {"gl_vendor", i.vendor},
                        {"gl_renderer", i.renderer},
                        {"gl_version", i.version},
                        {"glsl_version", i.glslVersion},
                        {"max_texture_size", i.maxTextureSize},
                        {"max_samples", i.maxSamples},
                        {"aa_auto", resolveAntiAliasing(RenderSettings{}, i.software, i.maxSamples).label()},
                        {"tried", i.tried}};
    std::cout << j.dump(2) << "\n";
    return 0;
}

// --- serve -----------------------------------------------------------------------------------

struct ServeArgs {
    std::string bind = "127.0.0.1", data = "dermis-data", content, token, gl = "auto", web;
    int port = 8080;
    dermis::ServerLimits limits;
    double maxUploadMb = 64;
    double gpuCacheMb = static_cast<double>(dermis::kDefaultGpuCacheBytes >> 20);
    double contentCacheMb = static_cast<double>(dermis::ServerLimits{}.contentCacheBytes >> 20);
    double decodeBudgetMb = static_cast<double>(dermis::ServerLimits{}.decodeBudgetBytes >> 20);
    std::string historyKeep = "all";
    dermis::ApiOptions api; ///< connection limits (head deadline, per-address and total caps)
};

int runServe(ServeArgs a) {
    using namespace dermis;
    if (a.token.empty())
        if (const char* env = std::getenv("DERMIS_TOKEN")) a.token = env;
    // A short token is guessed quickly even at the throttled rate (docs/reliability.md).
    if (!a.token.empty() && a.token.size() < 16)
        std::cerr << "dermis-server: warning: the token is " << a.token.size()
                  << " characters; use at least 16 random ones (e.g. `openssl rand -hex 16`)\n";
    a.limits.maxUploadBytes = static_cast<std::size_t>(a.maxUploadMb * 1024.0 * 1024.0);
    a.limits.contentCacheBytes = static_cast<std::size_t>(a.contentCacheMb * 1024.0 * 1024.0);
    a.limits.decodeBudgetBytes = static_cast<std::size_t>(a.decodeBudgetMb * 1024.0 * 1024.0);
    auto keep = parseHistoryRetention(a.historyKeep);
    if (!keep) return fail(keep.error());
    a.limits.historyKeep = *keep;
    // SIGINT/SIGTERM are taken by a waiting thread (blocked here, before any thread starts).
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
    std::signal(SIGPIPE, SIG_IGN);

    RendererOptions rendererOptions;
    rendererOptions.cacheBudgetBytes = static_cast<std::size_t>(a.gpuCacheMb * 1024.0 * 1024.0);
    auto renderer = Renderer::create(backendOf(a.gl), rendererOptions);
    if (!renderer) return fail(renderer.error());
    ServiceConfig config;
    config.dataDir = a.data;
    config.contentDir = a.content.empty() ? dermisContentDir() : a.content;
    config.limits = a.limits;
    auto service = Service::open(config, std::move(*renderer));
    if (!service) return fail(service.error());
    for (const std::string& w : (*service)->warnings())
        std::cerr << "dermis-server: warning: skipped " << w << "\n";
    // A fresh data folder starts with one scene: the default character and pattern set — unless
    // the limits given refuse it (--max-render-side 512, --max-placements 1, …): then the server
    // starts without it and says why.
    if ((*service)->listScenes()["scenes"].empty()) {
        auto created = (*service)->createScene({{"default_patterns", true}});
        if (!created)
            std::cerr << "dermis-server: warning: no default scene: the limits given refuse it ("
                      << created.error().message << "); create scenes through the API or the editor\n";
    }
    const nlohmann::json scenes = (*service)->listScenes()["scenes"];
    const std::string firstScene = scenes.empty() ? "" : scenes[0]["id"].get<std::string>();
    ApiOptions opt = a.api;
    opt.bind = a.bind;
    opt.port = a.port;
    opt.token = a.token;
    opt.webDir = a.web.empty() ? config.contentDir + "/web" : a.web;
    Api api(**service, opt);
    auto port = api.bind();
    if (!port) return fail(port.error());
    const nlohmann::json info = (*service)->info();
    std::cout << "dermis-server: serving http://" << a.bind << ":" << *port << "/ (editor), API http://"
              << a.bind << ":" << *port << "/api/v1 — " << info["backend"].get<std::string>() << ", "
              << info["gl"]["renderer"].get<std::string>() << "; data in " << a.data
              << ", content in " << config.contentDir
              << (a.token.empty() ? "" : "; token required (bearer, or the page's sign-in)") << "\n";
    if (!firstScene.empty())
        std::cout << "dermis-server: scene " << firstScene << ": http://" << a.bind << ":" << *port
                  << "/api/v1/scenes/" << firstScene << "/frame\n";
    std::cout << std::flush;
    std::thread waiter([&api, signals] {
        int sig = 0;
        sigwait(&signals, &sig);
        api.stop();
    });
    api.run();
    // Wake the waiter if the server stopped for another reason.
    pthread_kill(waiter.native_handle(), SIGTERM);
    waiter.join();
    std::cout << "dermis-server: stopped" << std::endl;
    return 0;
}

void addServeOptions(CLI::App& app, ServeArgs& s) {
    app.add_option("--bind", s.bind, "Address to listen on (127.0.0.1 = this machine only)");
    app.add_option("--port", s.port, "TCP port (0 = any free port)")->check(CLI::Range(0, 65535));
    app.add_option("--data", s.data, "Data directory: uploads and scenes, written durably");
    app.add_option("--content", s.content,
                   "Built-in content directory, read only: patterns/, models/, web/ "
                   "(default $DERMIS_CONTENT_DIR or the source tree)");
    app.add_option("--token", s.token,
                   "Token every API route but /health and /session requires, as a bearer token or "
                   "through a page's sign-in (POST /api/v1/session) (or $DERMIS_TOKEN)");
    app.add_option("--web", s.web, "Folder of the web editor served at / (default: the content folder's web/)");
    app.add_option("--gpu-cache-mb", s.gpuCacheMb,
                   "GPU memory kept for pattern textures and model uploads between renders "
                   "(least recently used freed first; deleted content freed at once)")
        ->check(CLI::Range(0.0, 1048576.0));
    app.add_option("--content-cache-mb", s.contentCacheMb,
                   "Memory kept for models and patterns that batches (POST /render) sent by content "
                   "address, decoded (least recently used freed first; a replica that lacks one "
                   "answers 409 missing_content)")
        ->check(CLI::Range(0.0, 1048576.0));
    app.add_option("--max-upload-mb", s.maxUploadMb, "Largest request body / upload")->check(CLI::Range(0.001, 4096.0));
    app.add_option("--max-render-side", s.limits.maxRenderSide, "Largest frame side")->check(CLI::Range(16, 8192));
    app.add_option("--max-map-side", s.limits.maxMapSide, "Largest height-map side")->check(CLI::Range(16, 4096));
    app.add_option("--max-image-side", s.limits.maxImageSide, "Largest uploaded pattern side; model textures above it are downscaled")->check(CLI::Range(16, 8192));
    app.add_option("--max-placements", s.limits.maxPlacements, "Most placements per scene")->check(CLI::Range(1, 100000));
    app.add_option("--max-triangles", s.limits.maxTriangles, "Most triangles per model (after instancing)");
    app.add_option("--max-joints", s.limits.maxJoints, "Most joints per model");
    app.add_option("--queue", s.limits.queueLength, "Renders that may wait for the GL thread")->check(CLI::Range(1, 10000));
    app.add_option("--timeout", s.limits.requestTimeoutSeconds,
                   "Request read/write timeout (s): a body read or an answer written must make "
                   "progress within it (a client that stops reading is dropped)")
        ->check(CLI::Range(1, 3600));
    app.add_option("--head-timeout", s.api.headSeconds,
                   "Seconds a connection has to send a whole request head (line and headers); "
                   "past it the connection is closed")
        ->check(CLI::Range(1, 3600));
    app.add_option("--max-connections-per-address", s.api.maxConnectionsPerAddress,
                   "Connections open at once from one peer address; past it the address's oldest "
                   "idle one is closed, or the new one answered 503 when none is idle")
        ->check(CLI::Range(1, 65536));
    app.add_option("--max-connections", s.api.maxConnections,
                   "Connections open at once in all (one thread each); past it the oldest connection "
                   "that never finished a request head is closed for the new one, else 503, closed")
        ->check(CLI::Range(1, 65536));
    app.add_option("--decode-budget-mb", s.decodeBudgetMb,
                   "Memory of pattern decodes in flight (uploads, batch parts); a decode that does not "
                   "fit waits up to 2 s, then 503")
        ->check(CLI::Range(16.0, 65536.0));
    app.add_option("--history-keep", s.historyKeep,
                   "History each scene keeps: N (the newest N revisions), Nd (those of the last N "
                   "days) or all (the default); older revisions answer 410 and their files are "
                   "compacted away")
        ->check(CLI::Validator(
            [](std::string& v) {
                auto r = dermis::parseHistoryRetention(v);
                return r ? std::string() : r.error().message;
            },
            "N|Nd|all"));
    app.add_option("--max-streams-per-address", s.api.maxStreamsPerAddress,
                   "Event streams one peer address may hold (default: half of the server's 16); "
                   "raise it behind a reverse proxy, where every stream comes from its address")
        ->check(CLI::Range(1, 65536));
}

} // namespace

int main(int argc, char** argv) {
    CLI::App app{"Dermis render server: skin deformation with dynamic height patterns"};
    app.set_version_flag("--version", "dermis-server 0.1.0");
    app.require_subcommand(0, 1);
    ServeArgs serve;
    addServeOptions(app, serve);
    app.add_option("--gl", serve.gl, "GL backend")->check(CLI::IsMember(kBackendNames));
    CLI::App* serveCmd = app.add_subcommand("serve", "Run the HTTP server (the default)");
    serveCmd->fallthrough();

    BakeArgs bake;
    CLI::App* bakeCmd = app.add_subcommand(
        "bake", "Write the height maps of a scene as EXR (CPU reference, or --gpu)");
    bakeCmd->add_option("--scene", bake.scene, "Scene document (dermis.scene/1)")
        ->required()
        ->check(CLI::ExistingFile);
    bakeCmd->add_option("--out", bake.out, "Output folder for bump.exr and displacement.exr")
        ->required();
    bakeCmd->add_option("--time", bake.time, "Animation time in seconds (overrides pose.time)")
        ->check(CLI::NonNegativeNumber);
    bakeCmd->add_option("--threads", bake.threads, "CPU worker threads (0 = all cores)")
        ->check(CLI::Range(0, 256));
    bakeCmd->add_flag("--png", bake.png, "Also write 16-bit PNG previews (0.5 grey = height 0)");
    bakeCmd->add_flag("--gpu", bake.gpu, "Bake with the GL height pass instead of the CPU");
    bakeCmd->add_flag("--normals", bake.normals,
                      "Also write normal.png, a UV-space normal map of the bump map");
    bakeCmd->add_option("--content", bake.content, "Built-in content directory (builtin: names)");
    bakeCmd->add_option("--gl", bake.gl, "GL backend for --gpu")
        ->check(CLI::IsMember(kBackendNames));

    RenderArgs render;
    CLI::App* renderCmd = app.add_subcommand("render", "Render frames of a scene to image files");
    renderCmd->add_option("--scene", render.scene, "Scene document (dermis.scene/1)")
        ->required()
        ->check(CLI::ExistingFile);
    renderCmd->add_option("--out", render.out,
                          "Output image (.png, .jpg, .webp, .exr); with --frames a pattern like "
                          "dir/frame_%04d.png")
        ->required();
    auto* timeOpt = renderCmd->add_option("--time", render.time, "Animation time in seconds")
                        ->check(CLI::NonNegativeNumber);
    renderCmd->add_option("--frames", render.frames,
                          "Animation range A:B:STEP in seconds (frame k at A + k·STEP)")
        ->excludes(timeOpt);
    renderCmd->add_option("--size", render.size, "Frame size WxH (overrides render.size)");
    renderCmd->add_option("--msaa", render.msaa,
                          "MSAA with 1, 2 or 4 samples per pixel (overrides render.msaa and selects MSAA)")
        ->check(CLI::IsMember({1, 2, 4}));
    renderCmd->add_option("--aa", render.aa,
                          "Anti-aliasing: auto (post on software rasterizers, else MSAA), msaa, post or none "
                          "(overrides render.aa)")
        ->check(CLI::IsMember({"auto", "msaa", "post", "none"}));
    renderCmd->add_option("--shading", render.shading,
                          "pbr (the default: the model's glTF material under image-based light), skin (pbr "
                          "with light scattered under the skin and a second specular lobe) or legacy (one key "
                          "light, the look before PBR; overrides render.shading)")
        ->check(CLI::IsMember({"legacy", "pbr", "skin"}));
    renderCmd->add_option("--exposure", render.exposure, "pbr: light scale before tone mapping (overrides render.exposure)")
        ->check(CLI::Range(0.0, 64.0));
    renderCmd->add_option("--tone-mapping", render.toneMapping,
                          "pbr: neutral (Khronos PBR Neutral), aces or none (overrides render.tone_mapping)")
        ->check(CLI::IsMember({"neutral", "aces", "none"}));
    renderCmd->add_option("--environment", render.environment,
                          "pbr: light the frame with this equirectangular image (.hdr, .exr; linear radiance) "
                          "instead of the default studio environment")
        ->check(CLI::ExistingFile);
    renderCmd->add_option("--key-light", render.keyLight,
                          "pbr and skin: a directional key light with a shadow, X,Y,Z (world, towards the "
                          "light) or X,Y,Z,INTENSITY, or off (overrides render.key_light)");
    renderCmd->add_flag("--no-shadows", render.noShadows, "The key light casts no shadow");
    renderCmd->add_option("--view", render.view,
                          "shaded (default), or unlit: bump / displacement height as grey, normal")
        ->check(CLI::IsMember({"shaded", "bump", "displacement", "normal", "basecolor", "lighting"}));
    renderCmd->add_flag("--timings", render.timings,
                        "Print where the time went (start-up, the first frame's stages, encode) as JSON on stderr");
    renderCmd->add_flag("--heightmaps", render.heightmaps,
                        "Also write <frame>.bump.exr and <frame>.displacement.exr");
    renderCmd->add_option("--content", render.content, "Built-in content directory (builtin: names)");
    renderCmd->add_option("--gl", render.gl, "GL backend")->check(CLI::IsMember(kBackendNames));
    renderCmd->add_option("--shard", render.shard,
                          "Render only slice I of N of the range, interleaved (frames k with "
                          "k mod N = I); auto/N takes I from SLURM_ARRAY_TASK_ID or "
                          "JOB_COMPLETION_INDEX. Skips complete frames, writes "
                          "manifest.shard-I-of-N.json beside them");
    renderCmd->add_flag("--resume", render.resume, "Skip frames whose file already exists");

    FarmVerifyArgs verify;
    CLI::App* verifyCmd = app.add_subcommand(
        "farm-verify", "Check that every frame of a range exists and matches the shards' manifests");
    verifyCmd->add_option("out", verify.out, "Frame pattern (dir/frame_%04d.png) or the frames' folder")
        ->required();
    verifyCmd->add_option("--frames", verify.frames, "Animation range A:B:STEP in seconds")->required();
    verifyCmd->add_flag("--json", verify.json, "Print the report as JSON");

    std::string infoGl = "auto";
    CLI::App* infoCmd = app.add_subcommand("info", "Print the GL backend and driver as JSON");
    infoCmd->add_option("--gl", infoGl, "GL backend")->check(CLI::IsMember(kBackendNames));

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    if (bakeCmd->parsed()) {
        bake.hasTime = bakeCmd->count("--time") > 0;
        return runBake(bake);
    }
    if (renderCmd->parsed()) {
        render.hasTime = renderCmd->count("--time") > 0;
        return runRender(render);
    }
    if (verifyCmd->parsed()) return runFarmVerify(verify);
    if (infoCmd->parsed()) return runInfo(infoGl);
    return runServe(serve);
}
