// The checks file: validated member by member, errors naming a JSON pointer.
#include "check_cases.hpp"

#include "context.hpp"

#include <filesystem>
#include <regex>
#include <set>

namespace dermis::cli {

namespace {

double number(const nlohmann::json& j, const std::string& pointer, double lo, double hi) {
    if (!j.is_number() || j.get<double>() < lo || j.get<double>() > hi)
        throw usageError("must be a number in [" + nlohmann::json(lo).dump() + ", " + nlohmann::json(hi).dump() + "]", pointer);
    return j.get<double>();
}

} // namespace

std::vector<CheckCase> parseChecks(const std::string& path) {
    auto doc = nlohmann::json::parse(readFileOrThrow(path, "cases"), nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) throw usageError(path + " is not a JSON object", "cases");
    const std::filesystem::path base = std::filesystem::path(path).parent_path();
    double threshold = 0.1, fraction = 0.005;
    if (doc.contains("threshold")) threshold = number(doc["threshold"], "/threshold", 0, 1);
    if (doc.contains("fraction")) fraction = number(doc["fraction"], "/fraction", 0, 1);
    const nlohmann::json defaults = doc.value("defaults", nlohmann::json::object());
    if (!defaults.is_object()) throw usageError("must be an object", "/defaults");
    if (!doc.contains("cases") || !doc["cases"].is_array() || doc["cases"].empty())
        throw usageError("must be a non-empty array of cases", "/cases");
    static const std::regex namePattern("^[A-Za-z0-9_.-]{1,100}$");
    std::set<std::string> names;
    std::vector<CheckCase> out;
    for (std::size_t i = 0; i < doc["cases"].size(); ++i) {
        const std::string at = "/cases/" + std::to_string(i);
        if (!doc["cases"][i].is_object()) throw usageError("must be an object", at);
        nlohmann::json c = defaults;
        c.update(doc["cases"][i]);
        CheckCase k;
        k.threshold = threshold;
        k.fraction = fraction;
        k.name = c.value("name", "");
        if (!std::regex_match(k.name, namePattern)) throw usageError("a name of [A-Za-z0-9_.-] is required", at + "/name");
        if (!names.insert(k.name).second) throw usageError("\"" + k.name + "\" is used twice", at + "/name");
        const nlohmann::json scene = c.value("scene", nlohmann::json());
        if (scene.is_object()) {
            k.sceneDoc = scene;
        } else if (scene.is_string() && std::regex_match(scene.get<std::string>(), std::regex("^s_[0-9a-f]{16}$"))) {
            k.sceneId = scene;
        } else if (scene.is_string() && !scene.get<std::string>().empty()) {
            const std::filesystem::path p(scene.get<std::string>());
            k.sceneFile = (p.is_absolute() ? p : base / p).string();
        } else {
            throw usageError("a scene document file, a scene id or an inline document is required", at + "/scene");
        }
        if (c.contains("size")) {
            const auto& s = c["size"];
            if (!s.is_array() || s.size() != 2 || !s[0].is_number_integer() || !s[1].is_number_integer() || s[0].get<int>() < 1 ||
                s[1].get<int>() < 1)
                throw usageError("must be [width, height]", at + "/size");
            k.size = s;
        }
        if (c.contains("camera")) {
            if (!c["camera"].is_object()) throw usageError("must be an object {yaw, pitch, distance}", at + "/camera");
            k.camera = c["camera"];
        }
        if (c.contains("view")) {
            if (!c["view"].is_string()) throw usageError("must be shaded, bump, displacement, normal, basecolor or lighting", at + "/view");
            k.view = c["view"];
        }
        if (c.contains("threshold")) k.threshold = number(c["threshold"], at + "/threshold", 0, 1);
        if (c.contains("fraction")) k.fraction = number(c["fraction"], at + "/fraction", 0, 1);
        const nlohmann::json pose = c.value("pose", nlohmann::json());
        if (!pose.is_null() && !pose.is_object()) throw usageError("must be a pose object", at + "/pose");
        if (c.contains("times")) {
            if (!c["times"].is_array() || c["times"].empty()) throw usageError("must be a non-empty array of seconds", at + "/times");
            for (std::size_t t = 0; t < c["times"].size(); ++t) {
                const double time = number(c["times"][t], at + "/times/" + std::to_string(t), 0, 86400);
                nlohmann::json frame = {{"time", time}};
                if (pose.is_object()) {
                    frame = {{"pose", pose}};
                    frame["pose"]["time"] = time;
                }
                k.frames.push_back({k.name + "_" + std::to_string(t) + ".png", frame});
            }
        } else {
            nlohmann::json frame = nlohmann::json::object();
            if (pose.is_object()) frame["pose"] = pose;
            if (c.contains("time")) frame["time"] = number(c["time"], at + "/time", 0, 86400);
            if (frame.empty()) frame["time"] = nullptr; // the scene's own pose: filled in when rendering
            k.frames.push_back({k.name + ".png", frame});
        }
        out.push_back(std::move(k));
    }
    return out;
}

} // namespace dermis::cli
