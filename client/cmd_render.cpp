// frame (one frame to a file), maps (height and normal maps), render (an animation range through
// the batch route, each frame written atomically as its part arrives; --resume skips frames whose
// file exists — a file exists only complete, as it is renamed into place).
#include "batch.hpp"
#include "commands.hpp"
#include "frames.hpp"
#include "http_client.hpp"
#include "output.hpp"
#include "render_range.hpp"

#include <filesystem>
#include <iostream>

namespace dermis::cli {

namespace {

struct FrameOptions {
    std::string id, sceneFile, out, frames, size, view = "shaded", map, format, aa, shading, keyLight;
    double time = -1, yaw = 0, pitch = 0, distance = 0;
    int width = 0, height = 0, msaa = 0, revision = 0, batch = 100, parallel = 1;
    bool hasYaw = false, hasPitch = false, hasDistance = false, resume = false;
};

/// "WxH" → [W, H]; CliError exit 2 (field --size) otherwise.
nlohmann::json parseSize(const std::string& size) {
    int w = 0, h = 0;
    char tail = 0;
    if (std::sscanf(size.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 1 || h < 1)
        throw usageError("expected WxH, got \"" + size + "\"", "--size");
    return {w, h};
}

void addCameraOptions(CLI::App* cmd, const std::shared_ptr<FrameOptions>& o) {
    cmd->add_option("--yaw", o->yaw, "Camera yaw, degrees");
    cmd->add_option("--pitch", o->pitch, "Camera pitch, degrees (-90 … 90)");
    cmd->add_option("--distance", o->distance, "Camera distance (default: the scene's, auto frames the model)");
}

} // namespace

void addRenderCommands(CLI::App& app, Context& ctx) {
    auto o = std::make_shared<FrameOptions>();

    CLI::App* frame = app.add_subcommand("frame", "Render one frame of a scene to a file (.png or .jpg: the format from the extension)");
    frame->add_option("id", o->id, "Scene id")->required();
    frame->add_option("-o,--out", o->out, "Output file (.png, .jpg, .jpeg)")->required();
    frame->add_option("--width", o->width, "Width in pixels (default the scene's render.size)")->check(CLI::PositiveNumber);
    frame->add_option("--height", o->height, "Height in pixels")->check(CLI::PositiveNumber);
    frame->add_option("--time", o->time, "Seconds into the pose's clip")->check(CLI::NonNegativeNumber);
    frame->add_option("--msaa", o->msaa, "MSAA with 1, 2 or 4 samples")->check(CLI::IsMember({1, 2, 4}));
    frame->add_option("--aa", o->aa, "Anti-aliasing: auto (post on software rasterizers, else MSAA), msaa, post or none")
        ->check(CLI::IsMember({"auto", "msaa", "post", "none"}));
    frame->add_option("--shading", o->shading, "pbr (the model's glTF material under image-based light), skin (pbr with subsurface scattering) or legacy (the look before PBR)")
        ->check(CLI::IsMember({"legacy", "pbr", "skin"}));
    frame->add_option("--key-light", o->keyLight, "pbr and skin: on draws the scene's render.key_light (or the default one), off none")
        ->check(CLI::IsMember({"on", "off"}));
    frame->add_option("--view", o->view, "shaded, or bump / displacement / normal")
        ->check(CLI::IsMember({"shaded", "bump", "displacement", "normal", "basecolor", "lighting"}));
    frame->add_option("--revision", o->revision, "The scene as it was at this revision")->check(CLI::PositiveNumber);
    addCameraOptions(frame, o);
    frame->callback([&ctx, o, frame] {
        ctx.action = [&ctx, o, frame] {
            const std::string format = imageFormatOf(o->out);
            if (format.empty()) throw usageError("the file name must end in .png, .jpg or .jpeg", "--out");
            std::vector<std::pair<std::string, std::string>> q = {{"format", format}};
            if (o->width) q.push_back({"width", std::to_string(o->width)});
            if (o->height) q.push_back({"height", std::to_string(o->height)});
            if (o->time >= 0) q.push_back({"time", nlohmann::json(o->time).dump()});
            if (o->msaa) q.push_back({"msaa", std::to_string(o->msaa)});
            if (!o->aa.empty()) q.push_back({"aa", o->aa});
            if (!o->shading.empty()) q.push_back({"shading", o->shading});
            if (!o->keyLight.empty()) q.push_back({"key_light", o->keyLight});
            if (o->view != "shaded") q.push_back({"view", o->view});
            if (o->revision) q.push_back({"revision", std::to_string(o->revision)});
            if (frame->count("--yaw")) q.push_back({"yaw", nlohmann::json(o->yaw).dump()});
            if (frame->count("--pitch")) q.push_back({"pitch", nlohmann::json(o->pitch).dump()});
            if (frame->count("--distance")) q.push_back({"distance", nlohmann::json(o->distance).dump()});
            Reply r = ctx.http().download(scenePath(o->id) + "/frame?" + queryString(q), o->out, fileKindOf(format));
            if (!ctx.global.json) std::cout << o->out << "\n";
            else printJson({{"file", o->out}, {"bytes", std::stoull(r.header("X-Dermis-Bytes"))}, {"backend", r.header("X-Dermis-Backend")}});
            return kExitOk;
        };
    });

    CLI::App* maps = app.add_subcommand("maps", "Write a scene's bump or displacement height map, or its normal map (format from the extension: .png, .exr, .f32)");
    maps->add_option("id", o->id, "Scene id")->required();
    maps->add_option("map", o->map, "bump, displacement or normal")->required()->check(CLI::IsMember({"bump", "displacement", "normal"}));
    maps->add_option("-o,--out", o->out, "Output file: .png (16-bit grey; normal: 8-bit RGB), .exr, .f32 (raw floats)")->required();
    maps->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            const std::string ext = extensionOf(o->out);
            std::string format;
            if (ext == "png") format = o->map == "normal" ? "png" : "png16";
            else if (ext == "exr") format = "exr";
            else if (ext == "f32" && o->map != "normal") format = "f32";
            else throw usageError("the file name must end in .png, .exr" + std::string(o->map == "normal" ? "" : " or .f32"), "--out");
            Reply r = ctx.http().download(scenePath(o->id) + "/heightmaps/" + o->map + "?format=" + format, o->out,
                                          fileKindOf(format == "png16" ? "png" : format));
            if (!ctx.global.json) std::cout << o->out << "\n";
            else printJson({{"file", o->out}, {"bytes", std::stoull(r.header("X-Dermis-Bytes"))}});
            return kExitOk;
        };
    });

    CLI::App* render = app.add_subcommand("render", "Render an animation range to files through the batch route (POST /render), each frame written as it arrives");
    render->add_option("id", o->id, "Scene id (or --scene-file)");
    render->add_option("--scene-file", o->sceneFile, "A scene document to render instead of a stored scene")->check(CLI::ExistingFile);
    render->add_option("--frames", o->frames, "A:B:STEP in seconds: frame k at A + k·STEP (as dermis-server render)")->required();
    render->add_option("-o,--out", o->out, "File pattern with a %04d-style field, e.g. out/frame_%04d.png (.png or .jpg)")->required();
    render->add_option("--size", o->size, "WxH (overrides the scene's render.size)");
    render->add_option("--view", o->view, "shaded, or bump / displacement / normal")
        ->check(CLI::IsMember({"shaded", "bump", "displacement", "normal", "basecolor", "lighting"}));
    render->add_flag("--resume", o->resume, "Skip frames whose file exists (files appear only complete)");
    render->add_option("--batch", o->batch, "Frames per request (default 100; the server allows limits.max_batch_frames)")
        ->check(CLI::Range(1, 100000));
    render->add_option("--parallel", o->parallel,
                       "Requests in flight at once, each its own connection (default 1): replicas behind a load "
                       "balancer render side by side")
        ->check(CLI::Range(1, 64));
    render->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            if (o->id.empty() == o->sceneFile.empty()) throw usageError("give a scene id or --scene-file, not both", "id");
            const std::string format = imageFormatOf(o->out);
            if (format.empty()) throw usageError("the file name must end in .png, .jpg or .jpeg", "--out");
            const std::vector<double> times = parseFrameRange(o->frames, "--frames");
            if (times.size() > 1 && framePath(o->out, 0) == o->out)
                throw usageError("a frame range needs a %04d-style field in the file name", "--out");
            nlohmann::json scene = o->sceneFile.empty() ? ctx.http().getJson(scenePath(o->id))["scene"]
                                                        : readJsonFile(o->sceneFile, "--scene-file");
            if (!o->size.empty()) scene["render"]["size"] = parseSize(o->size);
            // A scene file's model and pattern files go by content address: any server (any
            // replica behind a load balancer) can render them, asking for the bytes it lacks.
            const ContentFiles content = o->sceneFile.empty() ? ContentFiles{} : addressContent(scene, o->sceneFile);

            RangeJob job;
            job.scene = std::move(scene);
            job.content = &content;
            job.format = format;
            job.view = o->view;
            job.out = o->out;
            job.times = times;
            for (std::size_t k = 0; k < times.size(); ++k)
                if (!o->resume || !std::filesystem::exists(framePath(o->out, static_cast<int>(k)))) job.pending.push_back(k);
            job.batch = static_cast<std::size_t>(o->batch);
            job.parallel = o->parallel;
            const std::size_t skipped = times.size() - job.pending.size();
            Progress progress("frames", job.pending.size(), stdoutIsTerminal() && !ctx.global.json, !ctx.global.json);
            RangeOutcome r;
            try {
                r = renderRange(ctx.global, job, progress);
            } catch (...) {
                progress.finish();
                throw;
            }
            progress.finish();
            const double seconds = progress.seconds();
            const double fps = seconds > 0 ? double(r.written) / seconds : 0.0;
            if (ctx.global.json) {
                nlohmann::json failed = nlohmann::json::array();
                for (const auto& f : r.failed) failed.push_back(f.first);
                printJson({{"frames", times.size()}, {"written", r.written}, {"skipped", skipped}, {"failed", failed},
                           {"interrupted", r.interrupted}, {"retries", r.retries}, {"content_sent", r.contentSent},
                           {"parallel", job.parallel}, {"seconds", seconds}, {"frames_per_second", fps}});
            } else {
                char line[200];
                std::snprintf(line, sizeof line, "rendered %zu frames of %zu (%zu skipped, %zu failed) in %.2f s, %.1f frames/s", r.written,
                              times.size(), skipped, r.failed.size(), seconds, fps);
                std::cout << line << "\n";
            }
            for (const auto& [index, message] : r.failed) std::cerr << "dermis: error: frame " << index << ": " << message << "\n";
            if (r.interrupted) {
                std::cerr << "dermis: interrupted: " << r.written << " frames written, run again with --resume for the rest\n";
                return kExitInterrupted;
            }
            return r.failed.empty() ? kExitOk : kExitFramesFailed;
        };
    });
}

} // namespace dermis::cli
