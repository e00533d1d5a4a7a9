// A full pattern set for a character. See propose.hpp.
#include "propose.hpp"

#include "surface_query.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>

namespace dermis {

namespace {

struct Ctx {
    const Model& model;
    const RestSkin& rest;
    const SymmetryPlane& plane;
    const BodyMap& body;
    const MotionAnalysis& motion;
    std::vector<const std::vector<glm::vec3>*> restPos;
    std::vector<std::vector<glm::mat4>> sampleWorld; ///< world matrices per motion sample
};

struct Tri {
    std::size_t part, base;
};

glm::dvec3 skinVertex(const MeshPart& p, std::uint32_t v, const std::vector<glm::mat4>& world) {
    glm::dmat4 m(0.0);
    double total = 0.0;
    const bool weighted = v < p.joints.size() && v < p.weights.size();
    for (int k = 0; k < (weighted ? 4 : 1); ++k) {
        const std::size_t inf = weighted ? p.joints[v][k] : 0;
        const double w = weighted ? p.weights[v][k] : 1.0;
        if (!(w > 0.0) || inf >= p.influences.size()) continue;
        const int node = p.influences[inf].node;
        const glm::dmat4 wm = node >= 0 && static_cast<std::size_t>(node) < world.size()
                                  ? glm::dmat4(world[static_cast<std::size_t>(node)])
                                  : glm::dmat4(1.0);
        m += w * (wm * glm::dmat4(p.influences[inf].inverseBind));
        total += w;
    }
    if (!(total > 0.0)) m = glm::dmat4(1.0);
    return glm::dvec3(m * glm::dvec4(glm::dvec3(p.positions[v]), 1.0));
}

/// Triangles of `nodes` whose rest centroid is within `radius` of x and whose rest normal faces
/// `dir` (cosine > 0.2).
std::vector<Tri> regionNear(const Ctx& c, glm::dvec3 x, glm::dvec3 dir, double radius, const std::set<int>& nodes) {
    std::vector<Tri> out;
    for (std::size_t pi = 0; pi < c.model.parts.size() && pi < c.rest.parts.size(); ++pi) {
        const MeshPart& p = c.model.parts[pi];
        const auto& pos = c.rest.parts[pi].positions;
        for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
            const std::uint32_t i0 = p.indices[t], i1 = p.indices[t + 1], i2 = p.indices[t + 2];
            if (i0 >= pos.size() || i1 >= pos.size() || i2 >= pos.size()) continue;
            const glm::dvec3 a(pos[i0]), b(pos[i1]), cc(pos[i2]);
            if (glm::length((a + b + cc) / 3.0 - x) > radius) continue;
            const glm::dvec3 n = glm::cross(b - a, cc - a);
            if (!(glm::length(n) > 0.0) || glm::dot(glm::normalize(n), dir) < 0.2) continue;
            if (!triangleWeighsOn(p, t, nodes)) continue;
            out.push_back({pi, t});
        }
    }
    return out;
}

struct RegionStrain {
    double compression = 0.0, stretch = 0.0;
    glm::dvec3 compressionDirection{0.0};
};

/// Area-weighted mean strain of `tris` between the rest skin and `posed` vertex positions.
RegionStrain strainOf(const Ctx& c, const std::vector<Tri>& tris,
                      const std::vector<std::vector<glm::dvec3>>& posed) {
    RegionStrain out;
    double area = 0.0;
    glm::dmat3 tensor(0.0);
    for (const Tri& t : tris) {
        const MeshPart& p = c.model.parts[t.part];
        const auto& pos = c.rest.parts[t.part].positions;
        const std::uint32_t i[3] = {p.indices[t.base], p.indices[t.base + 1], p.indices[t.base + 2]};
        const glm::dvec3 a(pos[i[0]]), b(pos[i[1]]), cc(pos[i[2]]);
        const double ar = 0.5 * glm::length(glm::cross(b - a, cc - a));
        const TriangleStrain s = triangleStrain(a, b, cc, posed[t.part][i[0]], posed[t.part][i[1]], posed[t.part][i[2]]);
        const double comp = std::max(0.0, 1.0 - s.minStretch);
        out.compression += ar * comp;
        out.stretch += ar * std::max(0.0, s.maxStretch - 1.0);
        tensor += ar * comp * glm::outerProduct(s.minDirection, s.minDirection);
        area += ar;
    }
    if (area > 0.0) {
        out.compression /= area;
        out.stretch /= area;
        glm::dvec3 v = tensor[0];
        for (int k = 1; k < 3; ++k)
            if (glm::length(tensor[k]) > glm::length(v)) v = tensor[k];
        for (int it = 0; it < 50 && glm::length(v) > 0.0; ++it) v = glm::normalize(tensor * v);
        out.compressionDirection = v;
    }
    return out;
}

/// Posed positions under `world` of the vertices `tris` use, into `posed` (sized to the parts'
/// vertices on the first call; other vertices are left as they are): one buffer for every sample.
void skinTris(const Ctx& c, const std::vector<Tri>& tris, const std::vector<glm::mat4>& world,
              std::vector<std::vector<glm::dvec3>>& posed) {
    if (posed.size() != c.model.parts.size()) {
        posed.resize(c.model.parts.size());
        for (std::size_t pi = 0; pi < c.model.parts.size(); ++pi) posed[pi].assign(c.model.parts[pi].positions.size(), glm::dvec3(0.0));
    }
    for (const Tri& t : tris) {
        const MeshPart& p = c.model.parts[t.part];
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = p.indices[t.base + static_cast<std::size_t>(k)];
            if (v < p.positions.size()) posed[t.part][v] = skinVertex(p, v, world);
        }
    }
}

/// Pearson r of the region's mean compression (stretch) with θ of `node` about `axis` over the
/// motion's samples; 0 when either does not vary.
double correlationOf(const Ctx& c, const std::vector<Tri>& tris, int node, glm::dvec3 axis, bool stretch) {
    const std::size_t n = c.motion.samples.size();
    if (n < 3 || tris.empty()) return 0.0;
    std::vector<double> xs, ys;
    const glm::quat restQ = c.model.nodes[static_cast<std::size_t>(node)].rotation;
    std::vector<std::vector<glm::dvec3>> posed;
    for (std::size_t s = 0; s < n; ++s) {
        skinTris(c, tris, c.sampleWorld[s], posed);
        const RegionStrain rs = strainOf(c, tris, posed);
        xs.push_back(jointAngle(restQ, c.motion.rotations[s][static_cast<std::size_t>(node)], glm::vec3(axis)));
        ys.push_back(stretch ? rs.stretch : rs.compression);
    }
    double mx = 0, my = 0;
    for (std::size_t k = 0; k < n; ++k) {
        mx += xs[k];
        my += ys[k];
    }
    mx /= static_cast<double>(n);
    my /= static_cast<double>(n);
    double sxy = 0, sxx = 0, syy = 0;
    for (std::size_t k = 0; k < n; ++k) {
        sxy += (xs[k] - mx) * (ys[k] - my);
        sxx += (xs[k] - mx) * (xs[k] - mx);
        syy += (ys[k] - my) * (ys[k] - my);
    }
    return sxx > 1e-12 && syy > 1e-18 ? sxy / std::sqrt(sxx * syy) : 0.0;
}

double round6(double x) { return std::abs(x) < 1e-6 ? 0.0 : std::round(x * 1e6) / 1e6; }
double roundHalf(double x) { return std::round(x * 2.0) / 2.0; }
double roundSize(double x) { return std::max(1e-4, std::round(x * 1e5) / 1e5); }

/// Bind-space anchor of a rest-world surface hit with rest-world tangent `u`.
SurfaceAnchor anchorAt(const Ctx& c, const SurfacePoint& sp, glm::dvec3 u) {
    SurfaceAnchor a;
    const glm::dvec3 p = bindPositionAt(c.model, sp), n = bindNormalAt(c.model, sp);
    const glm::dmat3 lin(restSkinningAt(c.model, c.rest, sp));
    glm::dvec3 t = std::abs(glm::determinant(lin)) > 1e-12 ? glm::inverse(lin) * u : u;
    t -= glm::dot(t, n) * n;
    if (!(glm::length(t) > 1e-9)) t = std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1, 0, 0)) : glm::cross(n, glm::dvec3(0, 1, 0));
    t = glm::normalize(t);
    const auto r9 = [](double x) { return std::abs(x) < 1e-12 ? 0.0 : std::round(x * 1e9) / 1e9; };
    a.position = {r9(p.x), r9(p.y), r9(p.z)};
    a.normal = {n.x, n.y, n.z};
    a.tangent = {t.x, t.y, t.z};
    return a;
}

std::string sideSuffix(char side) { return side == 'l' ? "_l" : side == 'r' ? "_r" : ""; }
std::string sideWord(char side) { return side == 'l' ? "left " : side == 'r' ? "right " : ""; }

struct Site {
    const char* kind;     ///< crease | bone | bulge
    const char* pattern;
    const char* idBase;   ///< elbow_crease
    const char* label;    ///< elbow crease
    DeformModel model;
    Target target;
    double along = 0.5;   ///< bulge: where on the parent bone, from the parent joint (0..1)
};

/// The proposals for bending joint `j` with motion `jm` (see the header's table).
void proposeAt(const Ctx& c, int j, const JointMotion& jm, const std::vector<Site>& sites,
               std::vector<Proposal>& out) {
    const JointInfo* info = c.body.info(j);
    if (!info) return;
    std::vector<int> twists;
    const int parent = boneParent(c.model, c.body, j, &twists);
    const int child = boneChild(c.model, c.body, j, &twists);
    std::set<int> nodes(twists.begin(), twists.end());
    nodes.insert(j);
    if (parent >= 0) nodes.insert(parent);
    if (child >= 0) nodes.insert(child);
    const glm::dvec3 P = restJointPosition(c.rest, j);
    const glm::dvec3 parentPos = parent >= 0 ? restJointPosition(c.rest, parent) : P - glm::dvec3(0, 0.1, 0);
    glm::dvec3 pb = P - parentPos;
    const double parentLength = glm::length(pb);
    if (!(parentLength > 0.0)) return;
    pb /= parentLength;
    // The bend at the peak: where the child moves, ⟂ the parent bone, is the concave side.
    const std::vector<glm::mat4> bent = worldMatrices(c.model, bendPose(c.model, j, jm.axis, jm.peak));
    glm::dvec3 tipRest, tipBent;
    if (child >= 0) {
        tipRest = restJointPosition(c.rest, child);
        tipBent = glm::dvec3(bent[static_cast<std::size_t>(child)][3]);
    } else {
        tipRest = P + pb * (0.5 * parentLength);
        const glm::dmat4 rel = glm::dmat4(bent[static_cast<std::size_t>(j)]) *
                               glm::inverse(glm::dmat4(c.rest.world[static_cast<std::size_t>(j)]));
        tipBent = glm::dvec3(rel * glm::dvec4(tipRest, 1.0));
    }
    glm::dvec3 d = tipBent - tipRest;
    d -= glm::dot(d, pb) * pb;
    if (!(glm::length(d) > 1e-6 * c.body.height)) return;
    d = glm::normalize(d);
    const double maxRay = 0.5 * c.body.height;
    const auto accept = [&](std::size_t part, int tri) {
        return triangleWeighsOn(c.model.parts[part], static_cast<std::size_t>(tri) * 3, nodes);
    };
    const std::vector<std::vector<glm::dvec3>> posedAll = [&] {
        std::vector<std::vector<glm::dvec3>> p(c.model.parts.size());
        const auto skinned = skin(c.model, bent);
        for (std::size_t pi = 0; pi < skinned.size(); ++pi)
            p[pi].assign(skinned[pi].positions.begin(), skinned[pi].positions.end());
        return p;
    }();
    std::string peakClip;
    double peakTime = 0.0;
    if (!jm.synthetic && jm.peakSample >= 0 && static_cast<std::size_t>(jm.peakSample) < c.motion.samples.size()) {
        const MotionSample& s = c.motion.samples[static_cast<std::size_t>(jm.peakSample)];
        if (s.clip >= 0) {
            peakClip = c.model.clips[static_cast<std::size_t>(s.clip)].name;
            peakTime = std::round(static_cast<double>(s.time) * 1000.0) / 1000.0;
        }
    }
    for (const Site& site : sites) {
        const std::string kind = site.kind;
        glm::dvec3 origin = P, dir = d;
        if (kind == "bone") dir = -d;
        if (kind == "bulge") origin = parentPos + site.along * (P - parentPos);
        const auto hit = castRay(c.model, c.restPos, origin, dir, maxRay, accept);
        if (!hit) continue;
        const double r = hit->distance;
        const glm::dvec3 X = restPositionAt(c.model, c.rest, hit->point);
        const glm::dvec3 N = restNormalAt(c.model, c.rest, hit->point);
        if (glm::dot(N, dir) < 0.0) continue; // the ray left through a back face: not the limb's outside
        const std::vector<Tri> region = regionNear(c, X, dir, 1.2 * r, nodes);
        const RegionStrain strain = strainOf(c, region, posedAll);
        glm::dvec3 across = glm::cross(N, pb); // ⟂ the bone, in the tangent plane
        if (kind == "crease" && glm::length(strain.compressionDirection) > 0.0) {
            const glm::dvec3 comp = strain.compressionDirection - glm::dot(strain.compressionDirection, N) * N;
            if (glm::length(comp) > 1e-6) across = glm::cross(N, glm::normalize(comp));
        }
        if (!(glm::length(across) > 1e-9)) continue;
        across = glm::normalize(across);
        Proposal pr;
        pr.kind = kind;
        Placement& p = pr.placement;
        p.id = std::string(site.idBase) + sideSuffix(info->side);
        p.label = sideWord(info->side) + site.label;
        p.pattern = site.pattern;
        p.projection = Projection::Surface;
        p.anchor = anchorAt(c, hit->point, across);
        if (kind == "crease") p.size = {roundSize(2.0 * r), roundSize(1.2 * r)};
        else if (kind == "bone") p.size = {roundSize(1.1 * r), roundSize(1.1 * r)};
        else p.size = {roundSize(1.4 * r), roundSize(0.45 * parentLength)};
        // On a coarse mesh the anchor may lie far inside a large triangle: the decal reaches at
        // least its nearest corner (what lint's off_surface looks for).
        {
            const MeshPart& mp = c.model.parts[hit->point.part];
            const glm::dvec3 at(p.anchor.position[0], p.anchor.position[1], p.anchor.position[2]);
            double nearest = std::numeric_limits<double>::max();
            for (int k = 0; k < 3; ++k)
                nearest = std::min(nearest, glm::length(glm::dvec3(mp.positions[mp.indices[hit->point.base + static_cast<std::size_t>(k)]]) - at));
            if (1.25 * nearest > p.depthOrDefault()) p.depth = roundSize(1.25 * nearest);
        }
        p.joint = c.model.nodes[static_cast<std::size_t>(j)].name;
        p.axisName.clear();
        p.axis = {round6(jm.axis.x), round6(jm.axis.y), round6(jm.axis.z)};
        p.thetaMin = roundHalf(jm.neutral);
        p.thetaMax = roundHalf(jm.peak);
        p.model = site.model;
        p.target = site.target;
        ProposalWhy& why = pr.why;
        why.joint = p.joint;
        why.role = describeJoint(c.model, c.body, j);
        why.axis = jm.axis;
        why.neutral = p.thetaMin;
        why.peak = p.thetaMax;
        why.peakClip = peakClip;
        why.peakTime = peakTime;
        why.synthetic = jm.synthetic;
        why.planarity = jm.planarity;
        why.compression = strain.compression;
        why.stretch = strain.stretch;
        why.radius = r;
        why.correlation = jm.synthetic ? 0.0 : correlationOf(c, region, j, jm.axis, kind == "bone");
        const double strength = kind == "bone" ? std::min(1.0, strain.stretch / 0.08) : std::min(1.0, strain.compression / 0.08);
        const double follows = jm.synthetic ? 0.3 : std::max(0.0, why.correlation);
        pr.score = std::round((0.5 * strength + 0.5 * follows) * 1000.0) / 1000.0;
        out.push_back(std::move(pr));
    }
}

} // namespace

std::vector<Proposal> proposePatterns(const Model& model, const RestSkin& rest, const SymmetryPlane& plane,
                                      const BodyMap& body, const MotionAnalysis& motion) {
    std::vector<Proposal> out;
    if (model.joints.empty() || rest.parts.size() != model.parts.size()) return out;
    Ctx c{model, rest, plane, body, motion, restPositions(rest), {}};
    c.sampleWorld.reserve(motion.samples.size());
    for (const MotionSample& s : motion.samples) c.sampleWorld.push_back(worldMatrices(model, samplePose(model, s)));
    const bool clips = !model.clips.empty();
    // A synthetic range on a model with clips only where no clip moves the joint at all (the
    // clips say nothing about it) or where they turn it the synthetic way: else no clip would
    // ever show the pattern.
    const auto usable = [&](const JointMotion* jm) {
        if (!jm || jm->peak - jm->neutral < 2.0) return false;
        return !clips || !jm->synthetic || jm->clipHi - jm->clipLo < 0.5 || jm->clipHi > 0.5;
    };
    const std::vector<Site> elbow = {
        {"crease", "crease", "elbow_crease", "elbow crease", DeformModel::Scale, Target::Bump},
        {"bone", "round_bulge", "elbow_bone", "elbow tip", DeformModel::Bias, Target::Bump},
        {"bulge", "round_bulge", "biceps", "biceps", DeformModel::Scale, Target::Displacement, 0.55}};
    const std::vector<Site> knee = {
        {"crease", "crease", "knee_crease", "knee crease", DeformModel::Scale, Target::Bump},
        {"bone", "round_bulge", "knee_bone", "knee cap", DeformModel::Bias, Target::Bump},
        {"bulge", "elongated_bulge", "thigh", "thigh bulge", DeformModel::Scale, Target::Displacement, 0.5}};
    // The calf swells as the ankle points the foot (plantar flexion): on the back of the shin, a
    // third of the way down from the knee.
    const std::vector<Site> ankle = {
        {"bulge", "elongated_bulge", "calf", "calf", DeformModel::Scale, Target::Displacement, 0.35}};
    // The ankle's angle turned so that pointing the foot is positive: the toe tip moves away from
    // the knee (along the shin) at the positive peak.
    const auto pointing = [&](int j, const JointMotion& jm) {
        const int child = boneChild(model, body, j), parent = boneParent(model, body, j);
        if (child < 0 || parent < 0) return jm;
        const auto bent = worldMatrices(model, bendPose(model, j, jm.axis, std::max(10.0, jm.peak)));
        const glm::dvec3 moved = glm::dvec3(bent[static_cast<std::size_t>(child)][3]) - restJointPosition(rest, child);
        const glm::dvec3 shin = restJointPosition(rest, j) - restJointPosition(rest, parent);
        return glm::dot(moved, shin) >= 0.0 ? jm : motionAbout(model, motion, j, -jm.axis);
    };
    // Spine and neck: the joint of that role that bends forward most, its crease on the front.
    const auto forwardBend = [&](JointRole role, const Site& site) {
        int best = -1;
        JointMotion bestMotion;
        for (int j : model.joints) {
            const JointInfo* info = body.info(j);
            const JointMotion* jm = motion.motion(j);
            if (!info || info->role != role || !info->deforms || !jm || (clips && jm->synthetic)) continue;
            // The sign of the axis that moves the child forward (+z).
            JointMotion m = *jm;
            const int child = mainChild(model, body, j);
            if (child < 0) continue;
            const auto bent = worldMatrices(model, bendPose(model, j, m.axis, std::max(10.0, m.peak)));
            const double forward = bent[static_cast<std::size_t>(child)][3].z - restJointPosition(rest, child).z;
            if (forward < 0.0) m = motionAbout(model, motion, j, -m.axis);
            if (!usable(&m) || m.peak <= 0.0 || m.peak - m.neutral < kMinMotionDegrees) continue;
            if (best < 0 || m.peak - m.neutral > bestMotion.peak - bestMotion.neutral) {
                best = j;
                bestMotion = m;
            }
        }
        if (best >= 0) proposeAt(c, best, bestMotion, {site}, out);
    };
    forwardBend(JointRole::Spine, {"crease", "stomach_wrinkles", "stomach_crease", "stomach crease", DeformModel::Scale, Target::Bump});
    forwardBend(JointRole::Neck, {"crease", "neck_rings", "neck_crease", "neck crease", DeformModel::Scale, Target::Bump});
    // Limbs: left first; a right joint whose left twin has proposals gets their mirror images.
    for (const JointRole role : {JointRole::Elbow, JointRole::Knee, JointRole::Ankle}) {
        const std::vector<Site>& sites = role == JointRole::Elbow ? elbow : role == JointRole::Knee ? knee : ankle;
        std::vector<int> done;
        for (const char side : {'l', 'r', '\0'}) {
            for (int j : model.joints) {
                const JointInfo* info = body.info(j);
                if (!info || info->role != role || info->side != side || !info->deforms) continue;
                if (std::find(done.begin(), done.end(), j) != done.end()) continue;
                done.push_back(j);
                const JointMotion* found = motion.motion(j);
                if (!found) continue;
                const JointMotion jm = role == JointRole::Ankle ? pointing(j, *found) : *found;
                if (!usable(&jm)) continue;
                const std::size_t first = out.size();
                proposeAt(c, j, jm, sites, out);
                if (side != 'l') continue;
                // The right twin: by mirror image.
                const int twin = body.find(role, 'r');
                const JointMotion* tm = motion.motion(twin);
                if (twin < 0 || !usable(tm)) continue;
                done.push_back(twin);
                const std::size_t last = out.size();
                for (std::size_t k = first; k < last; ++k) {
                    auto mirrored = mirrorSurfacePlacement(out[k].placement, model, plane, rest);
                    if (!mirrored || mirrored->joint != model.nodes[static_cast<std::size_t>(twin)].name) continue;
                    const JointMotion about = motionAbout(model, motion, twin, glm::dvec3(mirrored->axis[0], mirrored->axis[1], mirrored->axis[2]));
                    if (!(about.peak > 0.0)) continue;
                    Proposal r = out[k];
                    r.placement = *mirrored;
                    r.placement.id = out[k].placement.id.substr(0, out[k].placement.id.size() - 2) + "_r";
                    r.placement.label = "right " + out[k].placement.label.substr(5);
                    // Both twins: the range both joints reach.
                    const double lo = roundHalf(std::max(out[k].placement.thetaMin, about.neutral));
                    const double hi = roundHalf(std::min(out[k].placement.thetaMax, about.peak));
                    if (hi - lo < 2.0) continue;
                    out[k].placement.thetaMin = r.placement.thetaMin = lo;
                    out[k].placement.thetaMax = r.placement.thetaMax = hi;
                    r.why.joint = r.placement.joint;
                    r.why.role = describeJoint(model, body, twin);
                    r.why.axis = glm::dvec3(r.placement.axis[0], r.placement.axis[1], r.placement.axis[2]);
                    r.why.neutral = lo;
                    r.why.peakClip.clear();
                    r.why.peakTime = 0.0;
                    if (about.peakSample >= 0 && static_cast<std::size_t>(about.peakSample) < motion.samples.size()) {
                        const MotionSample& s = motion.samples[static_cast<std::size_t>(about.peakSample)];
                        if (s.clip >= 0) {
                            r.why.peakClip = model.clips[static_cast<std::size_t>(s.clip)].name;
                            r.why.peakTime = std::round(static_cast<double>(s.time) * 1000.0) / 1000.0;
                        }
                    }
                    r.why.peak = hi;
                    out[k].why.neutral = lo;
                    out[k].why.peak = hi;
                    out[k].twin = r.placement.id;
                    r.twin = out[k].placement.id;
                    out.push_back(std::move(r));
                }
            }
        }
    }
    return out;
}

MotionSuggestion suggestFromMotion(const Model& model, const RestSkin& rest, const SymmetryPlane& plane,
                                   const BodyMap& body, const MotionAnalysis& motion,
                                   const std::vector<Proposal>& proposals,
                                   const std::vector<std::pair<int, float>>& joints, glm::dvec3 position) {
    MotionSuggestion out;
    const auto setAxis = [&](glm::dvec3 a) {
        a = glm::normalize(a);
        for (int k = 0; k < 3; ++k)
            if (std::abs(a[k] - 1.0) < 1e-4) {
                out.driver.axis = std::string(1, static_cast<char>('x' + k));
                out.axisVector.reset();
                return;
            }
        out.driver.axis.clear();
        out.axisVector = glm::dvec3(round6(a.x), round6(a.y), round6(a.z));
    };
    // A proposal's decal holding the point.
    double bestArea = std::numeric_limits<double>::max();
    for (const Proposal& pr : proposals) {
        const Placement& p = pr.placement;
        const glm::dvec3 c(p.anchor.position[0], p.anchor.position[1], p.anchor.position[2]);
        const glm::dvec3 n(p.anchor.normal[0], p.anchor.normal[1], p.anchor.normal[2]);
        const glm::dvec3 t(p.anchor.tangent[0], p.anchor.tangent[1], p.anchor.tangent[2]);
        const glm::dvec3 d = position - c;
        const double area = p.size[0] * p.size[1];
        if (std::abs(glm::dot(d, n)) > p.depthOrDefault() || std::abs(glm::dot(d, t)) > 0.5 * p.size[0] ||
            std::abs(glm::dot(d, glm::cross(n, t))) > 0.5 * p.size[1] || area >= bestArea)
            continue;
        bestArea = area;
        out.driver.joint = p.joint;
        out.driver.thetaMin = p.thetaMin;
        out.driver.thetaMax = p.thetaMax;
        setAxis(glm::dvec3(p.axis[0], p.axis[1], p.axis[2]));
        out.role = pr.why.role;
        out.proposal = p.id;
    }
    if (!out.proposal.empty()) return out;
    // The weighted joint the clips move most.
    int best = -1;
    double bestScore = 0.0;
    for (auto [node, weight] : joints) {
        const JointMotion* jm = motion.motion(node);
        if (!jm || jm->synthetic) continue;
        const double score = weight * (jm->peak - jm->neutral);
        if (score > bestScore) {
            bestScore = score;
            best = node;
        }
    }
    if (best < 0) {
        out.driver = suggestDriver(model, joints);
        const int n = model.findJoint(out.driver.joint);
        if (n >= 0) out.role = describeJoint(model, body, n);
        return out;
    }
    JointMotion jm = *motion.motion(best);
    const JointInfo* info = body.info(best);
    if (info && info->side == 'r') {
        const int left = body.find(info->role, 'l');
        const JointMotion* lm = motion.motion(left);
        if (left >= 0 && lm && !lm->synthetic && info->role != JointRole::Other) {
            const glm::vec3 mirrored = mirrorAxis(model, left, best, glm::vec3(lm->axis), plane.axis);
            const JointMotion about = motionAbout(model, motion, best, glm::dvec3(mirrored));
            if (about.peak > about.neutral) jm = about;
        }
    }
    (void)rest;
    out.driver.joint = model.nodes[static_cast<std::size_t>(best)].name;
    out.driver.thetaMin = roundHalf(jm.neutral);
    out.driver.thetaMax = roundHalf(jm.peak);
    setAxis(jm.axis);
    out.role = describeJoint(model, body, best);
    return out;
}

} // namespace dermis
