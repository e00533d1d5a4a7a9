// Content addresses of a scene file's model, patterns and environment, and the multipart batch
// that carries their bytes.
#include "content.hpp"

#include "context.hpp"
#include "common/sha256.hpp"

#include <filesystem>

namespace dermis::cli {

namespace {

namespace fs = std::filesystem;

/// A .gltf whose buffers and images are all data: URIs (or inside the file) is self-contained.
bool selfContainedGltf(const std::string& bytes) {
    const auto doc = nlohmann::json::parse(bytes, nullptr, false);
    if (!doc.is_object()) return true; // not JSON: the server reports what is wrong with it
    for (const char* list : {"buffers", "images"})
        if (auto it = doc.find(list); it != doc.end() && it->is_array())
            for (const auto& item : *it)
                if (item.is_object() && item.contains("uri") && item["uri"].is_string() &&
                    item["uri"].get<std::string>().rfind("data:", 0) != 0)
                    return false;
    return true;
}

} // namespace

ContentFiles addressContent(nlohmann::json& scene, const std::string& sceneFile) {
    ContentFiles out;
    if (!scene.is_object()) return out;
    const fs::path folder = fs::path(sceneFile).parent_path();
    std::map<std::string, std::string> addressOfPath; // each file read and hashed once
    const auto address = [&](nlohmann::json& member, const std::string& field) {
        if (!member.is_string()) return;
        const std::string value = member.get<std::string>();
        if (value.empty() || value.rfind("builtin:", 0) == 0 || value.rfind("sha256:", 0) == 0) return;
        const fs::path p = fs::path(value).is_absolute() ? fs::path(value) : folder / value;
        std::error_code ec;
        if (!fs::is_regular_file(p, ec)) return; // an id: the server resolves it
        const std::string path = p.lexically_normal().string();
        auto known = addressOfPath.find(path);
        if (known == addressOfPath.end()) {
            const std::string bytes = readFileOrThrow(path, "/scene" + field);
            if (field == "/model" && p.extension() == ".gltf" && !selfContainedGltf(bytes))
                throw usageError(path + " has buffers or images in files of their own: only a .glb or a "
                                        "self-contained .gltf can be sent by content (pack it as .glb, or "
                                        "upload it with `dermis model upload` and name its id)",
                                 "/scene" + field);
            known = addressOfPath.emplace(path, "sha256:" + toHex(sha256(std::string_view(bytes)))).first;
            out.paths[known->second] = path;
        }
        member = known->second;
    };
    if (auto m = scene.find("model"); m != scene.end()) address(*m, "/model");
    if (auto pm = scene.find("patterns"); pm != scene.end() && pm->is_object())
        for (auto it = pm->begin(); it != pm->end(); ++it) address(it.value(), "/patterns/" + it.key());
    if (auto hm = scene.find("heightmap"); hm != scene.end() && hm->is_object())
        if (auto base = hm->find("base"); base != hm->end()) address(*base, "/heightmap/base");
    if (auto r = scene.find("render"); r != scene.end() && r->is_object())
        if (auto env = r->find("environment"); env != r->end()) address(*env, "/render/environment");
    return out;
}

std::string contentBody(const nlohmann::json& request, const std::vector<std::string>& addresses,
                        const ContentFiles& files, const std::string& boundary) {
    std::string body = "--" + boundary +
                       "\r\nContent-Disposition: form-data; name=\"request\"\r\nContent-Type: application/json\r\n\r\n" +
                       request.dump() + "\r\n";
    for (const std::string& address : addresses) {
        auto it = files.paths.find(address);
        if (it == files.paths.end())
            throw CliError(kExitServerSaidNo,
                           "the server lacks content " + address + " and no file of this scene has it", address);
        std::string name = fs::path(it->second).filename().string();
        for (char& c : name)
            if (c == '"' || c == '\\' || c == '\r' || c == '\n') c = '_';
        body += "--" + boundary + "\r\nContent-Disposition: form-data; name=\"" + address + "\"; filename=\"" + name +
                "\"\r\nContent-Type: application/octet-stream\r\n\r\n" + readFileOrThrow(it->second, address) + "\r\n";
    }
    return body + "--" + boundary + "--\r\n";
}

} // namespace dermis::cli
