// Mirror twins of placements. See mirror.hpp.
#include "mirror.hpp"

#include "camera.hpp"
#include "surface_query.hpp"

#include <glm/gtc/matrix_access.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace dermis {

namespace {

/// The largest footprint side a scene accepts (scene_parse.cpp's limit).
constexpr double kMaxPlacementScaleForMirror = 16.0;

glm::vec3 reflect(glm::vec3 p, const SymmetryPlane& s) {
    p[s.axis] = 2.0f * s.offset - p[s.axis];
    return p;
}

/// UV of the rest-mesh point nearest to world point q (parts with UVs only).
std::optional<glm::dvec2> nearestUv(const Model& m, const std::vector<SkinnedPart>& rest, glm::vec3 q) {
    double best = std::numeric_limits<double>::max();
    std::optional<glm::dvec2> uv;
    for (std::size_t pi = 0; pi < m.parts.size() && pi < rest.size(); ++pi) {
        const MeshPart& p = m.parts[pi];
        if (p.uvs.empty()) continue;
        const auto& pos = rest[pi].positions;
        for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
            const std::uint32_t i[3] = {p.indices[t], p.indices[t + 1], p.indices[t + 2]};
            if (i[0] >= pos.size() || i[1] >= pos.size() || i[2] >= pos.size() ||
                i[0] >= p.uvs.size() || i[1] >= p.uvs.size() || i[2] >= p.uvs.size())
                continue;
            const glm::dvec3 b = closestBary(glm::dvec3(q), glm::dvec3(pos[i[0]]), glm::dvec3(pos[i[1]]),
                                             glm::dvec3(pos[i[2]]));
            const glm::dvec3 c = b.x * glm::dvec3(pos[i[0]]) + b.y * glm::dvec3(pos[i[1]]) + b.z * glm::dvec3(pos[i[2]]);
            const double d = glm::length(c - glm::dvec3(q));
            if (d < best) {
                best = d;
                uv = b.x * glm::dvec2(p.uvs[i[0]]) + b.y * glm::dvec2(p.uvs[i[1]]) + b.z * glm::dvec2(p.uvs[i[2]]);
            }
        }
    }
    return uv;
}

/// Rest-world position of the surface at a UV point.
std::optional<glm::vec3> surfaceAt(const Model& m, const std::vector<SkinnedPart>& rest,
                                   const UvLookup& lookup, glm::dvec2 uv) {
    const auto hit = lookup.find(uv);
    if (!hit || static_cast<std::size_t>(hit->part) >= rest.size()) return std::nullopt;
    const MeshPart& p = m.parts[static_cast<std::size_t>(hit->part)];
    const auto& pos = rest[static_cast<std::size_t>(hit->part)].positions;
    glm::vec3 out(0.0f);
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t i = p.indices[3 * static_cast<std::size_t>(hit->triangle) + static_cast<std::size_t>(k)];
        if (i >= pos.size()) return std::nullopt; // a RestSkin of another model
        out += hit->bary[k] * pos[i];
    }
    return out;
}

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

} // namespace

RestSkin restSkin(const Model& model) {
    RestSkin out;
    out.world = worldMatrices(model, restPose(model));
    out.parts = skin(model, out.world);
    out.bounds = framingBounds(out.parts);
    return out;
}

SymmetryPlane symmetryPlane(const Model& model) {
    return symmetryPlane(restSkin(model));
}

SymmetryPlane symmetryPlane(const RestSkin& restSkin) {
    const std::vector<SkinnedPart>& rest = restSkin.parts;
    std::vector<glm::vec3> all;
    for (const auto& p : rest) all.insert(all.end(), p.positions.begin(), p.positions.end());
    SymmetryPlane best;
    if (all.empty()) return best;
    const Bounds& b = restSkin.bounds;
    const glm::vec3 centre = 0.5f * (b.min + b.max);
    const std::size_t stride = std::max<std::size_t>(1, all.size() / 150);
    best.error = std::numeric_limits<float>::max();
    for (int axis = 0; axis < 3; ++axis) {
        SymmetryPlane s{axis, centre[axis], 0.0f};
        double sum = 0.0;
        std::size_t n = 0;
        for (std::size_t k = 0; k < all.size(); k += stride, ++n) {
            const glm::vec3 q = reflect(all[k], s);
            float d = std::numeric_limits<float>::max();
            for (const glm::vec3& v : all) d = std::min(d, glm::length(v - q));
            sum += d;
        }
        s.error = static_cast<float>(sum / static_cast<double>(std::max<std::size_t>(n, 1)));
        if (s.error < best.error) best = s;
    }
    return best;
}

std::string mirrorJointName(const Model& model, const std::string& joint) {
    static const std::pair<const char*, const char*> kSuffixes[] = {{"_l", "_r"}, {".l", ".r"}, {"left", "right"}};
    static const std::pair<const char*, const char*> kPrefixes[] = {{"l_", "r_"}, {"left", "right"}};
    const std::string lj = lower(joint);
    auto tryName = [&](const std::string& candidate) -> std::string {
        const std::string lc = lower(candidate);
        for (int n : model.joints)
            if (lower(model.nodes[static_cast<std::size_t>(n)].name) == lc && lc != lj)
                return model.nodes[static_cast<std::size_t>(n)].name;
        return "";
    };
    for (auto [a, b] : kSuffixes)
        for (auto [from, to] : {std::pair{a, b}, std::pair{b, a}}) {
            const std::size_t len = std::strlen(from);
            if (lj.size() > len && lj.compare(lj.size() - len, len, from) == 0)
                if (auto n = tryName(joint.substr(0, joint.size() - len) + to); !n.empty()) return n;
        }
    for (auto [a, b] : kPrefixes)
        for (auto [from, to] : {std::pair{a, b}, std::pair{b, a}}) {
            const std::size_t len = std::strlen(from);
            if (lj.size() > len && lj.compare(0, len, from) == 0)
                if (auto n = tryName(to + joint.substr(len)); !n.empty()) return n;
        }
    // Left/Right or _L_/_R_ anywhere in the name (mixamorig:LeftArm, leg_joint_L_1).
    for (auto [from, to] : {std::pair{"left", "right"}, std::pair{"right", "left"},
                            std::pair{"_l_", "_r_"}, std::pair{"_r_", "_l_"}})
        if (auto at = lj.find(from); at != std::string::npos)
            if (auto n = tryName(joint.substr(0, at) + to + joint.substr(at + std::strlen(from))); !n.empty())
                return n;
    return "";
}

namespace {

bool isUpper(char c) { return std::isupper(static_cast<unsigned char>(c)) != 0; }
bool isLower(char c) { return std::islower(static_cast<unsigned char>(c)) != 0; }
bool isLetter(char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; }

/// What may stand beside a one-letter side token ("elbow_l", "(L)", "leg_L_1"): not a letter or
/// digit, and none of the characters that join a letter to a word ("l'", "R&D").
bool separates(char c) {
    return std::strchr(" _.-()[]:/,", c) != nullptr && c != '\0';
}

struct SideToken {
    std::size_t at = 0, len = 0;
    bool left = false;
};

/// The side tokens of `s`, in order (see swapSides).
std::vector<SideToken> sideTokens(const std::string& s) {
    std::vector<SideToken> out;
    const std::string ls = lower(s);
    for (std::size_t i = 0; i < s.size();) {
        bool word = false;
        for (auto [w, left] : {std::pair{"left", true}, std::pair{"right", false}}) {
            const std::size_t n = std::strlen(w);
            if (ls.compare(i, n, w) != 0) continue;
            const char prev = i > 0 ? s[i - 1] : ' ', next = i + n < s.size() ? s[i + n] : ' ';
            bool allUpper = true;
            for (std::size_t k = i; k < i + n; ++k) allUpper = allUpper && isUpper(s[k]);
            const bool starts = !isLetter(prev) || (isUpper(s[i]) && isLower(prev));
            const bool ends = !isLetter(next) || (isUpper(next) && !allUpper);
            if (starts && ends) {
                out.push_back({i, n, left});
                i += n;
                word = true;
                break;
            }
        }
        if (word) continue;
        if ((ls[i] == 'l' || ls[i] == 'r') && (i == 0 || separates(s[i - 1])) &&
            (i + 1 == s.size() || separates(s[i + 1])))
            out.push_back({i, 1, ls[i] == 'l'});
        ++i;
    }
    return out;
}

/// `to` in the case of `from` (ALL CAPS, Capitalised or small).
std::string inCaseOf(const std::string& from, const char* to) {
    std::string out = to;
    bool allUpper = true;
    for (char c : from) allUpper = allUpper && isUpper(c);
    for (std::size_t k = 0; k < out.size(); ++k)
        if (allUpper || (k == 0 && isUpper(from[0])))
            out[k] = static_cast<char>(std::toupper(static_cast<unsigned char>(out[k])));
    return out;
}

/// At most `max` bytes of `s`, cut before a UTF-8 continuation byte never.
std::string cutUtf8(std::string s, std::size_t max) {
    if (s.size() <= max) return s;
    std::size_t n = max;
    while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
    s.resize(n);
    return s;
}

} // namespace

std::optional<std::string> swapSides(const std::string& s) {
    const std::vector<SideToken> tokens = sideTokens(s);
    if (tokens.empty()) return std::nullopt;
    std::string out;
    std::size_t from = 0;
    for (const SideToken& t : tokens) {
        out += s.substr(from, t.at - from);
        const std::string token = s.substr(t.at, t.len);
        out += inCaseOf(token, t.len == 1 ? (t.left ? "r" : "l") : (t.left ? "right" : "left"));
        from = t.at + t.len;
    }
    return out + s.substr(from);
}

char sideOf(const std::string& name) {
    const std::vector<SideToken> tokens = sideTokens(name);
    return tokens.empty() ? 0 : tokens.front().left ? 'l' : 'r';
}

std::string mirrorPlacementId(const std::string& id, const std::string& twinJoint) {
    if (auto swapped = swapSides(id)) return *swapped;
    if (const char side = sideOf(twinJoint)) return id + "_" + side;
    return id + "_twin";
}

std::string mirrorLabel(const std::string& label) {
    if (label.empty()) return label;
    if (auto swapped = swapSides(label)) return cutUtf8(*swapped, kMaxLabelLength);
    const std::string suffix = " (mirror)";
    return cutUtf8(label, kMaxLabelLength - suffix.size()) + suffix;
}

int findMirrorTwin(const Scene& scene, const Placement& twin) {
    const double w = scene.heightmapSize[0], h = scene.heightmapSize[1];
    for (std::size_t k = 0; k < scene.placements.size(); ++k) {
        const Placement& q = scene.placements[k];
        if (q.joint != twin.joint || q.pattern != twin.pattern || q.target != twin.target ||
            q.projection != twin.projection)
            continue;
        if (twin.projection == Projection::Surface) {
            if (surfaceAnchorDistance(q, twin) <= kMirrorAnchorFraction * std::max(twin.size[0], twin.size[1]))
                return static_cast<int>(k);
            continue;
        }
        if (std::hypot((q.center[0] - twin.center[0]) * w, (q.center[1] - twin.center[1]) * h) <=
            kMirrorCenterTexels)
            return static_cast<int>(k);
    }
    return -1;
}

double surfaceAnchorDistance(const Placement& a, const Placement& b) {
    const auto& p = a.anchor.position;
    const auto& q = b.anchor.position;
    return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

namespace {

glm::dmat3 reflectionD(int axis) {
    glm::dmat3 r(1.0);
    r[axis][axis] = -1.0;
    return r;
}

/// Rest world rotation in double: the world matrices' rotation parts with scale removed
/// (Gram–Schmidt, so that a slightly skewed float matrix still gives a rotation).
glm::dquat restWorldRotationD(const std::vector<glm::mat4>& world, int n) {
    glm::dmat3 m{glm::dmat4(world[static_cast<std::size_t>(n)])};
    m[0] = glm::normalize(m[0]);
    m[1] = glm::normalize(m[1] - glm::dot(m[1], m[0]) * m[0]);
    m[2] = glm::cross(m[0], m[1]) * (glm::dot(glm::cross(m[0], m[1]), m[2]) < 0 ? -1.0 : 1.0);
    return glm::normalize(glm::quat_cast(m));
}

glm::dquat restWorldRotationD(const Model& model, int n) {
    return restWorldRotationD(worldMatrices(model, restPose(model)), n);
}

/// mirrorAxis from the rest world matrices.
glm::vec3 mirrorAxisOf(const std::vector<glm::mat4>& world, int j, int t, const glm::vec3& axis,
                       int planeAxis) {
    const glm::dvec3 w = restWorldRotationD(world, j) * glm::dvec3(axis);
    const glm::dvec3 mirrored = -(reflectionD(planeAxis) * w);
    return glm::vec3(glm::normalize(glm::inverse(restWorldRotationD(world, t)) * mirrored));
}

} // namespace

glm::quat restWorldRotation(const Model& model, int n) {
    return glm::quat(restWorldRotationD(model, n));
}

glm::quat mirrorDelta(const glm::quat& qj, const glm::quat& qt, const glm::quat& delta, int axis) {
    const glm::dmat3 r = reflectionD(axis);
    const glm::dquat dj(qj), dt(qt), dd(delta);
    const glm::dmat3 worldDelta = glm::mat3_cast(dj * dd * glm::inverse(dj));
    const glm::dmat3 mirrored = r * worldDelta * r;
    return glm::quat(glm::normalize(glm::inverse(dt) * glm::quat_cast(mirrored) * dt));
}

glm::vec3 mirrorAxis(const Model& model, int j, int t, const glm::vec3& axis, int planeAxis) {
    return mirrorAxisOf(worldMatrices(model, restPose(model)), j, t, axis, planeAxis);
}

Result<Placement> mirrorPlacement(const Placement& p, const Model& model, const UvLookup& lookup,
                                  const SymmetryPlane& plane) {
    if (!model.hasUVs() && p.projection == Projection::Uv)
        return mirrorPlacement(p, model, lookup, plane, RestSkin{});
    return mirrorPlacement(p, model, lookup, plane, restSkin(model));
}

Result<Placement> mirrorPlacement(const Placement& p, const Model& model, const UvLookup& lookup,
                                  const SymmetryPlane& plane, const RestSkin& restSkin) {
    const char* where = "dermis::mirrorPlacement";
    if (p.projection == Projection::Surface) return mirrorSurfacePlacement(p, model, plane, restSkin);
    if (!model.hasUVs()) return makeError(ErrorCode::Unsupported, where, "/uvs", "the model has no UVs");
    const std::vector<SkinnedPart>& rest = restSkin.parts;
    Footprint fp;
    fp.center = {p.center[0], p.center[1]};
    fp.scale = {p.scale[0], p.scale[1]};
    fp.rotationDeg = p.rotation;
    auto mapUv = [&](glm::dvec2 uv) -> std::optional<glm::dvec2> {
        const auto s = surfaceAt(model, rest, lookup, uv);
        if (!s) return std::nullopt;
        return nearestUv(model, rest, reflect(*s, plane));
    };
    const auto centre = mapUv(fp.center);
    if (!centre) return makeError(ErrorCode::NotFound, where, "center", "the footprint centre lies on no UV chart");
    Placement out = p;
    out.id.clear();
    out.label = mirrorLabel(p.label);
    out.center = {centre->x, centre->y};
    // The footprint's axes through the same map: steps of a fifth of the footprint.
    const glm::dvec2 su = fp.toUV({0.7, 0.5}), sv = fp.toUV({0.5, 0.7});
    const auto mu = mapUv(su), mv = mapUv(sv);
    if (mu && mv) {
        const glm::dvec2 du = *mu - *centre, dv = *mv - *centre;
        const double lu = glm::length(du), lv = glm::length(dv);
        const double ou = glm::length(su - fp.center), ov = glm::length(sv - fp.center);
        if (lu > 1e-9 && lv > 1e-9 && ou > 0 && ov > 0) {
            out.rotation = std::round(glm::degrees(std::atan2(du.y, du.x)) * 100.0) / 100.0;
            out.scale = {std::clamp(p.scale[0] * lu / ou, 1e-4, kMaxPlacementScaleForMirror),
                         std::clamp(p.scale[1] * lv / ov, 1e-4, kMaxPlacementScaleForMirror)};
        }
    }
    if (auto st = mirrorDriver(p, model, plane, restSkin, out); !st) return st.error();
    return out;
}

Status mirrorDriver(const Placement& p, const Model& model, const SymmetryPlane& plane,
                    const RestSkin& restSkin, Placement& out) {
    const char* where = "dermis::mirrorPlacement";
    // Joint: by name, else by reflected rest position.
    const std::vector<glm::mat4>& world = restSkin.world;
    const auto inWorld = [&](int n) { return n >= 0 && static_cast<std::size_t>(n) < world.size(); };
    int j = model.findJoint(p.joint);
    if (!inWorld(j)) j = -1; // a RestSkin of another model
    std::string twin = mirrorJointName(model, p.joint);
    if (j >= 0) {
        // The joint nearest the reflected rest position: the twin when the names give none, and
        // instead of the name twin when that lies elsewhere (CesiumMan's left elbow is
        // "arm_joint_L__3_", its right one "arm_joint_R__2_"; "R__3_" is the right wrist).
        const glm::vec3 at = reflect(glm::vec3(world[static_cast<std::size_t>(j)][3]), plane);
        const Bounds& b = restSkin.bounds;
        const float tolerance = 0.05f * glm::length(b.max - b.min);
        float best = tolerance;
        std::string nearest;
        for (int n : model.joints) {
            if (!inWorld(n)) continue;
            const float d = glm::length(glm::vec3(world[static_cast<std::size_t>(n)][3]) - at);
            if (d < best) {
                best = d;
                nearest = model.nodes[static_cast<std::size_t>(n)].name;
            }
        }
        const int named = twin.empty() ? -1 : model.findJoint(twin);
        const bool namedFar = named >= 0 && inWorld(named) &&
                              glm::length(glm::vec3(world[static_cast<std::size_t>(named)][3]) - at) > tolerance;
        if (twin.empty() || (namedFar && !nearest.empty())) twin = nearest;
    }
    if (twin.empty() || j < 0)
        return makeError(ErrorCode::NotFound, where, "joint",
                         "joint '" + p.joint + "' has no mirror twin by name or by position");
    out.joint = twin;
    const int t = model.findJoint(twin);
    if (!inWorld(t))
        return makeError(ErrorCode::NotFound, where, "joint",
                         "joint '" + twin + "' is not in the rest pose given");
    const glm::dvec3 in(p.axis[0], p.axis[1], p.axis[2]);
    if (!(glm::length(in) > 0.0)) return makeError(ErrorCode::InvalidArgument, where, "axis", "zero axis");
    const glm::vec3 a = mirrorAxisOf(world, j, t, glm::vec3(glm::normalize(in)), plane.axis);
    // Written rounded: no -1.777e-7 for a component that is 0 up to float noise.
    const auto rounded = [](double x) {
        return std::abs(x) < 1e-6 ? 0.0 : std::round(x * 1e6) / 1e6;
    };
    out.axis = {rounded(a.x), rounded(a.y), rounded(a.z)};
    out.axisName.clear();
    for (int k = 0; k < 3; ++k) // a named axis stays named when it maps onto one
        if (std::abs(std::abs(a[k]) - 1.0f) < 1e-4f && a[k] > 0) {
            out.axisName = std::string(1, static_cast<char>('x' + k));
            out.axis = {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0};
        }
    return Ok{};
}

} // namespace dermis

// --- surface placements (SPEC §8) -----------------------------------------------------------------

namespace dermis {

namespace {

glm::dvec3 reflectD(glm::dvec3 p, const SymmetryPlane& s) {
    p[s.axis] = 2.0 * s.offset - p[s.axis];
    return p;
}

glm::dvec3 reflectDir(glm::dvec3 d, int axis) {
    d[axis] = -d[axis];
    return d;
}

} // namespace

Result<Placement> mirrorSurfacePlacement(const Placement& p, const Model& model,
                                         const SymmetryPlane& plane, const RestSkin& rest) {
    const char* where = "dermis::mirrorPlacement";
    std::vector<const std::vector<glm::vec3>*> bind, world;
    for (std::size_t pi = 0; pi < model.parts.size(); ++pi) {
        bind.push_back(&model.parts[pi].positions);
        if (pi < rest.parts.size()) world.push_back(&rest.parts[pi].positions);
    }
    const glm::dvec3 c(p.anchor.position[0], p.anchor.position[1], p.anchor.position[2]);
    const glm::dvec3 n(p.anchor.normal[0], p.anchor.normal[1], p.anchor.normal[2]);
    const glm::dvec3 t(p.anchor.tangent[0], p.anchor.tangent[1], p.anchor.tangent[2]);
    const auto at = nearestSurfacePoint(model, bind, c);
    if (!at || world.size() != model.parts.size())
        return makeError(ErrorCode::InvalidArgument, where, "anchor", "the model has no surface to mirror the anchor on");
    // Into rest world space, through the skinning where the anchor sits.
    const glm::dmat4 toWorld = restSkinningAt(model, rest, *at);
    const glm::dmat3 lin(toWorld);
    const glm::dvec3 cw = glm::dvec3(toWorld * glm::dvec4(c, 1.0));
    const glm::dvec3 nw = glm::normalize(glm::transpose(glm::inverse(lin)) * n);
    // The pattern's effective axes (rotation applied), as the bake uses them (bake.cpp).
    const double rot = glm::radians(p.rotation);
    const glm::dvec3 te = std::cos(rot) * t + std::sin(rot) * glm::cross(n, t);
    glm::dvec3 tw = lin * te;
    tw = glm::normalize(tw - glm::dot(tw, nw) * nw);
    const glm::dvec3 bw = glm::cross(nw, tw);
    // Reflected, then onto the rest surface nearest to the reflected point.
    const glm::dvec3 target = reflectD(cw, plane);
    const auto twin = nearestSurfacePoint(model, world, target);
    if (!twin) return makeError(ErrorCode::InvalidArgument, where, "anchor", "the model has no surface to mirror the anchor on");
    const MeshPart& tp = model.parts[twin->part];
    glm::dvec3 c2(0.0);
    for (int k = 0; k < 3; ++k) c2 += twin->bary[k] * glm::dvec3(tp.positions[tp.indices[twin->base + static_cast<std::size_t>(k)]]);
    const glm::dvec3 n2w = reflectDir(nw, plane.axis);
    // Keep the axis that lies more within the plane as the mirror image has it; turn the other.
    glm::dvec3 t2w;
    if (std::abs(tw[plane.axis]) <= std::abs(bw[plane.axis])) {
        t2w = reflectDir(tw, plane.axis);                // u as mirrored; v = n × u turns
    } else {
        const glm::dvec3 b2w = reflectDir(bw, plane.axis); // v as mirrored; u turns
        t2w = glm::cross(b2w, n2w);                       // so that n × u = v
    }
    // Back to bind space through the skinning at the twin point.
    const glm::dmat4 toWorld2 = restSkinningAt(model, rest, *twin);
    const glm::dmat3 lin2(toWorld2), inv2 = glm::inverse(lin2);
    glm::dvec3 n2 = glm::normalize(glm::transpose(lin2) * n2w);
    glm::dvec3 te2 = inv2 * t2w;
    te2 = te2 - glm::dot(te2, n2) * n2;
    if (!(glm::length(te2) > 1e-12) || !std::isfinite(n2.x))
        return makeError(ErrorCode::InvalidArgument, where, "anchor", "the mirrored anchor frame is degenerate");
    te2 = glm::normalize(te2);
    // The same `rotation` on the twin: its tangent is the effective axis turned back by it.
    const glm::dvec3 t2 = glm::normalize(std::cos(rot) * te2 - std::sin(rot) * glm::cross(n2, te2));
    const auto rounded = [](double x) { return std::abs(x) < 1e-12 ? 0.0 : std::round(x * 1e9) / 1e9; };
    Placement out = p;
    out.id.clear();
    out.label = mirrorLabel(p.label);
    out.anchor.position = {rounded(c2.x), rounded(c2.y), rounded(c2.z)};
    out.anchor.normal = {n2.x, n2.y, n2.z};
    out.anchor.tangent = {t2.x, t2.y, t2.z};
    if (auto st = mirrorDriver(p, model, plane, rest, out); !st) return st.error();
    return out;
}

} // namespace dermis
