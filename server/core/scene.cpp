// Dermis core — serialisation of the scene document `dermis.scene/1` (SPEC §2b): toJson(Scene)
// writes every field explicitly ("auto" where optional values are absent), so that parse →
// serialise → parse → serialise is byte-stable; and the names of Projection.
// Parsing is in scene_parse.cpp, the pattern manifest in scene_manifest.cpp, the shared JSON
// reader and predicates in scene_json.hpp.
#include "scene.hpp"

#include "scene_json.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <string_view>
#include <utility>

namespace dermis {

using namespace scene_detail;

std::string_view toString(Projection p) { return p == Projection::Surface ? "surface" : "uv"; }

double Placement::depthOrDefault() const {
    return depth ? *depth : std::max(size[0], size[1]) / 2.0;
}

std::optional<Projection> projectionFromString(std::string_view s) {
    if (s == "uv") return Projection::Uv;
    if (s == "surface") return Projection::Surface;
    return std::nullopt;
}

json toJson(const Scene& scene) {
    json doc = json::object();
    doc["format"] = kSceneFormat;
    doc["model"] = scene.model;
    doc["uv_layout"] = std::string(toString(scene.uvLayout));

    json heightmap = json::object();
    heightmap["size"] = json::array({scene.heightmapSize[0], scene.heightmapSize[1]});
    if (scene.heightmapBase) heightmap["base"] = *scene.heightmapBase;
    doc["heightmap"] = std::move(heightmap);

    json patterns = json::object();
    for (const auto& [id, path] : scene.patterns)
        patterns[id] = path;
    doc["patterns"] = std::move(patterns);

    json placements = json::array();
    for (const Placement& p : scene.placements) {
        json e = json::object();
        e["id"] = p.id;
        e["pattern"] = p.pattern;
        e["center"] = json::array({p.center[0], p.center[1]});
        e["scale"] = json::array({p.scale[0], p.scale[1]});
        e["rotation"] = p.rotation;
        e["joint"] = p.joint;
        if (p.axisName.empty())
            e["axis"] = json::array({p.axis[0], p.axis[1], p.axis[2]});
        else
            e["axis"] = p.axisName;
        e["theta_min"] = p.thetaMin;
        e["theta_max"] = p.thetaMax;
        e["h"] = p.h;
        e["model"] = std::string(toString(p.model));
        e["target"] = std::string(toString(p.target));
        e["response"] = std::string(toString(p.response));
        e["enabled"] = p.enabled;
        e["label"] = p.label;
        // SPEC §8: projection on every placement; the surface members only where they are used.
        e["projection"] = std::string(toString(p.projection));
        if (p.projection == Projection::Surface) {
            const SurfaceAnchor& a = p.anchor;
            e["anchor"] = json{
                {"position", json::array({a.position[0], a.position[1], a.position[2]})},
                {"normal", json::array({a.normal[0], a.normal[1], a.normal[2]})},
                {"tangent", json::array({a.tangent[0], a.tangent[1], a.tangent[2]})}};
            e["size"] = json::array({p.size[0], p.size[1]});
            e["depth"] = p.depth ? json(*p.depth) : json("auto");
        }
        placements.push_back(std::move(e));
    }
    doc["placements"] = std::move(placements);

    json pose = json::object();
    if (scene.pose.animation) pose["animation"] = *scene.pose.animation;
    pose["time"] = scene.pose.time;
    json joints = json::object();
    for (const auto& [name, jp] : scene.pose.joints) {
        json j = json::object();
        if (jp.rotation) {
            const auto& q = *jp.rotation;
            j["rotation"] = json::array({q[0], q[1], q[2], q[3]});
        } else {
            const auto a = jp.axisAngles.value_or(std::array<double, 3>{0, 0, 0});
            j["axis_angles"] = json{{"x", a[0]}, {"y", a[1]}, {"z", a[2]}};
        }
        joints[name] = std::move(j);
    }
    pose["joints"] = std::move(joints);
    if (!scene.pose.morphs.empty()) pose["morphs"] = scene.pose.morphs; // written only when set
    doc["pose"] = std::move(pose);

    const RenderSettings& r = scene.render;
    json render = json::object();
    render["size"] = json::array({r.size[0], r.size[1]});
    json camera = json::object();
    camera["yaw"] = r.camera.yaw;
    camera["pitch"] = r.camera.pitch;
    camera["distance"] = r.camera.distance ? json(*r.camera.distance) : json("auto");
    render["camera"] = std::move(camera);
    render["displacement_scale"] = r.displacementScale ? json(*r.displacementScale) : json("auto");
    render["bump_strength"] = r.bumpStrength;
    render["msaa"] = r.msaa;
    render["aa"] = std::string(toString(r.aa));
    render["displacement"] = std::string(toString(r.displacement));
    // The shading members are written when they differ from their defaults, so that documents
    // from before them keep their exact text (history, hashes).
    const RenderSettings defaults;
    if (r.shading != defaults.shading) render["shading"] = std::string(toString(r.shading));
    if (r.exposure != defaults.exposure) render["exposure"] = r.exposure;
    if (r.toneMapping != defaults.toneMapping)
        render["tone_mapping"] = std::string(toString(r.toneMapping));
    if (r.environmentRotation != defaults.environmentRotation)
        render["environment_rotation"] = r.environmentRotation;
    if (!r.environment.empty()) render["environment"] = r.environment;
    if (r.keyLight) {
        const KeyLight& k = *r.keyLight;
        render["key_light"] = json{{"direction", k.direction}, {"intensity", k.intensity},
                                   {"color", k.color}, {"shadow", k.shadow}};
    }
    doc["render"] = std::move(render);
    return doc;
}

} // namespace dermis
