// dermis-server — command line entry point. For now the offline commands:
//   dermis-server bake --scene S.json --out DIR [--time T] [--threads N] [--png]
// Errors go to stderr as "dermis-server: error: <message>" with exit code 1 (2 for usage).
#include "io/image_io.hpp"
#include "io/scene_files.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace {

int fail(const dermis::Error& e) {
    std::cerr << "dermis-server: error: " << e.message << "\n";
    return 1;
}

struct BakeArgs {
    std::string scene, out;
    double time = -1.0;
    bool hasTime = false;
    int threads = 0;
    bool png = false;
};

int runBake(const BakeArgs& a) {
    using namespace dermis;
    auto t0 = std::chrono::steady_clock::now();
    auto loaded = loadSceneFile(a.scene);
    if (!loaded) return fail(loaded.error());
    SceneBakeOptions opt;
    if (a.hasTime) opt.time = a.time;
    opt.base = loaded->base ? &*loaded->base : nullptr;
    opt.threads = a.threads;
    auto maps = bakeScene(loaded->scene, loaded->model, loaded->images, opt);
    if (!maps) return fail(maps.error());
    std::error_code ec;
    std::filesystem::create_directories(a.out, ec);
    if (ec)
        return fail(makeError(ErrorCode::Io, "dermis-server bake", a.out,
                              "cannot create the output folder: " + ec.message()));
    const std::string bump = a.out + "/bump.exr", disp = a.out + "/displacement.exr";
    if (auto s = writeFloatImage(bump, maps->bump); !s) return fail(s.error());
    if (auto s = writeFloatImage(disp, maps->displacement); !s) return fail(s.error());
    if (a.png) {
        if (auto s = writeHeight16Png(a.out + "/bump.png", maps->bump); !s) return fail(s.error());
        if (auto s = writeHeight16Png(a.out + "/displacement.png", maps->displacement); !s)
            return fail(s.error());
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::cout << "baked " << maps->bump.width << "x" << maps->bump.height << " maps of "
              << loaded->scene.placements.size() << " placements into " << a.out << " ("
              << static_cast<int>(ms) << " ms)\n";
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    CLI::App app{"Dermis render server: skin deformation with dynamic height patterns"};
    app.set_version_flag("--version", "dermis-server 0.1.0");
    app.require_subcommand(1);

    BakeArgs bake;
    CLI::App* bakeCmd =
        app.add_subcommand("bake", "Write the height maps of a scene (CPU reference) as EXR");
    bakeCmd->add_option("--scene", bake.scene, "Scene document (dermis.scene/1)")
        ->required()
        ->check(CLI::ExistingFile);
    bakeCmd->add_option("--out", bake.out, "Output folder for bump.exr and displacement.exr")
        ->required();
    bakeCmd->add_option("--time", bake.time, "Animation time in seconds (overrides pose.time)")
        ->check(CLI::NonNegativeNumber);
    bakeCmd->add_option("--threads", bake.threads, "Worker threads (0 = all cores)")
        ->check(CLI::Range(0, 256));
    bakeCmd->add_flag("--png", bake.png, "Also write 16-bit PNG previews (0.5 grey = height 0)");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    if (bakeCmd->parsed()) {
        bake.hasTime = bakeCmd->count("--time") > 0;
        return runBake(bake);
    }
    return 2;
}
