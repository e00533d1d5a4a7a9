// Another character's placements onto this one. See transfer.hpp.
#include "transfer.hpp"

#include "motion.hpp"
#include "pick.hpp"
#include "surface_query.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace dermis {

namespace {

/// Joints of `role` and `side` in depth order (root first).
std::vector<int> runOf(const TransferModel& m, JointRole role, char side) {
    std::vector<std::pair<int, int>> byDepth;
    for (int j : m.model.joints) {
        const JointInfo* i = m.body.info(j);
        if (!i || i->role != role || i->side != side || !i->deforms) continue;
        int depth = 0;
        for (int p = m.model.parentJoint(j); p >= 0; p = m.model.parentJoint(p)) ++depth;
        byDepth.push_back({depth, j});
    }
    std::sort(byDepth.begin(), byDepth.end());
    std::vector<int> out;
    for (auto [d, j] : byDepth) out.push_back(j);
    return out;
}

/// The body's frame around a bone direction d (unit): e1 the forward direction (+z) made ⟂ d
/// (up, +y, where d is along z), e2 = d × e1.
void boneFrame(glm::dvec3 d, glm::dvec3& e1, glm::dvec3& e2) {
    glm::dvec3 f(0, 0, 1);
    if (std::abs(glm::dot(f, d)) > 0.95) f = {0, 1, 0};
    e1 = glm::normalize(f - glm::dot(f, d) * d);
    e2 = glm::cross(d, e1);
}

struct Segment {
    glm::dvec3 a{0.0}, d{0, 1, 0}; ///< start, unit direction
    double length = 0.0;
    glm::dvec3 e1{0.0}, e2{0.0};
    bool valid = false;
};

Segment segment(const RestSkin& rest, int from, int to) {
    Segment s;
    if (from < 0 || to < 0) return s;
    s.a = restJointPosition(rest, from);
    const glm::dvec3 v = restJointPosition(rest, to) - s.a;
    s.length = glm::length(v);
    if (!(s.length > 1e-9)) return s;
    s.d = v / s.length;
    boneFrame(s.d, s.e1, s.e2);
    s.valid = true;
    return s;
}

/// The segments into (parent → j) and out of (j → child) joint j.
std::pair<Segment, Segment> segmentsOf(const TransferModel& m, int j) {
    return {segment(m.rest, boneParent(m.model, m.body, j), j), segment(m.rest, j, boneChild(m.model, m.body, j))};
}

double distanceToSegment(const Segment& s, glm::dvec3 x) {
    const double t = std::clamp(glm::dot(x - s.a, s.d), 0.0, s.length);
    return glm::length(x - (s.a + t * s.d));
}

/// Components of v in the segment's frame (d, e1, e2) and back.
glm::dvec3 toFrame(const Segment& s, glm::dvec3 v) { return {glm::dot(v, s.d), glm::dot(v, s.e1), glm::dot(v, s.e2)}; }
glm::dvec3 fromFrame(const Segment& s, glm::dvec3 c) { return c.x * s.d + c.y * s.e1 + c.z * s.e2; }

} // namespace

std::string matchJoint(const TransferModel& from, const TransferModel& to, const std::string& joint,
                       const std::map<std::string, std::string>& explicitMap) {
    if (auto it = explicitMap.find(joint); it != explicitMap.end() && to.model.findJoint(it->second) >= 0)
        return it->second;
    if (to.model.findJoint(joint) >= 0) return joint;
    const int j = from.model.findJoint(joint);
    const JointInfo* info = from.body.info(j);
    if (!info || info->role == JointRole::Other || info->role == JointRole::Twist) return "";
    const std::vector<int> src = runOf(from, info->role, info->side);
    const std::vector<int> dst = runOf(to, info->role, info->side);
    if (dst.empty()) return "";
    const auto at = std::find(src.begin(), src.end(), j);
    const double fraction = src.size() > 1 && at != src.end()
                                ? static_cast<double>(at - src.begin()) / static_cast<double>(src.size() - 1)
                                : 0.5;
    std::size_t best = 0;
    for (std::size_t k = 0; k < dst.size(); ++k) {
        const double fk = dst.size() > 1 ? static_cast<double>(k) / static_cast<double>(dst.size() - 1) : 0.5;
        const double fb = dst.size() > 1 ? static_cast<double>(best) / static_cast<double>(dst.size() - 1) : 0.5;
        if (std::abs(fk - fraction) < std::abs(fb - fraction)) best = k;
    }
    return to.model.nodes[static_cast<std::size_t>(dst[best])].name;
}

Result<Placement> surfaceFromUv(const Placement& p, const Model& m, const UvLookup* lookup, const Model& uvModel) {
    const char* where = "dermis::surfaceFromUv";
    if (p.projection == Projection::Surface) return p;
    if (!lookup) return makeError(ErrorCode::Unsupported, where, "/uvs", "the model has no UVs");
    const auto hit = pickUv(uvModel, *lookup, {p.center[0], p.center[1]});
    if (!hit || hit->part < 0 || static_cast<std::size_t>(hit->part) >= m.parts.size())
        return makeError(ErrorCode::NotFound, where, "center", "the footprint centre lies on no UV chart");
    const MeshPart& part = m.parts[static_cast<std::size_t>(hit->part)];
    SurfacePoint sp{static_cast<std::size_t>(hit->part), 3 * static_cast<std::size_t>(hit->triangle),
                    glm::dvec3(hit->bary)};
    const glm::dvec3 pos = bindPositionAt(m, sp), n = bindNormalAt(m, sp);
    // The triangle's UV → position map J: [P1 − P0, P2 − P0] = J · [U1 − U0, U2 − U0]. The
    // lookup's model may carry another layout's UVs than `m` (the same triangles).
    const MeshPart& uvPart = static_cast<std::size_t>(hit->part) < uvModel.parts.size() ? uvModel.parts[static_cast<std::size_t>(hit->part)] : part;
    glm::dvec3 P[3];
    glm::dvec2 U[3];
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = part.indices[sp.base + static_cast<std::size_t>(k)];
        P[k] = glm::dvec3(part.positions[v]);
        U[k] = v < uvPart.uvs.size() ? glm::dvec2(uvPart.uvs[v]) : glm::dvec2(0.0);
    }
    const glm::dmat2 du(U[1] - U[0], U[2] - U[0]);
    if (!(std::abs(glm::determinant(du)) > 1e-14))
        return makeError(ErrorCode::NotFound, where, "center", "the footprint centre's triangle has no UV area");
    const glm::dmat2 inv = glm::inverse(du);
    const glm::dvec3 e1 = P[1] - P[0], e2 = P[2] - P[0];
    const auto J = [&](glm::dvec2 uv) {
        const glm::dvec2 c = inv * uv;
        return c.x * e1 + c.y * e2;
    };
    const double r = glm::radians(p.rotation);
    const glm::dvec2 u(std::cos(r), std::sin(r)), v(-std::sin(r), std::cos(r));
    glm::dvec3 t = J(u);
    t -= glm::dot(t, n) * n;
    if (!(glm::length(t) > 1e-12)) return makeError(ErrorCode::NotFound, where, "center", "degenerate UV map at the centre");
    Placement out = p;
    out.projection = Projection::Surface;
    out.anchor.position = {pos.x, pos.y, pos.z};
    out.anchor.normal = {n.x, n.y, n.z};
    t = glm::normalize(t);
    out.anchor.tangent = {t.x, t.y, t.z};
    out.size = {std::clamp(p.scale[0] * glm::length(J(u)), 1e-4, kMaxSurfaceSize),
                std::clamp(p.scale[1] * glm::length(J(v)), 1e-4, kMaxSurfaceSize)};
    out.rotation = 0.0;
    return out;
}

TransferResult transferPlacements(const std::vector<Placement>& placements, const TransferModel& from,
                                  const TransferModel& to, const std::map<std::string, std::string>& explicitMap) {
    TransferResult out;
    const auto srcBind = bindPositions(from.model);
    const auto dstRest = restPositions(to.rest);
    for (const Placement& original : placements) {
        const std::string target = matchJoint(from, to, original.joint, explicitMap);
        if (target.empty()) {
            out.unmapped.push_back({original.id, "joint", "no joint of the character matches '" + original.joint + "'"});
            continue;
        }
        auto surface = surfaceFromUv(original, from.model, from.lookup, from.uvModel ? *from.uvModel : from.model);
        if (!surface) {
            out.unmapped.push_back({original.id, surface.error().field, surface.error().message});
            continue;
        }
        const Placement& p = *surface;
        const int sj = from.model.findJoint(p.joint), tj = to.model.findJoint(target);
        // The anchor in the source's rest world.
        const glm::dvec3 c(p.anchor.position[0], p.anchor.position[1], p.anchor.position[2]);
        const auto at = nearestSurfacePoint(from.model, srcBind, c);
        if (!at || sj < 0 || tj < 0) {
            out.unmapped.push_back({original.id, "anchor", "the source model has no surface at the anchor"});
            continue;
        }
        const glm::dmat4 toWorld = restSkinningAt(from.model, from.rest, *at);
        const glm::dmat3 lin(toWorld);
        const glm::dvec3 x = glm::dvec3(toWorld * glm::dvec4(c, 1.0));
        const glm::dvec3 tn(p.anchor.tangent[0], p.anchor.tangent[1], p.anchor.tangent[2]);
        const glm::dvec3 tw = lin * tn;
        // The nearer segment of the driver's bone, and the target's matching one.
        const auto [sin, sout] = segmentsOf(from, sj);
        const auto [tin, tout] = segmentsOf(to, tj);
        const bool useIn = sin.valid && tin.valid &&
                           (!sout.valid || !tout.valid || distanceToSegment(sin, x) <= distanceToSegment(sout, x));
        const Segment& s = useIn ? sin : sout;
        const Segment& t = useIn ? tin : tout;
        if (!s.valid || !t.valid) {
            out.unmapped.push_back({original.id, "joint", "joint '" + p.joint + "' or '" + target + "' has no bone to measure by"});
            continue;
        }
        const double along = glm::dot(x - s.a, s.d) / s.length;
        const glm::dvec3 radial = x - (s.a + along * s.length * s.d);
        // The angle around the bone from the surface normal there (⟂ the bone): the side of the
        // limb the anchor is on, also where a rig puts its joints near the skin (the default
        // character's clavicles), where the radial vector from the bone says little.
        const glm::dvec3 nw = glm::normalize(glm::transpose(glm::inverse(lin)) *
                                             glm::dvec3(p.anchor.normal[0], p.anchor.normal[1], p.anchor.normal[2]));
        glm::dvec3 side = nw - glm::dot(nw, s.d) * s.d;
        if (!(glm::length(side) > 0.2)) side = radial;
        const double phi = std::atan2(glm::dot(side, s.e2), glm::dot(side, s.e1));
        const double ratio = t.length / s.length;
        const glm::dvec3 q = t.a + along * t.length * t.d;
        // A limb's segment (both ends off the symmetry plane) turns with the limb (a T-pose arm
        // onto an A-pose one): the angle around the bone. A segment from the trunk (the chest to
        // a shoulder without a clavicle) runs through the body: the world direction of the
        // normal is kept instead.
        const auto sided = [&](int node) {
            const JointInfo* i = to.body.info(node);
            return i && i->side != 0;
        };
        const bool limb = useIn ? sided(boneParent(to.model, to.body, tj)) && sided(tj)
                                : sided(tj) && sided(boneChild(to.model, to.body, tj));
        const glm::dvec3 dir = limb ? std::cos(phi) * t.e1 + std::sin(phi) * t.e2 : nw;
        // The skin of the bone's joints first (not a prop, the beard or another limb in the way).
        std::vector<int> twists;
        std::set<int> near{tj};
        if (const int bp = boneParent(to.model, to.body, tj, &twists); bp >= 0) near.insert(bp);
        if (const int bc = boneChild(to.model, to.body, tj, &twists); bc >= 0) near.insert(bc);
        near.insert(twists.begin(), twists.end());
        const double reach = 4.0 * std::max(t.length, glm::length(radial) * ratio);
        std::optional<SurfacePoint> hitPoint;
        if (auto hit = castRay(to.model, dstRest, q, dir, reach, [&](std::size_t part, int tri) {
                return triangleWeighsOn(to.model.parts[part], 3 * static_cast<std::size_t>(tri), near);
            }))
            hitPoint = hit->point;
        else if (auto any = castRay(to.model, dstRest, q, dir, reach))
            hitPoint = any->point;
        else
            hitPoint = nearestSurfacePoint(to.model, dstRest, q + glm::length(radial) * ratio * dir);
        if (!hitPoint) {
            out.unmapped.push_back({original.id, "anchor", "the character has no surface there"});
            continue;
        }
        // Back to the target's bind space.
        const glm::dvec3 pos = bindPositionAt(to.model, *hitPoint), n = bindNormalAt(to.model, *hitPoint);
        const glm::dmat3 lin2(restSkinningAt(to.model, to.rest, *hitPoint));
        const glm::dvec3 twTarget = limb ? fromFrame(t, toFrame(s, tw)) : tw;
        glm::dvec3 tb = std::abs(glm::determinant(lin2)) > 1e-12 ? glm::inverse(lin2) * twTarget : twTarget;
        tb -= glm::dot(tb, n) * n;
        if (!(glm::length(tb) > 1e-9)) tb = std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1, 0, 0)) : glm::cross(n, glm::dvec3(0, 1, 0));
        tb = glm::normalize(tb);
        // The driver axis keeps its angles to the bone's frame (the out segment when it has one).
        const Segment& sa = sout.valid && tout.valid ? sout : s;
        const Segment& ta = sout.valid && tout.valid ? tout : t;
        const glm::dvec3 axisLocal(p.axis[0], p.axis[1], p.axis[2]);
        const glm::dvec3 axisWorld = glm::dquat(restWorldRotation(from.model, sj)) * axisLocal;
        glm::dvec3 axisT = glm::inverse(glm::dquat(restWorldRotation(to.model, tj))) * fromFrame(ta, toFrame(sa, axisWorld));
        axisT = glm::length(axisT) > 0.0 ? glm::normalize(axisT) : glm::dvec3(1, 0, 0);
        const auto r6 = [](double v) { return std::abs(v) < 1e-6 ? 0.0 : std::round(v * 1e6) / 1e6; };
        const auto r9 = [](double v) { return std::abs(v) < 1e-12 ? 0.0 : std::round(v * 1e9) / 1e9; };
        Placement moved = p;
        moved.joint = target;
        moved.axisName.clear();
        moved.axis = {r6(axisT.x), r6(axisT.y), r6(axisT.z)};
        for (int k = 0; k < 3; ++k)
            if (std::abs(std::abs(moved.axis[static_cast<std::size_t>(k)]) - 1.0) < 1e-4 && moved.axis[static_cast<std::size_t>(k)] > 0) {
                moved.axisName = std::string(1, static_cast<char>('x' + k));
                moved.axis = {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0};
            }
        moved.anchor.position = {r9(pos.x), r9(pos.y), r9(pos.z)};
        moved.anchor.normal = {n.x, n.y, n.z};
        moved.anchor.tangent = {tb.x, tb.y, tb.z};
        moved.size = {std::clamp(p.size[0] * ratio, 1e-4, kMaxSurfaceSize), std::clamp(p.size[1] * ratio, 1e-4, kMaxSurfaceSize)};
        if (p.depth) moved.depth = std::clamp(*p.depth * ratio, 1e-4, kMaxSurfaceSize);
        out.joints[original.joint] = target;
        out.mapped.push_back({original.id, std::move(moved)});
    }
    return out;
}

} // namespace dermis
