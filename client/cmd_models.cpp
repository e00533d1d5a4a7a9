// model upload|list|show|rm, pattern upload|list|rm. `model show` prints the model's UV diagnosis
// (SPEC §8) too: used and overlapping texels, the regions sharing texels, mirrored island pairs,
// texel density per driving joint.
// Uploads print the id alone on stdout (M=$(dermis model upload a.glb)); the server answers 201
// for new bytes and 200 for bytes it holds already (content-addressed: the same id again).
#include "commands.hpp"
#include "frames.hpp"
#include "http_client.hpp"
#include "output.hpp"

#include <cstdio>
#include <filesystem>
#include <iostream>

namespace dermis::cli {

namespace {

struct ModelOptions {
    std::vector<std::string> files, ids;
    std::string name, id;
};

void printUpload(const Context& ctx, const Reply& r) {
    auto j = nlohmann::json::parse(r.body, nullptr, false);
    if (ctx.global.json) printJson(j);
    else std::cout << j.value("id", "") << "\n";
}

std::string imageContentType(const std::string& path) {
    const std::string ext = extensionOf(path);
    if (ext == "png") return "image/png";
    if (ext == "jpg" || ext == "jpeg") return "image/jpeg";
    if (ext == "tif" || ext == "tiff") return "image/tiff";
    if (ext == "exr") return "image/x-exr";
    return "application/octet-stream";
}

std::string percentCell(const nlohmann::json& fraction) {
    if (!fraction.is_number()) return "-";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f%%", 100.0 * fraction.get<double>());
    return buf;
}

/// The UV diagnosis of `model show` (the `uv` member of GET /models/{id}), after its key rows.
void printUvDiagnosis(const nlohmann::json& uv) {
    std::vector<std::vector<std::string>> regions;
    for (const auto& r : uv.value("sharing", nlohmann::json::array())) {
        std::string with;
        for (const auto& o : r.value("shares_with", nlohmann::json::array()))
            with += (with.empty() ? "" : ", ") + o.value("region", std::string());
        const auto more = r.value("shares_with_more", 0);
        if (more > 0) with += " and " + std::to_string(more) + " more";
        if (with.empty()) with = "(folds onto itself)";
        regions.push_back({cell(r["region"]), cell(r["shared_texels"]), with});
    }
    if (!regions.empty()) {
        std::cout << "\n";
        printTable({"REGION", "SHARED TEXELS", "SHARES TEXELS WITH"}, regions);
    }
    std::vector<std::vector<std::string>> mirrored;
    for (const auto& p : uv.value("mirrored_pairs", nlohmann::json::array()))
        mirrored.push_back({cell(p["regions"][0]), cell(p["regions"][1]), cell(p["islands"])});
    if (!mirrored.empty()) {
        std::cout << "\n";
        printTable({"MIRRORED", "AND", "ISLANDS"}, mirrored);
    }
    std::vector<std::vector<std::string>> density;
    for (const auto& j : uv.value("density", nlohmann::json::array()))
        density.push_back({cell(j["joint"]), cell(j["triangles"]), cell(j["texels_per_unit"])});
    if (!density.empty()) {
        std::cout << "\n";
        printTable({"JOINT", "TRIANGLES", "TEXELS/UNIT @" + cell(uv.value("resolution", nlohmann::json()))}, density);
    }
}

void removeEach(Context& ctx, const std::string& kind, const std::vector<std::string>& ids) {
    for (const auto& id : ids) {
        ctx.http().send("DELETE", "/" + kind + "/" + httplib::detail::encode_query_param(id), "", "", true);
        if (!ctx.global.json) std::cout << "deleted " << id << "\n";
    }
}

} // namespace

void addModelCommands(CLI::App& app, Context& ctx) {
    auto o = std::make_shared<ModelOptions>();

    CLI::App* model = app.add_subcommand("model", "Characters: upload, list, show, rm");
    model->require_subcommand(1);
    CLI::App* up = model->add_subcommand("upload", "Upload a .glb, or a .gltf followed by its buffer and image files; prints the id");
    up->add_option("files", o->files, "FILE.glb, or FILE.gltf and its files")->required()->check(CLI::ExistingFile);
    up->add_option("--name", o->name, "Display name (default: the file's)");
    up->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            const std::string& first = o->files.front();
            const std::string ext = extensionOf(first);
            const std::string name = o->name.empty() ? std::filesystem::path(first).stem().string() : o->name;
            const std::string path = "/models?" + queryString({{"name", name}});
            if (ext == "glb") {
                if (o->files.size() > 1) throw usageError("a .glb is uploaded alone", "files");
                printUpload(ctx, ctx.http().send("POST", path, readFileOrThrow(first, "files"), "model/gltf-binary", true));
            } else if (ext == "gltf") {
                httplib::MultipartFormDataItems items;
                for (std::size_t k = 0; k < o->files.size(); ++k) {
                    const std::string file = std::filesystem::path(o->files[k]).filename().string();
                    items.push_back({k == 0 ? "gltf" : "file" + std::to_string(k), readFileOrThrow(o->files[k], "files"),
                                     file, k == 0 ? "model/gltf+json" : "application/octet-stream"});
                }
                printUpload(ctx, ctx.http().postMultipart(path, items));
            } else {
                throw usageError("expected a .glb or a .gltf, got " + first, "files");
            }
            return kExitOk;
        };
    });
    CLI::App* list = model->add_subcommand("list", "List models");
    list->callback([&ctx] {
        ctx.action = [&ctx] {
            auto j = ctx.http().getJson("/models");
            if (ctx.global.json) {
                printJson(j);
                return kExitOk;
            }
            std::vector<std::vector<std::string>> rows;
            for (const auto& m : j["models"])
                rows.push_back({cell(m["id"]), cell(m["name"]), cell(m["triangles"]), cell(m["joints"]),
                                cell(m["clips"]), cell(m["has_uvs"]), cell(m["bytes"])});
            printTable({"ID", "NAME", "TRIANGLES", "JOINTS", "CLIPS", "UVS", "BYTES"}, rows);
            return kExitOk;
        };
    });
    CLI::App* show = model->add_subcommand("show", "A model's joints, clips and UV diagnosis");
    show->add_option("id", o->id, "Model id (e.g. builtin:default)")->required();
    show->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            auto j = ctx.http().getJson("/models/" + httplib::detail::encode_query_param(o->id));
            if (ctx.global.json) {
                printJson(j);
                return kExitOk;
            }
            const nlohmann::json uv = j.value("uv", nlohmann::json::object());
            std::vector<std::vector<std::string>> keys = {
                {"id", cell(j["id"])},
                {"name", cell(j["name"])},
                {"triangles", cell(j.value("triangles", nlohmann::json()))},
                {"vertices", cell(j.value("vertices", nlohmann::json()))},
                {"joints", cell(j.value("joint_count", nlohmann::json()))},
                {"has_uvs", cell(j.value("has_uvs", nlohmann::json()))}};
            if (!uv.empty()) {
                keys.push_back({"uv_usable", cell(uv.value("usable", nlohmann::json()))});
                keys.push_back({"uv_used", percentCell(uv.value("used_fraction", nlohmann::json()))});
                keys.push_back({"uv_overlap", percentCell(uv.value("overlap_fraction", nlohmann::json()))});
                keys.push_back({"uv_islands", cell(uv.value("islands", nlohmann::json()))});
                const auto missing = uv.value("missing", nlohmann::json::object());
                keys.push_back({"uv_missing", cell(missing.value("triangles", nlohmann::json())) + " triangles"});
                const auto outside = uv.value("out_of_range", nlohmann::json::object());
                keys.push_back({"uv_out_of_range", cell(outside.value("vertices", nlohmann::json())) + " vertices"});
            }
            printTable({"KEY", "VALUE"}, keys);
            std::vector<std::vector<std::string>> clips;
            for (const auto& c : j.value("clips", nlohmann::json::array()))
                clips.push_back({cell(c["name"]), cell(c["duration"])});
            if (!clips.empty()) {
                std::cout << "\n";
                printTable({"CLIP", "DURATION"}, clips);
            }
            if (!uv.empty()) printUvDiagnosis(uv);
            return kExitOk;
        };
    });
    CLI::App* rm = model->add_subcommand("rm", "Delete uploaded models (refused while a scene uses one)");
    rm->add_option("ids", o->ids, "Model ids")->required();
    rm->callback([&ctx, o] { ctx.action = [&ctx, o] { removeEach(ctx, "models", o->ids); return kExitOk; }; });

    auto p = std::make_shared<ModelOptions>();
    CLI::App* pattern = app.add_subcommand("pattern", "Pattern images: upload, list, rm");
    pattern->require_subcommand(1);
    CLI::App* pup = pattern->add_subcommand("upload", "Upload a pattern image (PNG, JPEG, TIFF, EXR …); prints the id");
    pup->add_option("file", p->id, "Image file")->required()->check(CLI::ExistingFile);
    pup->add_option("--name", p->name, "Display name (default: the file's)");
    pup->callback([&ctx, p] {
        ctx.action = [&ctx, p] {
            const std::string name = p->name.empty() ? std::filesystem::path(p->id).stem().string() : p->name;
            printUpload(ctx, ctx.http().send("POST", "/patterns?" + queryString({{"name", name}}),
                                             readFileOrThrow(p->id, "file"), imageContentType(p->id), true));
            return kExitOk;
        };
    });
    CLI::App* plist = pattern->add_subcommand("list", "List patterns (built-in and uploaded)");
    plist->callback([&ctx] {
        ctx.action = [&ctx] {
            auto j = ctx.http().getJson("/patterns");
            if (ctx.global.json) {
                printJson(j);
                return kExitOk;
            }
            std::vector<std::vector<std::string>> rows;
            for (const auto& e : j["patterns"])
                rows.push_back({cell(e["id"]), cell(e["name"]), e.value("builtin", false) ? "built-in" : "uploaded",
                                cell(e.value("kind", nlohmann::json())), cell(e.value("target", nlohmann::json())),
                                e.contains("width") ? cell(e["width"]) + "x" + cell(e["height"]) : "-"});
            printTable({"ID", "NAME", "SOURCE", "KIND", "TARGET", "SIZE"}, rows);
            return kExitOk;
        };
    });
    CLI::App* prm = pattern->add_subcommand("rm", "Delete uploaded patterns (refused while a scene uses one)");
    prm->add_option("ids", p->ids, "Pattern ids")->required();
    prm->callback([&ctx, p] { ctx.action = [&ctx, p] { removeEach(ctx, "patterns", p->ids); return kExitOk; }; });

    auto e = std::make_shared<ModelOptions>();
    CLI::App* env = app.add_subcommand("environment", "Environments for image-based light (render.environment): upload, list, rm");
    env->require_subcommand(1);
    CLI::App* eup = env->add_subcommand("upload", "Upload an equirectangular Radiance .hdr or OpenEXR of linear radiance; prints the id");
    eup->add_option("file", e->id, ".hdr or .exr file")->required()->check(CLI::ExistingFile);
    eup->add_option("--name", e->name, "Display name (default: the file's)");
    eup->callback([&ctx, e] {
        ctx.action = [&ctx, e] {
            const std::string name = e->name.empty() ? std::filesystem::path(e->id).stem().string() : e->name;
            printUpload(ctx, ctx.http().send("POST", "/environments?" + queryString({{"name", name}}),
                                             readFileOrThrow(e->id, "file"), "application/octet-stream", true));
            return kExitOk;
        };
    });
    CLI::App* elist = env->add_subcommand("list", "List environments (the built-in studio and uploads)");
    elist->callback([&ctx] {
        ctx.action = [&ctx] {
            auto j = ctx.http().getJson("/environments");
            if (ctx.global.json) {
                printJson(j);
                return kExitOk;
            }
            std::vector<std::vector<std::string>> rows;
            for (const auto& x : j["environments"])
                rows.push_back({cell(x["id"]), cell(x["name"]), x.value("builtin", false) ? "built-in" : "uploaded",
                                x.contains("width") ? cell(x["width"]) + "x" + cell(x["height"]) : "-"});
            printTable({"ID", "NAME", "SOURCE", "SIZE"}, rows);
            return kExitOk;
        };
    });
    CLI::App* erm = env->add_subcommand("rm", "Delete uploaded environments (refused while a scene names one)");
    erm->add_option("ids", e->ids, "Environment ids")->required();
    erm->callback([&ctx, e] { ctx.action = [&ctx, e] { removeEach(ctx, "environments", e->ids); return kExitOk; }; });
}

} // namespace dermis::cli
