// The default character's UV atlas (see uv_atlas.hpp).
#include "uv_atlas.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <queue>
#include <set>

namespace dermis::chargen {
namespace {

// --- regions ------------------------------------------------------------------------------------

struct RegionSpec {
    std::string name;
    glm::vec3 seamSide{0, 0, -1}; ///< world direction the cut seams prefer to face
    glm::vec3 up{0, 1, 0};        ///< world direction shown as "up" in the texture
    float scale = 1.0f;           ///< texel density relative to the body
};

enum Region : int {
    kTorso,
    kHeadFront,
    kHeadBack,
    kArmL,
    kArmR,
    kHandBackL,
    kHandBackR,
    kPalmL,
    kPalmR,
    kLegL,
    kLegR,
    kFootTopL,
    kFootTopR,
    kSoleL,
    kSoleR,
    kRegionCount
};

glm::vec3 mirrorX(glm::vec3 p) {
    return {-p.x, p.y, p.z};
}

struct Rules {
    glm::vec3 shoulder, d, palmN, wrist, ankle;
    glm::vec3 thumbA, thumbB, thumbSide; ///< left thumb segment and its palm-facing side
    std::vector<RegionSpec> specs;

    explicit Rules(const Skeleton& sk) {
        const Joint& ua = sk.joints[static_cast<std::size_t>(sk.at("upper_arm.l"))];
        shoulder = ua.head;
        d = ua.frame[1];
        palmN = ua.frame[0];
        wrist = sk.joints[static_cast<std::size_t>(sk.at("hand.l"))].head;
        ankle = sk.joints[static_cast<std::size_t>(sk.at("foot.l"))].head;
        const Joint& t1 = sk.joints[static_cast<std::size_t>(sk.at("thumb_01.l"))];
        thumbA = t1.head;
        thumbB = sk.joints[static_cast<std::size_t>(sk.at("thumb_03.l"))].tail;
        thumbSide = t1.frame[2]; // the thumb's flexion side (toward the palm)
        specs.resize(kRegionCount);
        const glm::vec3 armSeam = glm::normalize(palmN + glm::vec3(0, 0, -1));
        auto both = [&](int l, const std::string& name, glm::vec3 seam, glm::vec3 up, float scale) {
            specs[static_cast<std::size_t>(l)] = {name + ".l", seam, up, scale};
            specs[static_cast<std::size_t>(l + 1)] = {name + ".r", mirrorX(seam), mirrorX(up),
                                                      scale};
        };
        specs[kTorso] = {"torso", {0, 0, -1}, {0, 1, 0}, 1.0f};
        specs[kHeadFront] = {"face", {0, 0, -1}, {0, 1, 0}, 1.0f};
        specs[kHeadBack] = {"head_back", {0, 0, -1}, {0, 1, 0}, 0.8f};
        both(kArmL, "arm", armSeam, -d, 1.0f);
        both(kHandBackL, "hand_back", {0, 0, -1}, -d, 0.75f);
        both(kPalmL, "palm", {0, 0, -1}, -d, 0.75f);
        both(kLegL, "leg", {-1, 0, 0}, {0, 1, 0}, 1.0f);
        both(kFootTopL, "foot_top", {0, 0, -1}, {0, 0, -1}, 0.75f);
        both(kSoleL, "sole", {0, 0, -1}, {0, 0, -1}, 0.6f);
    }

    /// Region of a triangle with centroid c and unit normal n.
    int classify(const glm::vec3& c, const glm::vec3& n) const {
        // Head: above a plane under the jaw and across the base of the skull.
        const glm::vec3 headN = glm::normalize(glm::vec3(0, 0.92f, 0.39f));
        if (c.y > 1.45f && std::abs(c.x) < 0.13f &&
            glm::dot(c - glm::vec3(0, 1.53f, 0.06f), headN) > 0)
            return c.z > -0.012f ? kHeadFront : kHeadBack;
        const int side = c.x >= 0 ? 0 : 1;
        const glm::vec3 q(std::abs(c.x), c.y, c.z);
        const glm::vec3 qn(side == 0 ? n.x : -n.x, n.y, n.z);
        // Hands: beyond the wrist; palm or back by normal and depth.
        if (q.x > 0.3f && glm::dot(q - wrist, d) > 0.0f) {
            // By the normal: every digit splits lengthwise into two half-tubes; the thumb, which
            // is turned toward the palm, splits about its own flexion side.
            const glm::vec3 ab = thumbB - thumbA;
            const float u = std::clamp(glm::dot(q - thumbA, ab) / glm::dot(ab, ab), 0.0f, 1.0f);
            const bool onThumb = u > 0.15f && glm::length(q - (thumbA + ab * u)) < 0.02f;
            const glm::vec3 facing = onThumb ? thumbSide : palmN;
            return (glm::dot(qn, facing) > 0 ? kPalmL : kHandBackL) + side;
        }
        // Arms: beyond a plane through the shoulder, from the armpit over the deltoid.
        const glm::vec3 shoulderN = glm::normalize(d + glm::vec3(0, 0.9f, 0));
        if (q.x > 0.12f && c.y > 1.0f &&
            glm::dot(q - (shoulder - glm::vec3(0.015f, 0, 0)), shoulderN) > 0)
            return kArmL + side;
        // Feet: below a plane through the ankle, tilted down toward the heel.
        const glm::vec3 footN = glm::normalize(glm::vec3(0, 1, -0.5f));
        if (c.y < 0.2f && glm::dot(q - (ankle + glm::vec3(0, -0.005f, 0)), footN) < 0)
            return (n.y < -0.5f && c.y < 0.025f ? kSoleL : kFootTopL) + side;
        // Legs: below the line from the crotch to the side of the hip.
        const glm::vec3 legN = glm::normalize(glm::vec3(-0.12f, 0.17f, 0));
        if (c.y < 1.0f && glm::dot(q - glm::vec3(0, 0.8f, 0), legN) < 0) return kLegL + side;
        return kTorso;
    }
};

// --- mesh adjacency -------------------------------------------------------------------------

/// adj[t][c] = triangle across edge (t[c], t[c+1]); the mesh is a closed manifold.
std::vector<std::array<int, 3>> adjacency(const TriMesh& mesh) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (std::size_t t = 0; t < mesh.tris.size(); ++t)
        for (int c = 0; c < 3; ++c)
            directed[{mesh.tris[t][c], mesh.tris[t][(c + 1) % 3]}] = static_cast<int>(t);
    std::vector<std::array<int, 3>> adj(mesh.tris.size());
    for (std::size_t t = 0; t < mesh.tris.size(); ++t)
        for (int c = 0; c < 3; ++c) {
            auto it = directed.find({mesh.tris[t][(c + 1) % 3], mesh.tris[t][c]});
            adj[t][static_cast<std::size_t>(c)] = it == directed.end() ? -1 : it->second;
        }
    return adj;
}

using EdgeKey = std::pair<std::uint32_t, std::uint32_t>;
EdgeKey edgeKey(std::uint32_t a, std::uint32_t b) {
    return a < b ? EdgeKey{a, b} : EdgeKey{b, a};
}

// --- chart-local meshes -----------------------------------------------------------------------

/// A region's triangles with vertices split along the region boundary and the cut edges, so
/// that it is a manifold surface with boundary.
struct LocalMesh {
    std::vector<int> tris;                         ///< global triangle ids
    std::vector<std::uint32_t> source;             ///< local vertex → global vertex
    std::vector<glm::uvec3> local;                 ///< local triangles
    std::vector<std::vector<std::uint32_t>> loops; ///< boundary loops (local vertices, in order)
    std::vector<int> loopOf; ///< local vertex → loop index, −1 when interior
};

LocalMesh buildLocal(const TriMesh& mesh, const std::vector<std::array<int, 3>>& adj,
                     const std::vector<int>& tris, const std::vector<int>& region, int r,
                     const std::set<EdgeKey>& cuts) {
    LocalMesh lm;
    lm.tris = tris;
    std::map<int, int> localIndex;
    for (std::size_t i = 0; i < tris.size(); ++i)
        localIndex[tris[i]] = static_cast<int>(i);
    const std::size_t nc = tris.size() * 3;
    std::vector<std::size_t> parent(nc);
    std::iota(parent.begin(), parent.end(), std::size_t(0));
    auto find = [&](std::size_t x) {
        while (parent[x] != x)
            x = parent[x] = parent[parent[x]];
        return x;
    };
    auto unite = [&](std::size_t a, std::size_t b) {
        a = find(a);
        b = find(b);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    };
    auto cornerOf = [&](int lt, std::uint32_t v) {
        const glm::uvec3& tri =
            mesh.tris[static_cast<std::size_t>(tris[static_cast<std::size_t>(lt)])];
        for (int c = 0; c < 3; ++c)
            if (tri[c] == v) return static_cast<std::size_t>(lt) * 3 + static_cast<std::size_t>(c);
        return std::size_t(0);
    };
    for (std::size_t i = 0; i < tris.size(); ++i) {
        const auto t = static_cast<std::size_t>(tris[i]);
        for (int c = 0; c < 3; ++c) {
            const int o = adj[t][static_cast<std::size_t>(c)];
            if (o < 0 || region[static_cast<std::size_t>(o)] != r) continue;
            const std::uint32_t a = mesh.tris[t][c], b = mesh.tris[t][(c + 1) % 3];
            if (cuts.count(edgeKey(a, b))) continue;
            const int lo = localIndex[o];
            unite(i * 3 + static_cast<std::size_t>(c), cornerOf(lo, a));
            unite(i * 3 + static_cast<std::size_t>((c + 1) % 3), cornerOf(lo, b));
        }
    }
    std::map<std::size_t, std::uint32_t> vid;
    lm.local.resize(tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const std::size_t root = find(i * 3 + static_cast<std::size_t>(c));
            auto it = vid.find(root);
            if (it == vid.end()) {
                it = vid.emplace(root, static_cast<std::uint32_t>(lm.source.size())).first;
                lm.source.push_back(mesh.tris[static_cast<std::size_t>(tris[i])][c]);
            }
            lm.local[i][c] = it->second;
        }
    // Boundary: directed local edges without a twin.
    std::set<std::pair<std::uint32_t, std::uint32_t>> directed;
    for (const auto& t : lm.local)
        for (int c = 0; c < 3; ++c)
            directed.insert({t[c], t[(c + 1) % 3]});
    std::map<std::uint32_t, std::uint32_t> next;
    for (const auto& e : directed)
        if (!directed.count({e.second, e.first})) next[e.first] = e.second;
    lm.loopOf.assign(lm.source.size(), -1);
    for (const auto& [start, unused] : next) {
        (void)unused;
        if (lm.loopOf[start] >= 0) continue;
        std::vector<std::uint32_t> loop;
        std::uint32_t v = start;
        do {
            lm.loopOf[v] = static_cast<int>(lm.loops.size());
            loop.push_back(v);
            v = next[v];
        } while (v != start && loop.size() <= next.size());
        lm.loops.push_back(loop);
    }
    return lm;
}

// --- sparse symmetric solver ------------------------------------------------------------------

struct Sparse {
    int n = 0;
    std::vector<int> rowStart, col;
    std::vector<double> val;
    static Sparse fromTriplets(int n, std::vector<std::tuple<int, int, double>> trip) {
        std::sort(trip.begin(), trip.end(), [](const auto& a, const auto& b) {
            return std::get<0>(a) != std::get<0>(b) ? std::get<0>(a) < std::get<0>(b)
                                                    : std::get<1>(a) < std::get<1>(b);
        });
        Sparse m;
        m.n = n;
        m.rowStart.assign(static_cast<std::size_t>(n) + 1, 0);
        for (std::size_t i = 0; i < trip.size();) {
            std::size_t j = i;
            double sum = 0;
            while (j < trip.size() && std::get<0>(trip[j]) == std::get<0>(trip[i]) &&
                   std::get<1>(trip[j]) == std::get<1>(trip[i]))
                sum += std::get<2>(trip[j++]);
            m.col.push_back(std::get<1>(trip[i]));
            m.val.push_back(sum);
            ++m.rowStart[static_cast<std::size_t>(std::get<0>(trip[i])) + 1];
            i = j;
        }
        for (int r = 0; r < n; ++r)
            m.rowStart[static_cast<std::size_t>(r) + 1] += m.rowStart[static_cast<std::size_t>(r)];
        return m;
    }
    void mul(const std::vector<double>& x, std::vector<double>& y) const {
        y.assign(static_cast<std::size_t>(n), 0.0);
        for (int r = 0; r < n; ++r) {
            double s = 0;
            for (int k = rowStart[static_cast<std::size_t>(r)];
                 k < rowStart[static_cast<std::size_t>(r) + 1]; ++k)
                s += val[static_cast<std::size_t>(k)] *
                     x[static_cast<std::size_t>(col[static_cast<std::size_t>(k)])];
            y[static_cast<std::size_t>(r)] = s;
        }
    }
};

/// Conjugate gradients for a symmetric positive definite system (x holds the initial guess).
void conjugateGradient(const Sparse& a, const std::vector<double>& b, std::vector<double>& x,
                       int maxIter = 4000, double tol = 1e-12) {
    const auto n = static_cast<std::size_t>(a.n);
    std::vector<double> r(n), p(n), ap(n);
    a.mul(x, ap);
    double bb = 0;
    for (std::size_t i = 0; i < n; ++i) {
        r[i] = b[i] - ap[i];
        bb += b[i] * b[i];
    }
    p = r;
    double rr = 0;
    for (double v : r)
        rr += v * v;
    if (bb == 0) bb = 1;
    for (int it = 0; it < maxIter && rr > tol * tol * bb; ++it) {
        a.mul(p, ap);
        double pap = 0;
        for (std::size_t i = 0; i < n; ++i)
            pap += p[i] * ap[i];
        if (pap <= 0) break;
        const double alpha = rr / pap;
        double rr2 = 0;
        for (std::size_t i = 0; i < n; ++i) {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
            rr2 += r[i] * r[i];
        }
        const double beta = rr2 / rr;
        rr = rr2;
        for (std::size_t i = 0; i < n; ++i)
            p[i] = r[i] + beta * p[i];
    }
}

// --- flattening -------------------------------------------------------------------------------

double signedArea(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    return 0.5 * ((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
}

bool segmentsCross(const glm::dvec2& p1, const glm::dvec2& p2, const glm::dvec2& q1,
                   const glm::dvec2& q2) {
    auto orient = [](const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
        return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    };
    const double d1 = orient(q1, q2, p1), d2 = orient(q1, q2, p2);
    const double d3 = orient(p1, p2, q1), d4 = orient(p1, p2, q2);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

/// True when the chart's boundary loop crosses itself (non-adjacent edges intersect).
bool boundarySelfIntersects(const std::vector<std::uint32_t>& loop,
                            const std::vector<glm::dvec2>& uv) {
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec2 a = uv[loop[i]], b = uv[loop[(i + 1) % n]];
        const glm::dvec2 lo = glm::min(a, b), hi = glm::max(a, b);
        for (std::size_t j = i + 2; j < n; ++j) {
            if (i == 0 && j == n - 1) continue;
            const glm::dvec2 c = uv[loop[j]], e = uv[loop[(j + 1) % n]];
            if (std::max(c.x, e.x) < lo.x || std::min(c.x, e.x) > hi.x ||
                std::max(c.y, e.y) < lo.y || std::min(c.y, e.y) > hi.y)
                continue;
            if (segmentsCross(a, b, c, e)) return true;
        }
    }
    return false;
}

/// σ_max / σ_min of the linear map taking a surface triangle onto its UV triangle.
double conformalDistortion(const glm::vec3& q0, const glm::vec3& q1, const glm::vec3& q2,
                           const glm::dvec2& u0, const glm::dvec2& u1, const glm::dvec2& u2) {
    const glm::dvec3 p0(q0), p1(q1), p2(q2);
    const glm::dvec3 e1 = glm::normalize(p1 - p0),
                     nrm = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    const glm::dvec3 e2 = glm::cross(nrm, e1);
    const glm::dvec2 x1(glm::length(p1 - p0), 0), x2(glm::dot(p2 - p0, e1), glm::dot(p2 - p0, e2));
    const glm::dmat2 X(x1, x2), U(u1 - u0, u2 - u0);
    const glm::dmat2 J = U * glm::inverse(X);
    const double a = J[0][0], b = J[1][0], c = J[0][1], d = J[1][1];
    const double s1sq = 0.5 * (a * a + b * b + c * c + d * d);
    const double det = std::abs(a * d - b * c);
    const double disc = std::sqrt(std::max(s1sq * s1sq - det * det, 0.0));
    const double smax = std::sqrt(s1sq + disc), smin = std::sqrt(std::max(s1sq - disc, 1e-30));
    return smax / smin;
}

/// Flattens a disk-shaped local mesh. Returns UVs in metres (isometric scale), positively
/// oriented triangles. Fails (empty result) when the Tutte embedding already flips (it cannot
/// for a disk with a convex boundary, up to solver accuracy).
std::vector<glm::dvec2> flatten(const LocalMesh& lm, const TriMesh& mesh, std::string& note) {
    const std::size_t nv = lm.source.size();
    const std::vector<std::uint32_t>& loop = lm.loops[0];
    std::vector<glm::dvec3> P(nv);
    for (std::size_t v = 0; v < nv; ++v)
        P[v] = glm::dvec3(mesh.positions[lm.source[v]]);

    // Tutte: boundary on a circle by arc length, interior = average of neighbours.
    std::vector<glm::dvec2> uv(nv, glm::dvec2(0));
    double perimeter = 0;
    std::vector<double> arc(loop.size() + 1, 0.0);
    for (std::size_t i = 0; i < loop.size(); ++i) {
        perimeter += glm::length(P[loop[(i + 1) % loop.size()]] - P[loop[i]]);
        arc[i + 1] = perimeter;
    }
    const double radius = perimeter / (2 * 3.14159265358979323846);
    // The loop runs counter-clockwise around the surface seen from outside; place it so that
    // the triangles come out positively oriented.
    for (std::size_t i = 0; i < loop.size(); ++i) {
        const double a = 2 * 3.14159265358979323846 * arc[i] / perimeter;
        uv[loop[i]] = radius * glm::dvec2(std::cos(a), std::sin(a));
    }
    std::vector<int> unknown(nv, -1);
    int nu = 0;
    for (std::size_t v = 0; v < nv; ++v)
        if (lm.loopOf[v] < 0) unknown[v] = nu++;
    std::vector<std::set<std::uint32_t>> ring(nv);
    for (const auto& t : lm.local)
        for (int c = 0; c < 3; ++c) {
            ring[t[c]].insert(t[(c + 1) % 3]);
            ring[t[c]].insert(t[(c + 2) % 3]);
        }
    if (nu > 0) {
        std::vector<std::tuple<int, int, double>> trip;
        std::vector<double> bx(static_cast<std::size_t>(nu), 0.0),
            by(static_cast<std::size_t>(nu), 0.0);
        for (std::size_t v = 0; v < nv; ++v) {
            const int i = unknown[v];
            if (i < 0) continue;
            trip.emplace_back(i, i, static_cast<double>(ring[v].size()));
            for (std::uint32_t w : ring[v]) {
                if (unknown[w] >= 0)
                    trip.emplace_back(i, unknown[w], -1.0);
                else {
                    bx[static_cast<std::size_t>(i)] += uv[w].x;
                    by[static_cast<std::size_t>(i)] += uv[w].y;
                }
            }
        }
        const Sparse a = Sparse::fromTriplets(nu, trip);
        std::vector<double> x(static_cast<std::size_t>(nu), 0.0),
            y(static_cast<std::size_t>(nu), 0.0);
        conjugateGradient(a, bx, x, 20000, 1e-14);
        conjugateGradient(a, by, y, 20000, 1e-14);
        for (std::size_t v = 0; v < nv; ++v)
            if (unknown[v] >= 0)
                uv[v] = {x[static_cast<std::size_t>(unknown[v])],
                         y[static_cast<std::size_t>(unknown[v])]};
    }
    // Orientation: make the total signed area positive.
    double total = 0;
    for (const auto& t : lm.local)
        total += signedArea(uv[t[0]], uv[t[1]], uv[t[2]]);
    if (total < 0)
        for (auto& p : uv)
            p.x = -p.x;
    auto allPositive = [&](const std::vector<glm::dvec2>& u) {
        for (const auto& t : lm.local)
            if (!(signedArea(u[t[0]], u[t[1]], u[t[2]]) > 0.0)) return false;
        return true;
    };
    if (!allPositive(uv)) {
        note = "Tutte embedding flipped";
        return {};
    }

    // ARAP (Liu et al. 2008, local/global) with a flip-free backtracking step.
    const std::size_t nt = lm.local.size();
    std::vector<std::array<glm::dvec2, 3>> iso(nt); // isometric local triangle
    std::vector<std::array<double, 3>> cot(nt);     // cot of the angle opposite edge (i, i+1)
    for (std::size_t t = 0; t < nt; ++t) {
        const glm::dvec3 a = P[lm.local[t][0]], b = P[lm.local[t][1]], c = P[lm.local[t][2]];
        const glm::dvec3 e1 = glm::normalize(b - a);
        const glm::dvec3 nrm = glm::normalize(glm::cross(b - a, c - a));
        const glm::dvec3 e2 = glm::cross(nrm, e1);
        iso[t] = {glm::dvec2(0, 0), glm::dvec2(glm::length(b - a), 0),
                  glm::dvec2(glm::dot(c - a, e1), glm::dot(c - a, e2))};
        for (int i = 0; i < 3; ++i) {
            const glm::dvec3 pi = P[lm.local[t][i]], pj = P[lm.local[t][(i + 1) % 3]],
                             pk = P[lm.local[t][(i + 2) % 3]];
            const glm::dvec3 u = pi - pk, w = pj - pk;
            cot[t][static_cast<std::size_t>(i)] = glm::dot(u, w) / glm::length(glm::cross(u, w));
        }
    }
    // Cotangent Laplacian with vertex 0 pinned.
    const int pin = 0;
    std::vector<int> idx(nv);
    for (std::size_t v = 0, k = 0; v < nv; ++v)
        idx[v] = static_cast<int>(v) == pin ? -1 : static_cast<int>(k++);
    const int n = static_cast<int>(nv) - 1;
    std::vector<std::tuple<int, int, double>> trip;
    for (std::size_t t = 0; t < nt; ++t)
        for (int i = 0; i < 3; ++i) {
            const std::uint32_t a = lm.local[t][i], b = lm.local[t][(i + 1) % 3];
            const double w = cot[t][static_cast<std::size_t>(i)];
            const int ia = idx[a], ib = idx[b];
            if (ia >= 0) trip.emplace_back(ia, ia, w);
            if (ib >= 0) trip.emplace_back(ib, ib, w);
            if (ia >= 0 && ib >= 0) {
                trip.emplace_back(ia, ib, -w);
                trip.emplace_back(ib, ia, -w);
            }
        }
    const Sparse lap = Sparse::fromTriplets(n, trip);
    std::vector<std::vector<std::uint32_t>> vertexTris(nv);
    for (std::size_t t = 0; t < nt; ++t)
        for (int c = 0; c < 3; ++c)
            vertexTris[lm.local[t][c]].push_back(static_cast<std::uint32_t>(t));
    std::vector<glm::dvec2> best = uv;
    int accepted = 0;
    for (int iter = 0; iter < 150; ++iter) {
        // Local step: best rotation per triangle.
        std::vector<glm::dmat2> rot(nt);
        for (std::size_t t = 0; t < nt; ++t) {
            glm::dmat2 s(0.0); // Σ cot · (u_i − u_j)(x_i − x_j)ᵀ, column-major
            for (int i = 0; i < 3; ++i) {
                const int j = (i + 1) % 3;
                const glm::dvec2 du = uv[lm.local[t][i]] - uv[lm.local[t][j]];
                const glm::dvec2 dx =
                    iso[t][static_cast<std::size_t>(i)] - iso[t][static_cast<std::size_t>(j)];
                const double w = cot[t][static_cast<std::size_t>(i)];
                s[0][0] += w * du.x * dx.x;
                s[1][0] += w * du.x * dx.y;
                s[0][1] += w * du.y * dx.x;
                s[1][1] += w * du.y * dx.y;
            }
            // Closest rotation to s (2×2): angle of (s00 + s11, s01 − s10).
            const double a = s[0][0] + s[1][1], b = s[0][1] - s[1][0];
            const double len = std::sqrt(a * a + b * b);
            const double c = len > 0 ? a / len : 1.0, sn = len > 0 ? b / len : 0.0;
            rot[t] = glm::dmat2(c, sn, -sn, c);
        }
        // Global step.
        std::vector<double> bx(static_cast<std::size_t>(n), 0.0),
            by(static_cast<std::size_t>(n), 0.0);
        for (std::size_t t = 0; t < nt; ++t)
            for (int i = 0; i < 3; ++i) {
                const int j = (i + 1) % 3;
                const std::uint32_t a = lm.local[t][i], b = lm.local[t][j];
                const glm::dvec2 r = cot[t][static_cast<std::size_t>(i)] *
                                     (rot[t] * (iso[t][static_cast<std::size_t>(i)] -
                                                iso[t][static_cast<std::size_t>(j)]));
                if (idx[a] >= 0) {
                    bx[static_cast<std::size_t>(idx[a])] += r.x;
                    by[static_cast<std::size_t>(idx[a])] += r.y;
                }
                if (idx[b] >= 0) {
                    bx[static_cast<std::size_t>(idx[b])] -= r.x;
                    by[static_cast<std::size_t>(idx[b])] -= r.y;
                }
                // The pinned vertex moves to the right-hand side.
                const double w = cot[t][static_cast<std::size_t>(i)];
                if (idx[a] < 0 && idx[b] >= 0) {
                    bx[static_cast<std::size_t>(idx[b])] += w * uv[a].x;
                    by[static_cast<std::size_t>(idx[b])] += w * uv[a].y;
                }
                if (idx[b] < 0 && idx[a] >= 0) {
                    bx[static_cast<std::size_t>(idx[a])] += w * uv[b].x;
                    by[static_cast<std::size_t>(idx[a])] += w * uv[b].y;
                }
            }
        std::vector<double> x(static_cast<std::size_t>(n)), y(static_cast<std::size_t>(n));
        for (std::size_t v = 0; v < nv; ++v)
            if (idx[v] >= 0) {
                x[static_cast<std::size_t>(idx[v])] = uv[v].x;
                y[static_cast<std::size_t>(idx[v])] = uv[v].y;
            }
        conjugateGradient(lap, bx, x, 3000, 1e-10);
        conjugateGradient(lap, by, y, 3000, 1e-10);
        std::vector<glm::dvec2> target = uv;
        for (std::size_t v = 0; v < nv; ++v)
            if (idx[v] >= 0)
                target[v] = {x[static_cast<std::size_t>(idx[v])],
                             y[static_cast<std::size_t>(idx[v])]};
        // Backtracking: the largest global step toward the target without a flipped triangle;
        // when even a small one flips (a crushed part unfolding), each vertex moves on its own
        // as far as its triangles allow (Gauss–Seidel order).
        std::vector<glm::dvec2> trial(nv);
        bool moved = false;
        for (double step = 1.0; step >= 1.0 / 16; step *= 0.5) {
            for (std::size_t v = 0; v < nv; ++v)
                trial[v] = uv[v] + step * (target[v] - uv[v]);
            if (allPositive(trial)) {
                moved = true;
                break;
            }
        }
        if (!moved) {
            trial = uv;
            for (std::size_t v = 0; v < nv; ++v) {
                const glm::dvec2 from = trial[v];
                for (double step = 1.0; step >= 1.0 / 64; step *= 0.5) {
                    trial[v] = from + step * (target[v] - from);
                    bool ok = true;
                    for (std::uint32_t t : vertexTris[v])
                        if (!(signedArea(trial[lm.local[t][0]], trial[lm.local[t][1]],
                                         trial[lm.local[t][2]]) > 0.0)) {
                            ok = false;
                            break;
                        }
                    if (ok) {
                        moved = true;
                        break;
                    }
                    trial[v] = from;
                }
            }
        }
        if (!moved) break;
        uv = trial;
        if (!boundarySelfIntersects(loop, uv)) {
            best = uv;
            ++accepted;
        }
    }
    note = "ARAP iterations kept: " + std::to_string(accepted);
    return best;
}

// --- packing ----------------------------------------------------------------------------------

struct PackItem {
    int chart;
    double w, h; // size in UV units, padding included
    double x = 0, y = 0;
};

/// Skyline bottom-left packing into a strip of width 1 (items sorted by height). Returns the
/// height used.
double skylinePack(std::vector<PackItem>& items) {
    std::vector<std::size_t> order(items.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return items[a].h > items[b].h; });
    struct Seg {
        double x, w, y;
    };
    std::vector<Seg> sky{{0.0, 1.0, 0.0}};
    double used = 0;
    for (std::size_t k : order) {
        PackItem& it = items[k];
        double bestY = 1e30, bestX = 0;
        for (std::size_t i = 0; i < sky.size(); ++i) {
            if (sky[i].x + it.w > 1.0 + 1e-12) break;
            // Height needed to place at sky[i].x: max y over segments covered.
            double y = 0, covered = 0;
            for (std::size_t j = i; j < sky.size() && covered < it.w - 1e-12; ++j) {
                y = std::max(y, sky[j].y);
                covered = sky[j].x + sky[j].w - sky[i].x;
            }
            if (covered < it.w - 1e-12) continue;
            if (y < bestY - 1e-12) {
                bestY = y;
                bestX = sky[i].x;
            }
        }
        if (bestY > 1e29) return 1e30;
        it.x = bestX;
        it.y = bestY;
        used = std::max(used, bestY + it.h);
        // Update the skyline: replace [bestX, bestX + w) with one segment at bestY + h.
        std::vector<Seg> next;
        const double x0 = bestX, x1 = bestX + it.w;
        for (const Seg& s : sky) {
            const double s0 = s.x, s1 = s.x + s.w;
            if (s1 <= x0 + 1e-15 || s0 >= x1 - 1e-15) {
                next.push_back(s);
                continue;
            }
            if (s0 < x0) next.push_back({s0, x0 - s0, s.y});
            if (s1 > x1) next.push_back({x1, s1 - x1, s.y});
        }
        next.push_back({x0, x1 - x0, bestY + it.h});
        std::sort(next.begin(), next.end(), [](const Seg& a, const Seg& b) { return a.x < b.x; });
        // Merge neighbours at the same height.
        sky.clear();
        for (const Seg& s : next) {
            if (!sky.empty() && std::abs(sky.back().y - s.y) < 1e-15 &&
                std::abs(sky.back().x + sky.back().w - s.x) < 1e-12)
                sky.back().w += s.w;
            else
                sky.push_back(s);
        }
    }
    return used;
}

} // namespace

bool buildAtlas(const TriMesh& mesh, const Body& body, const Skeleton& skeleton, Atlas& atlas,
                std::string& error, std::FILE* log) {
    const Rules rules(skeleton);
    const std::size_t nt = mesh.tris.size();
    const auto adj = adjacency(mesh);
    std::vector<glm::vec3> vn(mesh.positions.size());
    for (std::size_t v = 0; v < vn.size(); ++v)
        vn[v] = glm::normalize(body.gradient(mesh.positions[v]));

    // 1. Regions.
    std::vector<int> region(nt);
    for (std::size_t t = 0; t < nt; ++t) {
        const auto& tri = mesh.tris[t];
        const glm::vec3 c =
            (mesh.positions[tri[0]] + mesh.positions[tri[1]] + mesh.positions[tri[2]]) / 3.0f;
        const glm::vec3 n = glm::normalize(vn[tri[0]] + vn[tri[1]] + vn[tri[2]]);
        region[t] = rules.classify(c, n);
    }
    // Smooth ragged borders: a triangle with at most one neighbour in its own region (a tooth)
    // joins the region of its other neighbours (the lower region id on a tie).
    // Sequential updates (no oscillation); ends when no tooth is left.
    for (int pass = 0; pass < 30; ++pass) {
        std::vector<int>& next = region;
        bool changed = false;
        for (std::size_t t = 0; t < nt; ++t) {
            int same = 0;
            std::map<int, int> other;
            for (int o : adj[t]) {
                const int r = region[static_cast<std::size_t>(o)];
                if (r == region[t])
                    ++same;
                else
                    ++other[r];
            }
            if (same >= 2) continue;
            int best = -1, bestN = 0;
            for (const auto& [r, n] : other)
                if (n > bestN) best = r, bestN = n;
            next[t] = best;
            changed = true;
        }
        if (!changed) break;
    }
    // Connected pieces: keep each region's largest; smaller pieces join the neighbouring region
    // they share most edges with. Repeat until stable.
    for (int pass = 0; pass < 20; ++pass) {
        std::vector<int> comp(nt, -1);
        std::vector<int> compRegion, compSize;
        for (std::size_t s = 0; s < nt; ++s) {
            if (comp[s] >= 0) continue;
            const int id = static_cast<int>(compRegion.size());
            compRegion.push_back(region[s]);
            compSize.push_back(0);
            std::vector<std::size_t> stack{s};
            comp[s] = id;
            while (!stack.empty()) {
                const std::size_t t = stack.back();
                stack.pop_back();
                ++compSize[static_cast<std::size_t>(id)];
                for (int o : adj[t])
                    if (comp[static_cast<std::size_t>(o)] < 0 &&
                        region[static_cast<std::size_t>(o)] == region[s]) {
                        comp[static_cast<std::size_t>(o)] = id;
                        stack.push_back(static_cast<std::size_t>(o));
                    }
            }
        }
        std::vector<int> largest(kRegionCount, -1);
        for (std::size_t c = 0; c < compRegion.size(); ++c) {
            int& l = largest[static_cast<std::size_t>(compRegion[c])];
            if (l < 0 || compSize[c] > compSize[static_cast<std::size_t>(l)])
                l = static_cast<int>(c);
        }
        bool changed = false;
        for (std::size_t c = 0; c < compRegion.size(); ++c) {
            if (largest[static_cast<std::size_t>(compRegion[c])] == static_cast<int>(c)) continue;
            std::map<int, int> shared;
            for (std::size_t t = 0; t < nt; ++t)
                if (comp[t] == static_cast<int>(c))
                    for (int o : adj[t])
                        if (comp[static_cast<std::size_t>(o)] != static_cast<int>(c))
                            ++shared[region[static_cast<std::size_t>(o)]];
            int bestR = -1, bestN = -1;
            for (const auto& [r, cnt] : shared)
                if (cnt > bestN) bestR = r, bestN = cnt;
            for (std::size_t t = 0; t < nt; ++t)
                if (comp[t] == static_cast<int>(c)) region[t] = bestR;
            changed = true;
        }
        if (!changed) break;
    }

    // 2–3. Cut each region into a disk and flatten it.
    struct ChartUv {
        LocalMesh lm;
        std::vector<glm::dvec2> uv;
    };
    std::vector<ChartUv> charts;
    std::vector<int> chartRegion;
    for (int r = 0; r < kRegionCount; ++r) {
        std::vector<int> tris;
        for (std::size_t t = 0; t < nt; ++t)
            if (region[t] == r) tris.push_back(static_cast<int>(t));
        if (tris.empty()) continue;
        const RegionSpec& spec = rules.specs[static_cast<std::size_t>(r)];
        std::set<EdgeKey> cuts;
        LocalMesh lm = buildLocal(mesh, adj, tris, region, r, cuts);
        if (lm.loops.empty()) {
            error = "region " + spec.name + " has no boundary";
            return false;
        }
        // Shortest path (weighted to the seam side) from `sources` through interior vertices to
        // the first vertex where isTarget holds; its edges join `cuts`. False when none.
        auto cutPath = [&](const LocalMesh& l, const std::vector<std::uint32_t>& sources,
                           const std::function<bool(std::uint32_t)>& isTarget) {
            const std::size_t nv = l.source.size();
            std::vector<std::vector<std::pair<std::uint32_t, double>>> g(nv);
            std::map<EdgeKey, int> edgeTri;
            for (const auto& t : l.local)
                for (int c = 0; c < 3; ++c)
                    ++edgeTri[edgeKey(t[c], t[(c + 1) % 3])];
            for (const auto& [e, cnt] : edgeTri) {
                if (cnt != 2) continue; // boundary edge
                const glm::vec3 pa = mesh.positions[l.source[e.first]],
                                pb = mesh.positions[l.source[e.second]];
                const glm::vec3 n = glm::normalize(vn[l.source[e.first]] + vn[l.source[e.second]]);
                const double bias =
                    1.0 + 8.0 * (1.0 - glm::dot(n, glm::normalize(spec.seamSide))) * 0.5;
                const double w = glm::length(pb - pa) * bias;
                g[e.first].push_back({e.second, w});
                g[e.second].push_back({e.first, w});
            }
            std::vector<char> isSource(nv, 0);
            for (std::uint32_t v : sources)
                isSource[v] = 1;
            std::vector<double> dist(nv, 1e30);
            std::vector<std::int64_t> prev(nv, -1);
            using QE = std::pair<double, std::uint32_t>;
            std::priority_queue<QE, std::vector<QE>, std::greater<QE>> pq;
            for (std::uint32_t v : sources) {
                dist[v] = 0;
                pq.push({0.0, v});
            }
            std::int64_t hit = -1;
            while (!pq.empty()) {
                const auto [dv, v] = pq.top();
                pq.pop();
                if (dv > dist[v]) continue;
                if (!isSource[v] && isTarget(v)) {
                    hit = v;
                    break;
                }
                if (isSource[v] && dv > 0) continue; // never walk along the sources
                for (const auto& [w, len] : g[v]) {
                    if (isSource[w]) continue;
                    if (dv + len < dist[w]) {
                        dist[w] = dv + len;
                        prev[w] = v;
                        pq.push({dist[w], w});
                    }
                }
            }
            if (hit < 0) return false;
            for (std::int64_t v = hit; prev[static_cast<std::size_t>(v)] >= 0;
                 v = prev[static_cast<std::size_t>(v)])
                cuts.insert(
                    edgeKey(l.source[static_cast<std::size_t>(v)],
                            l.source[static_cast<std::size_t>(prev[static_cast<std::size_t>(v)])]));
            return true;
        };
        int guard = 0;
        while (lm.loops.size() > 1) {
            if (++guard > 16) {
                error = "region " + spec.name + ": cannot cut into a disk";
                return false;
            }
            // Cut from the last loop through interior vertices to any other loop.
            const int from = static_cast<int>(lm.loops.size()) - 1;
            std::vector<std::uint32_t> sources = lm.loops[static_cast<std::size_t>(from)];
            if (!cutPath(lm, sources, [&](std::uint32_t v) {
                    return lm.loopOf[v] >= 0 && lm.loopOf[v] != from;
                })) {
                error = "region " + spec.name + ": no cut path between boundary loops";
                return false;
            }
            lm = buildLocal(mesh, adj, tris, region, r, cuts);
        }
        std::string note;
        std::vector<glm::dvec2> uv;
        for (int extra = 0;; ++extra) {
            // Disk check: V − E + F = 1.
            std::set<EdgeKey> edges;
            for (const auto& t : lm.local)
                for (int c = 0; c < 3; ++c)
                    edges.insert(edgeKey(t[c], t[(c + 1) % 3]));
            const long chi = static_cast<long>(lm.source.size()) - static_cast<long>(edges.size()) +
                             static_cast<long>(lm.local.size());
            if (chi != 1 || lm.loops.size() != 1) {
                error = "region " + spec.name +
                        " is not a disk after cutting (χ = " + std::to_string(chi) + ")";
                return false;
            }
            uv = flatten(lm, mesh, note);
            if (uv.empty()) {
                error = "region " + spec.name + ": " + note;
                return false;
            }
            // A part that stays crushed (a fingertip folded by the initial embedding) gets a cut
            // from the boundary to it, and the chart is flattened again.
            double worst = 0;
            std::int64_t worstVertex = -1;
            for (const auto& t : lm.local) {
                const double dist = conformalDistortion(
                    mesh.positions[lm.source[t[0]]], mesh.positions[lm.source[t[1]]],
                    mesh.positions[lm.source[t[2]]], uv[t[0]], uv[t[1]], uv[t[2]]);
                for (int c = 0; c < 3; ++c)
                    if (dist > worst && lm.loopOf[t[c]] < 0) {
                        worst = dist;
                        worstVertex = t[c];
                    }
            }
            if (log && worst >= 6.0)
                std::fprintf(log, "  %s: worst distortion %.1f, extra cut %d\n", spec.name.c_str(),
                             worst, extra);
            if (worst < 6.0 || worstVertex < 0 || extra == 6) break;
            const auto target = static_cast<std::uint32_t>(worstVertex);
            if (!cutPath(lm, lm.loops[0], [&](std::uint32_t v) { return v == target; })) break;
            lm = buildLocal(mesh, adj, tris, region, r, cuts);
        }
        if (log)
            std::fprintf(log, "flattened %-12s %5zu triangles, %4zu vertices, %2zu cut edges, %s\n",
                         spec.name.c_str(), lm.local.size(), lm.source.size(), cuts.size(),
                         note.c_str());
        charts.push_back({std::move(lm), std::move(uv)});
        chartRegion.push_back(r);
    }

    // 4. Orientation (body "up" → texture up, never mirrored), density, packing.
    std::vector<PackItem> items;
    std::vector<glm::dvec2> chartLo(charts.size());
    for (std::size_t c = 0; c < charts.size(); ++c) {
        ChartUv& ch = charts[c];
        const RegionSpec& spec = rules.specs[static_cast<std::size_t>(chartRegion[c])];
        // Flatten produced positively oriented triangles in (x, y-up) terms; in glTF's (u, v-down)
        // image space that reads as the surface seen from outside, not mirrored, once v = −y.
        // Rotate so that the gradient of the height function (world `up`) points to −v.
        glm::dvec2 grad(0);
        for (const auto& t : ch.lm.local) {
            const glm::dvec2 a = ch.uv[t[0]], b = ch.uv[t[1]], cc = ch.uv[t[2]];
            const double h0 =
                glm::dot(glm::dvec3(mesh.positions[ch.lm.source[t[0]]]), glm::dvec3(spec.up));
            const double h1 =
                glm::dot(glm::dvec3(mesh.positions[ch.lm.source[t[1]]]), glm::dvec3(spec.up));
            const double h2 =
                glm::dot(glm::dvec3(mesh.positions[ch.lm.source[t[2]]]), glm::dvec3(spec.up));
            // Gradient of the linear interpolant, times area (area-weighted sum).
            const glm::dvec2 g((h1 - h0) * (cc.y - a.y) - (h2 - h0) * (b.y - a.y),
                               (h2 - h0) * (b.x - a.x) - (h1 - h0) * (cc.x - a.x));
            grad += g;
        }
        const double ang = std::atan2(grad.y, grad.x);
        const double rotate = 3.14159265358979323846 / 2 - ang; // bring grad to +y (y-up)
        const double cs = std::cos(rotate), sn = std::sin(rotate);
        for (auto& p : ch.uv)
            p = glm::dvec2(cs * p.x - sn * p.y, sn * p.x + cs * p.y);
        for (auto& p : ch.uv)
            p = glm::dvec2(p.x, -p.y) * static_cast<double>(spec.scale);
        glm::dvec2 lo(1e30), hi(-1e30);
        for (const auto& p : ch.uv) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        chartLo[c] = lo;
        items.push_back({static_cast<int>(c), hi.x - lo.x, hi.y - lo.y});
    }
    // Largest scale at which everything fits in [0,1]² with a padding of 6 texels at 1024².
    const double pad = 6.0 / 1024.0;
    double lo = 0.05, hi = 2.0, bestScale = 0;
    std::vector<PackItem> bestItems;
    for (int it = 0; it < 40; ++it) {
        const double s = 0.5 * (lo + hi);
        std::vector<PackItem> trial = items;
        for (auto& p : trial) {
            p.w = p.w * s + 2 * pad;
            p.h = p.h * s + 2 * pad;
        }
        const double used = skylinePack(trial);
        if (used <= 1.0) {
            lo = s;
            bestScale = s;
            bestItems = trial;
        } else {
            hi = s;
        }
    }
    if (bestScale <= 0) {
        error = "packing failed";
        return false;
    }

    // Output vertices and triangles.
    atlas = Atlas{};
    atlas.tris.assign(nt, glm::uvec3(0));
    atlas.triChart.assign(nt, -1);
    for (const PackItem& it : bestItems) {
        const auto c = static_cast<std::size_t>(it.chart);
        const ChartUv& ch = charts[c];
        const auto base = static_cast<std::uint32_t>(atlas.uvs.size());
        ChartInfo info;
        info.name = rules.specs[static_cast<std::size_t>(chartRegion[c])].name;
        info.lo = glm::vec2(1e9f);
        info.hi = glm::vec2(-1e9f);
        for (std::size_t v = 0; v < ch.lm.source.size(); ++v) {
            const glm::dvec2 p =
                (ch.uv[v] - chartLo[c]) * bestScale + glm::dvec2(it.x + pad, it.y + pad);
            const glm::vec2 uv(static_cast<float>(p.x), static_cast<float>(p.y));
            atlas.uvs.push_back(uv);
            atlas.source.push_back(ch.lm.source[v]);
            info.lo = glm::min(info.lo, uv);
            info.hi = glm::max(info.hi, uv);
        }
        for (std::size_t i = 0; i < ch.lm.tris.size(); ++i) {
            const auto t = static_cast<std::size_t>(ch.lm.tris[i]);
            atlas.tris[t] = ch.lm.local[i] + glm::uvec3(base);
            atlas.triChart[t] = static_cast<int>(atlas.charts.size());
        }
        info.triangles = static_cast<int>(ch.lm.tris.size());
        atlas.charts.push_back(info);
    }
    // Chart order in the output: by name (stable, readable), remapped.
    {
        std::vector<int> order(atlas.charts.size());
        std::iota(order.begin(), order.end(), 0);
        std::sort(order.begin(), order.end(), [&](int a, int b) {
            return atlas.charts[static_cast<std::size_t>(a)].name <
                   atlas.charts[static_cast<std::size_t>(b)].name;
        });
        std::vector<int> rank(order.size());
        std::vector<ChartInfo> sorted;
        for (std::size_t k = 0; k < order.size(); ++k) {
            rank[static_cast<std::size_t>(order[k])] = static_cast<int>(k);
            sorted.push_back(atlas.charts[static_cast<std::size_t>(order[k])]);
        }
        atlas.charts = sorted;
        for (int& c : atlas.triChart)
            c = rank[static_cast<std::size_t>(c)];
    }

    // Verification and statistics.
    for (std::size_t t = 0; t < nt; ++t) {
        if (atlas.triChart[t] < 0) {
            error = "triangle " + std::to_string(t) + " has no chart";
            return false;
        }
        const glm::uvec3& tri = atlas.tris[t];
        for (int c = 0; c < 3; ++c) {
            if (atlas.source[tri[c]] != mesh.tris[t][c]) {
                error = "internal: seam vertex mismatch";
                return false;
            }
            const glm::vec2 uv = atlas.uvs[tri[c]];
            if (!(uv.x >= 0 && uv.x <= 1 && uv.y >= 0 && uv.y <= 1)) {
                error = "UV outside [0,1]";
                return false;
            }
        }
        // v-down: a front face reads clockwise in (u, v) maths terms, i.e. negative area.
        const glm::dvec2 a(atlas.uvs[tri[0]]), b(atlas.uvs[tri[1]]), c(atlas.uvs[tri[2]]);
        if (!(signedArea(a, b, c) < 0)) {
            error = "flipped or degenerate UV triangle " + std::to_string(t);
            return false;
        }
        ChartInfo& info = atlas.charts[static_cast<std::size_t>(atlas.triChart[t])];
        const glm::vec3 p0 = mesh.positions[mesh.tris[t][0]], p1 = mesh.positions[mesh.tris[t][1]],
                        p2 = mesh.positions[mesh.tris[t][2]];
        info.surfaceArea += 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
        info.uvArea += static_cast<float>(-signedArea(a, b, c));
    }
    // Distortion: singular values of the map surface → UV per triangle.
    std::vector<double> confSum(atlas.charts.size(), 0), spreadSum(atlas.charts.size(), 0),
        areaSum(atlas.charts.size(), 0);
    for (std::size_t t = 0; t < nt; ++t) {
        const auto ci = static_cast<std::size_t>(atlas.triChart[t]);
        const ChartInfo& info = atlas.charts[ci];
        const glm::dvec3 p0(mesh.positions[mesh.tris[t][0]]), p1(mesh.positions[mesh.tris[t][1]]),
            p2(mesh.positions[mesh.tris[t][2]]);
        const glm::dvec3 e1 = glm::normalize(p1 - p0),
                         nrm = glm::normalize(glm::cross(p1 - p0, p2 - p0));
        const glm::dvec3 e2 = glm::cross(nrm, e1);
        const glm::dvec2 x1(glm::length(p1 - p0), 0),
            x2(glm::dot(p2 - p0, e1), glm::dot(p2 - p0, e2));
        const glm::dvec2 u0(atlas.uvs[atlas.tris[t][0]]), u1(atlas.uvs[atlas.tris[t][1]]),
            u2(atlas.uvs[atlas.tris[t][2]]);
        // J · [x1 x2] = [u1−u0 u2−u0]
        const glm::dmat2 X(x1, x2), U(u1 - u0, u2 - u0);
        const glm::dmat2 J = U * glm::inverse(X);
        const double a = J[0][0], b = J[1][0], c = J[0][1], d = J[1][1];
        const double s1sq = 0.5 * (a * a + b * b + c * c + d * d);
        const double det = std::abs(a * d - b * c);
        const double disc = std::sqrt(std::max(s1sq * s1sq - det * det, 0.0));
        const double smax = std::sqrt(s1sq + disc), smin = std::sqrt(std::max(s1sq - disc, 1e-30));
        const double area = 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
        const double chartScale = info.uvArea / info.surfaceArea;
        confSum[ci] += area * smax / smin;
        spreadSum[ci] += area * std::abs(std::log(det / chartScale));
        areaSum[ci] += area;
    }
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
        atlas.charts[c].conformal = static_cast<float>(confSum[c] / areaSum[c]);
        atlas.charts[c].areaSpread = static_cast<float>(spreadSum[c] / areaSum[c]);
    }
    // Charts never overlap: packed boxes are disjoint (padding included).
    for (std::size_t a = 0; a < atlas.charts.size(); ++a)
        for (std::size_t b = a + 1; b < atlas.charts.size(); ++b) {
            const ChartInfo &A = atlas.charts[a], &B = atlas.charts[b];
            if (A.lo.x < B.hi.x && B.lo.x < A.hi.x && A.lo.y < B.hi.y && B.lo.y < A.hi.y) {
                error = "charts " + A.name + " and " + B.name + " overlap";
                return false;
            }
        }
    return true;
}

glm::vec2 uvAt(const TriMesh& mesh, const Atlas& atlas, const glm::vec3& p, int* chart) {
    // Closest point on any triangle (exact point-triangle distance, Ericson's method).
    double best = 1e30;
    glm::vec2 out(0);
    int outChart = -1;
    for (std::size_t t = 0; t < mesh.tris.size(); ++t) {
        const glm::dvec3 a(mesh.positions[mesh.tris[t][0]]), b(mesh.positions[mesh.tris[t][1]]),
            c(mesh.positions[mesh.tris[t][2]]);
        const glm::dvec3 q(p);
        // Barycentric of the projection, clamped by region.
        const glm::dvec3 ab = b - a, ac = c - a, ap = q - a;
        const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
        double u, v, w;
        const glm::dvec3 bp = q - b;
        const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
        const glm::dvec3 cp = q - c;
        const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
        const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (d1 <= 0 && d2 <= 0) {
            u = 1;
            v = 0;
            w = 0;
        } else if (d3 >= 0 && d4 <= d3) {
            u = 0;
            v = 1;
            w = 0;
        } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
            v = d1 / (d1 - d3);
            u = 1 - v;
            w = 0;
        } else if (d6 >= 0 && d5 <= d6) {
            u = 0;
            v = 0;
            w = 1;
        } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
            w = d2 / (d2 - d6);
            u = 1 - w;
            v = 0;
        } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
            w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            u = 0;
            v = 1 - w;
        } else {
            const double denom = 1.0 / (va + vb + vc);
            v = vb * denom;
            w = vc * denom;
            u = 1 - v - w;
        }
        const glm::dvec3 x = u * a + v * b + w * c;
        const double dist = glm::length(x - q);
        if (dist < best) {
            best = dist;
            const glm::vec2 ua = atlas.uvs[atlas.tris[t][0]], ub = atlas.uvs[atlas.tris[t][1]],
                            uc = atlas.uvs[atlas.tris[t][2]];
            out = static_cast<float>(u) * ua + static_cast<float>(v) * ub +
                  static_cast<float>(w) * uc;
            outChart = atlas.triChart[t];
        }
    }
    if (chart) *chart = outChart;
    return out;
}

} // namespace dermis::chargen
