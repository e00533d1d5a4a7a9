// Pick and driver suggestion. See pick.hpp.
#include "pick.hpp"

#include "camera.hpp"
#include "texture_layout.hpp"
#include "uv_lookup.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace dermis {

namespace {

/// Möller–Trumbore in double: distance along the ray and barycentrics (u, v of corners 1, 2).
std::optional<glm::dvec3> intersect(const Ray& r, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const glm::dvec3 e1 = b - a, e2 = c - a;
    const glm::dvec3 p = glm::cross(r.direction, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-14) return std::nullopt;
    const double inv = 1.0 / det;
    const glm::dvec3 s = r.origin - a;
    const double u = glm::dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) return std::nullopt;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(r.direction, q) * inv;
    if (v < 0.0 || u + v > 1.0) return std::nullopt;
    const double t = glm::dot(e2, q) * inv;
    if (t <= 0.0) return std::nullopt;
    return glm::dvec3(t, u, v);
}

/// Skin weights at a hit, per node, largest four.
std::vector<std::pair<int, float>> weightsAt(const MeshPart& p, std::size_t base, glm::vec3 bary) {
    std::map<int, float> byNode;
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = p.indices[base + k];
        if (v >= p.joints.size() || v >= p.weights.size()) {
            if (!p.influences.empty()) byNode[p.influences[0].node] += bary[k];
            continue;
        }
        for (int c = 0; c < 4; ++c) {
            const std::size_t inf = p.joints[v][c];
            if (inf < p.influences.size() && p.weights[v][c] > 0.0f)
                byNode[p.influences[inf].node] += bary[k] * p.weights[v][c];
        }
    }
    std::vector<std::pair<int, float>> out(byNode.begin(), byNode.end());
    std::sort(out.begin(), out.end(), [](auto& a, auto& b) {
        return a.second > b.second || (a.second == b.second && a.first < b.first);
    });
    if (out.size() > 4) out.resize(4);
    return out;
}

} // namespace

static FrameCamera cameraOf(const FramePlan& plan, const Model& model, const std::vector<SkinnedPart>& posed) {
    const Bounds bounds = framingBounds(posed);
    const double disp = plan.render.displacementScale ? *plan.render.displacementScale
                                                      : autoDisplacementScale(model);
    return frameCamera(bounds.min, bounds.max, disp, plan.render.camera, plan.render.size[0],
                       plan.render.size[1]);
}

FrameCamera planCamera(const FramePlan& plan, const Model& model) {
    return cameraOf(plan, model, skin(model, plan.world, plan.pose.morphWeights));
}

std::optional<PickHit> pickUv(const Model& model, const UvLookup& lookup, glm::dvec2 uv) {
    const auto h = lookup.find(uv);
    if (!h) return std::nullopt;
    const MeshPart& part = model.parts[static_cast<std::size_t>(h->part)];
    PickHit hit;
    hit.part = h->part;
    hit.triangle = h->triangle;
    hit.bary = h->bary;
    hit.uv = glm::vec2(uv);
    hit.position = lookup.position(*h);
    hit.joints = weightsAt(part, 3 * static_cast<std::size_t>(h->triangle), h->bary);
    return hit;
}

Result<std::optional<PickHit>> pickFrame(const FramePlan& plan, const Model& model, double x, double y) {
    const char* where = "dermis::pickFrame";
    const int W = plan.render.size[0], H = plan.render.size[1];
    if (!std::isfinite(x) || x < 0.0 || x >= W)
        return makeError(ErrorCode::InvalidArgument, where, "x", "must be in [0, " + std::to_string(W) + ")");
    if (!std::isfinite(y) || y < 0.0 || y >= H)
        return makeError(ErrorCode::InvalidArgument, where, "y", "must be in [0, " + std::to_string(H) + ")");
    const std::vector<SkinnedPart> posed = skin(model, plan.world, plan.pose.morphWeights);
    const FrameCamera cam = cameraOf(plan, model, posed);
    const Ray ray = pixelRay(cam, {x, y});
    std::optional<PickHit> best;
    for (std::size_t pi = 0; pi < posed.size() && pi < model.parts.size(); ++pi) {
        const MeshPart& part = model.parts[pi];
        const std::vector<glm::vec3>& pos = posed[pi].positions;
        for (std::size_t t = 0; t + 2 < part.indices.size(); t += 3) {
            const std::uint32_t i0 = part.indices[t], i1 = part.indices[t + 1], i2 = part.indices[t + 2];
            if (i0 >= pos.size() || i1 >= pos.size() || i2 >= pos.size()) continue;
            const auto h = intersect(ray, glm::dvec3(pos[i0]), glm::dvec3(pos[i1]), glm::dvec3(pos[i2]));
            if (!h || (best && h->x >= best->distance)) continue;
            PickHit hit;
            hit.part = static_cast<int>(pi);
            hit.triangle = static_cast<int>(t / 3);
            hit.distance = h->x;
            hit.bary = glm::vec3(static_cast<float>(1.0 - h->y - h->z), static_cast<float>(h->y),
                                 static_cast<float>(h->z));
            hit.position = glm::vec3(ray.origin + h->x * ray.direction);
            best = hit;
        }
    }
    if (best) {
        const MeshPart& part = model.parts[static_cast<std::size_t>(best->part)];
        const std::size_t base = 3 * static_cast<std::size_t>(best->triangle);
        if (!part.uvs.empty() && part.indices[base] < part.uvs.size() &&
            part.indices[base + 1] < part.uvs.size() && part.indices[base + 2] < part.uvs.size())
            for (int k = 0; k < 3; ++k) best->uv += best->bary[k] * part.uvs[part.indices[base + k]];
        best->joints = weightsAt(part, base, best->bary);
    }
    return best;
}

std::optional<glm::vec2> layoutUv(const TextureLayout& layout, const PickHit& hit) {
    if (hit.part < 0 || static_cast<std::size_t>(hit.part) >= layout.parts.size() || hit.triangle < 0)
        return std::nullopt;
    const PartLayout& pl = layout.parts[static_cast<std::size_t>(hit.part)];
    const std::size_t base = 3 * static_cast<std::size_t>(hit.triangle);
    if (base + 2 >= pl.indices.size()) return std::nullopt;
    glm::vec2 uv(0.0f);
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = pl.indices[base + static_cast<std::size_t>(k)];
        if (v >= pl.uvs.size()) return std::nullopt;
        uv += hit.bary[k] * pl.uvs[v];
    }
    return uv;
}

namespace {

/// Any unit vector ⟂ n: the world axis least aligned with n, projected.
glm::dvec3 perpendicular(glm::dvec3 n) {
    const glm::dvec3 a = std::abs(n.x) <= std::abs(n.y) && std::abs(n.x) <= std::abs(n.z) ? glm::dvec3(1, 0, 0)
                         : std::abs(n.y) <= std::abs(n.z)                                  ? glm::dvec3(0, 1, 0)
                                                                                            : glm::dvec3(0, 0, 1);
    return glm::normalize(a - glm::dot(a, n) * n);
}

glm::dvec3 originOf(const std::vector<glm::mat4>& world, int n) {
    return glm::dvec3(world[static_cast<std::size_t>(n)][3]);
}

} // namespace

PickAnchor pickAnchor(const Model& model, const PickHit& hit, int joint,
                      const std::vector<glm::mat4>& restWorld) {
    PickAnchor a;
    if (hit.part < 0 || static_cast<std::size_t>(hit.part) >= model.parts.size()) return a;
    const MeshPart& part = model.parts[static_cast<std::size_t>(hit.part)];
    const std::size_t base = 3 * static_cast<std::size_t>(hit.triangle);
    if (hit.triangle < 0 || base + 2 >= part.indices.size()) return a;
    std::uint32_t v[3];
    for (int k = 0; k < 3; ++k) {
        v[k] = part.indices[base + static_cast<std::size_t>(k)];
        if (v[k] >= part.positions.size()) return a;
    }
    const glm::dvec3 p0(part.positions[v[0]]), p1(part.positions[v[1]]), p2(part.positions[v[2]]);
    a.position = static_cast<double>(hit.bary[0]) * p0 + static_cast<double>(hit.bary[1]) * p1 +
                 static_cast<double>(hit.bary[2]) * p2;
    glm::dvec3 n(0.0);
    if (part.normals.size() == part.positions.size())
        for (int k = 0; k < 3; ++k) n += static_cast<double>(hit.bary[k]) * glm::dvec3(part.normals[v[k]]);
    if (!(glm::length(n) > 1e-12)) n = glm::cross(p1 - p0, p2 - p0);
    a.normal = glm::length(n) > 0.0 ? glm::normalize(n) : glm::dvec3(0, 0, 1);
    a.tangent = perpendicular(a.normal);
    const auto valid = [&](int node) { return node >= 0 && static_cast<std::size_t>(node) < restWorld.size(); };
    if (!valid(joint)) return a;
    // The bone in rest world space.
    glm::dvec3 sum(0.0);
    int children = 0;
    for (int j : model.joints)
        if (valid(j) && model.parentJoint(j) == joint) {
            sum += originOf(restWorld, j);
            ++children;
        }
    glm::dvec3 bone(0.0);
    if (children > 0) {
        bone = sum / static_cast<double>(children) - originOf(restWorld, joint);
    } else if (const int parent = model.parentJoint(joint); valid(parent)) {
        bone = originOf(restWorld, joint) - originOf(restWorld, parent);
    }
    // Into bind space through the most weighted influence at the hit (its rest skinning).
    glm::dmat3 toWorld(1.0);
    const int node = hit.joints.empty() ? -1 : hit.joints.front().first;
    for (const Influence& inf : part.influences)
        if (inf.node == node && valid(node)) {
            toWorld = glm::dmat3(glm::dmat4(restWorld[static_cast<std::size_t>(node)]) * glm::dmat4(inf.inverseBind));
            break;
        }
    const double det = glm::determinant(toWorld);
    if (std::abs(det) > 1e-12 && std::isfinite(det)) bone = glm::inverse(toWorld) * bone;
    const glm::dvec3 across = glm::cross(a.normal, bone);
    if (glm::length(across) > 1e-9 * std::max(1.0, glm::length(bone))) a.tangent = glm::normalize(across);
    return a;
}

SuggestedDriver suggestDriver(const Model& model, const std::vector<std::pair<int, float>>& joints) {
    SuggestedDriver out;
    if (joints.empty()) {
        out.joint.clear();
        return out;
    }
    out.joint = model.nodes[static_cast<std::size_t>(joints.front().first)].name;
    if (model.clips.empty()) return out;
    const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    // Angle ranges of each candidate over every clip at 15 fps.
    std::vector<std::array<AngleRange, 3>> ranges(joints.size());
    for (const Clip& clip : model.clips) {
        const int steps = static_cast<int>(std::floor(clip.duration * 15.0)) + 1;
        const int c = model.findClip(clip.name);
        for (int k = 0; k <= steps; ++k) {
            const LocalPose pose = sampleClip(model, c, std::min(clip.duration, static_cast<float>(k) / 15.0f));
            for (std::size_t j = 0; j < joints.size(); ++j) {
                const int n = joints[j].first;
                for (int a = 0; a < 3; ++a) {
                    const double th = jointAngle(model.nodes[static_cast<std::size_t>(n)].rotation,
                                                 pose.rotation[static_cast<std::size_t>(n)], axes[a]);
                    ranges[j][static_cast<std::size_t>(a)].lo = std::min(ranges[j][static_cast<std::size_t>(a)].lo, th);
                    ranges[j][static_cast<std::size_t>(a)].hi = std::max(ranges[j][static_cast<std::size_t>(a)].hi, th);
                }
            }
        }
    }
    return chooseDriver(model, joints, ranges);
}

SuggestedDriver chooseDriver(const Model& model, const std::vector<std::pair<int, float>>& joints,
                             const std::vector<std::array<AngleRange, 3>>& ranges) {
    static const char* kAxes[3] = {"x", "y", "z"};
    SuggestedDriver out;
    out.joint = model.nodes[static_cast<std::size_t>(joints.front().first)].name;
    double bestScore = -1.0;
    for (std::size_t j = 0; j < joints.size(); ++j)
        for (std::size_t a = 0; a < 3; ++a) {
            const AngleRange& r = ranges[j][a];
            const double score = joints[j].second * (r.hi - r.lo);
            if (r.hi < r.lo || score <= bestScore) continue;
            bestScore = score;
            out.joint = model.nodes[static_cast<std::size_t>(joints[j].first)].name;
            out.axis = kAxes[a];
            const double nearRest = (r.lo <= 0.0 && r.hi >= 0.0) ? 0.0 : (std::abs(r.lo) < std::abs(r.hi) ? r.lo : r.hi);
            const double far = std::abs(r.hi - nearRest) >= std::abs(r.lo - nearRest) ? r.hi : r.lo;
            out.thetaMin = std::round(nearRest * 2.0) / 2.0;
            out.thetaMax = std::round(far * 2.0) / 2.0;
        }
    if (out.thetaMin == out.thetaMax) { // a joint that never moves: a default range
        out.thetaMin = 0.0;
        out.thetaMax = 90.0;
    }
    return out;
}

} // namespace dermis
