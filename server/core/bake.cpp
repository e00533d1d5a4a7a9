// Scene document + character → height maps (CPU reference path).
#include "bake.hpp"

#include "frame_plan.hpp"

#include <cmath>

namespace dermis {

int findPosable(const Model& model, const std::string& name) {
    if (int j = model.findJoint(name); j >= 0) return j;
    for (std::size_t n = 0; n < model.nodes.size(); ++n)
        if (model.nodes[n].name == name) return static_cast<int>(n);
    return -1;
}

Result<LocalPose> evaluatePose(const Model& model, const Pose& pose,
                               std::optional<double> timeOverride) {
    const char* where = "dermis::evaluatePose";
    LocalPose local;
    const double time = timeOverride.value_or(pose.time);
    if (!std::isfinite(time))
        return makeError(ErrorCode::InvalidArgument, where, "/pose/time", "must be finite");
    int clip = -1;
    if (pose.animation) {
        clip = model.findClip(*pose.animation);
        if (clip < 0)
            return makeError(ErrorCode::NotFound, where, "/pose/animation",
                             "the model has no clip named '" + *pose.animation + "'");
    } else if (!model.clips.empty()) {
        clip = 0;
    }
    local = clip >= 0 ? sampleClip(model, clip, static_cast<float>(time)) : restPose(model);

    for (const auto& [name, jp] : pose.joints) {
        const int n = findPosable(model, name);
        if (n < 0)
            return makeError(ErrorCode::NotFound, where, "/pose/joints/" + jsonPointerEscape(name),
                             "the model has no joint named '" + name + "'");
        if (jp.rotation) {
            const auto& q = *jp.rotation; // [x, y, z, w]
            local.rotation[n] = glm::normalize(glm::quat(static_cast<float>(q[3]),
                                                         static_cast<float>(q[0]),
                                                         static_cast<float>(q[1]),
                                                         static_cast<float>(q[2])));
        } else if (jp.axisAngles) {
            const auto& a = *jp.axisAngles;
            local.rotation[n] = axisAnglesRotation(model.nodes[n].rotation, a[0], a[1], a[2]);
        }
    }
    for (const auto& [name, w] : pose.morphs) {
        bool found = false;
        for (std::size_t k = 0; k < model.morphWeights.size() && k < local.morphWeights.size(); ++k)
            if (model.morphWeights[k].name == name) {
                local.morphWeights[k] = static_cast<float>(w);
                found = true;
            }
        if (!found)
            return makeError(ErrorCode::NotFound, where, "/pose/morphs/" + jsonPointerEscape(name),
                             "the model has no morph target named '" + name + "'");
    }
    return local;
}

Result<double> placementAngle(const Model& model, const LocalPose& pose, const Placement& p,
                              std::size_t index) {
    const int n = findPosable(model, p.joint);
    if (n < 0)
        return makeError(ErrorCode::NotFound, "dermis::placementAngle",
                         "/placements/" + std::to_string(index) + "/joint",
                         "the model has no joint named '" + p.joint + "'");
    const glm::vec3 axis = glm::normalize(glm::vec3(static_cast<float>(p.axis[0]),
                                                    static_cast<float>(p.axis[1]),
                                                    static_cast<float>(p.axis[2])));
    return jointAngle(model.nodes[n].rotation, pose.rotation[n], axis);
}

namespace {

/// Whether any part of `model` has TEXCOORD_0 for every vertex (modelTextureLayout not empty).
bool anyPartHasUVs(const Model& model) {
    for (const MeshPart& part : model.parts)
        if (!part.positions.empty() && part.uvs.size() >= part.positions.size() &&
            part.indices.size() >= 3)
            return true;
    return false;
}

} // namespace

bool surfaceFrameOf(const Placement& p, BakePlacement& b) {
    const glm::dvec3 n0(p.anchor.normal[0], p.anchor.normal[1], p.anchor.normal[2]);
    const glm::dvec3 t0(p.anchor.tangent[0], p.anchor.tangent[1], p.anchor.tangent[2]);
    const double nl = glm::length(n0);
    if (!(nl > 0.0) || !std::isfinite(nl)) return false;
    const glm::dvec3 n = n0 / nl;
    glm::dvec3 t = t0 - glm::dot(t0, n) * n;
    const double tl = glm::length(t);
    if (!(tl > 1e-9) || !std::isfinite(tl)) return false;
    t /= tl;
    const glm::dvec3 bt = glm::cross(n, t);
    const double a = glm::radians(p.rotation);
    b.surface = true;
    b.anchorPosition = glm::dvec3(p.anchor.position[0], p.anchor.position[1], p.anchor.position[2]);
    b.anchorNormal = n;
    b.anchorTangent = glm::normalize(std::cos(a) * t + std::sin(a) * bt);
    b.size = glm::dvec2(p.size[0], p.size[1]);
    b.depth = p.depthOrDefault();
    return b.size.x > 0.0 && b.size.y > 0.0 && b.depth > 0.0;
}

Result<std::vector<BakePlacement>> resolvePlacements(const Scene& scene, const Model& model,
                                                     const LocalPose& pose,
                                                     const PatternImages& images,
                                                     const TextureLayout* layout) {
    const char* where = "dermis::resolvePlacements";
    std::vector<BakePlacement> out;
    out.reserve(scene.placements.size());
    // UV placements live in the layout in use; without one given, the model's own UVs (every
    // part must have them, as before layouts existed).
    const bool uvs = layout ? !layout->empty() : model.hasUVs();
    const bool surfaceUvs = layout ? !layout->empty() : anyPartHasUVs(model);
    for (std::size_t i = 0; i < scene.placements.size(); ++i) {
        const Placement& p = scene.placements[i];
        const std::string ptr = "/placements/" + std::to_string(i);
        if (p.projection == Projection::Surface && !surfaceUvs)
            return makeError(ErrorCode::InvalidArgument, where, "/uv_layout",
                             "placement " + p.id + " is a surface placement, but the height-map "
                             "layout in use (" + (layout ? layout->kind : std::string("model")) +
                             ") has no UVs: the model has no TEXCOORD_0; use uv_layout "
                             "\"generated\"");
        if (p.projection == Projection::Uv && !uvs)
            return makeError(ErrorCode::InvalidArgument, where, ptr,
                             "the model has no TEXCOORD_0, so patterns cannot be placed in its "
                             "texture space (a surface placement can: projection \"surface\")");
        auto it = images.find(p.pattern);
        if (it == images.end())
            return makeError(ErrorCode::NotFound, where, ptr + "/pattern",
                             "no image loaded for pattern '" + p.pattern + "'");
        auto theta = placementAngle(model, pose, p, i);
        if (!theta) return theta.error();
        if (!p.enabled) continue; // checked like the others, contributes nothing
        BakePlacement b;
        if (!it->second)
            return makeError(ErrorCode::NotFound, where, ptr + "/pattern",
                             "no image loaded for pattern '" + p.pattern + "'");
        b.pattern = &it->second->pixels;
        b.patternId = it->second->contentId;
        b.footprint.center = {p.center[0], p.center[1]};
        b.footprint.scale = {p.scale[0], p.scale[1]};
        b.footprint.rotationDeg = p.rotation;
        if (p.projection == Projection::Surface && !surfaceFrameOf(p, b))
            return makeError(ErrorCode::InvalidArgument, where, ptr + "/anchor",
                             "needs a non-zero normal, a tangent not parallel to it, a size and a "
                             "depth > 0");
        b.model = p.model;
        b.target = p.target;
        b.response = p.response;
        b.h = p.h;
        b.t = normalizedT(*theta, p.thetaMin, p.thetaMax);
        b.source = static_cast<int>(i);
        out.push_back(b);
    }
    return out;
}

Result<HeightMaps> bakeScene(const Scene& scene, const Model& model, const PatternImages& images,
                             const SceneBakeOptions& options) {
    FrameOverrides overrides;
    overrides.time = options.time;
    overrides.layout = options.layout;
    auto plan = planFrame(scene, model, images, options.base, overrides);
    if (!plan) return plan.error();
    return bakeHeightMaps(plan->heights, options.threads);
}

} // namespace dermis
