// Scene documents on disk: path resolution and loading of everything a scene references.
#include "scene_files.hpp"

#include "gltf_loader.hpp"
#include "image_io.hpp"

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace dermis {
namespace fs = std::filesystem;

namespace {

Result<std::string> readText(const std::string& path, const char* where) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        return makeError(ErrorCode::NotFound, where, path, "no such file");
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    if (!in) return makeError(ErrorCode::Io, where, path, "cannot read");
    return ss.str();
}

std::string joinPath(const std::string& baseDir, const std::string& rel) {
    fs::path p(rel);
    if (p.is_absolute() || baseDir.empty()) return p.lexically_normal().string();
    return (fs::path(baseDir) / p).lexically_normal().string();
}

} // namespace

std::string dermisContentDir() {
    if (const char* env = std::getenv("DERMIS_CONTENT_DIR"); env && *env) return env;
    return DERMIS_SOURCE_DIR;
}

Result<PatternManifest> loadBuiltinManifest(const std::string& contentDir) {
    const char* where = "dermis::loadBuiltinManifest";
    const std::string path = contentDir + "/patterns/manifest.json";
    std::error_code ec;
    if (!fs::exists(path, ec)) return PatternManifest{};
    auto text = readText(path, where);
    if (!text) return text.error();
    auto doc = nlohmann::json::parse(*text, nullptr, false);
    if (doc.is_discarded())
        return makeError(ErrorCode::Parse, where, path, "malformed JSON");
    return parsePatternManifest(doc);
}

std::string resolveModelPath(const std::string& ref, const std::string& baseDir,
                             const std::string& contentDir) {
    static const std::string kBuiltin = "builtin:";
    if (ref.rfind(kBuiltin, 0) == 0)
        return contentDir + "/models/" + ref.substr(kBuiltin.size()) + ".glb";
    return joinPath(baseDir, ref);
}

Result<LoadedScene> loadSceneFile(const std::string& path, const std::string& contentDir) {
    const char* where = "dermis::loadSceneFile";
    auto manifest = loadBuiltinManifest(contentDir);
    if (!manifest) return manifest.error();
    auto text = readText(path, where);
    if (!text) return text.error();
    auto scene = parseSceneText(*text, *manifest);
    if (!scene) return scene.error();

    LoadedScene out;
    out.scene = std::move(*scene);
    out.baseDir = fs::path(path).parent_path().string();

    const std::string modelPath = resolveModelPath(out.scene.model, out.baseDir, contentDir);
    auto model = loadGltfFile(modelPath);
    if (!model) {
        Error e = model.error();
        e.message = std::string(where) + ": /model: '" + out.scene.model + "': " + e.message;
        e.field = "/model";
        return e;
    }
    out.model = std::move(*model);

    for (std::size_t i = 0; i < out.scene.placements.size(); ++i) {
        const std::string& id = out.scene.placements[i].pattern;
        if (out.images.count(id)) continue;
        std::string file;
        if (auto it = out.scene.patterns.find(id); it != out.scene.patterns.end()) {
            file = joinPath(out.baseDir, it->second);
        } else if (const PatternInfo* info = manifest->find(id)) {
            file = contentDir + "/patterns/" + info->file;
        } else {
            return makeError(ErrorCode::NotFound, where,
                             "/placements/" + std::to_string(i) + "/pattern",
                             "unknown pattern '" + id + "'");
        }
        auto img = readHeightImage(file);
        if (!img) {
            Error e = img.error();
            e.field = "/placements/" + std::to_string(i) + "/pattern";
            e.message = std::string(where) + ": " + e.field + ": " + e.message;
            return e;
        }
        out.images.emplace(id, makePatternImage(std::move(*img)));
    }
    if (out.scene.heightmapBase) {
        auto img = readHeightImage(joinPath(out.baseDir, *out.scene.heightmapBase));
        if (!img) {
            Error e = img.error();
            e.field = "/heightmap/base";
            e.message = std::string(where) + ": /heightmap/base: " + e.message;
            return e;
        }
        out.base = makePatternImage(std::move(*img));
    }
    return out;
}

} // namespace dermis
