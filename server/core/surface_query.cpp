// Geometry queries on a model's surface. See surface_query.hpp.
#include "surface_query.hpp"

#include <cmath>
#include <limits>

namespace dermis {

glm::dvec3 closestBary(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return {1, 0, 0};
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return {0, 1, 0};
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const double v = d1 - d3 != 0.0 ? d1 / (d1 - d3) : 0.0;
        return {1.0 - v, v, 0.0};
    }
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return {0, 0, 1};
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const double w = d2 - d6 != 0.0 ? d2 / (d2 - d6) : 0.0;
        return {1.0 - w, 0.0, w};
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        const double den = (d4 - d3) + (d5 - d6);
        const double w = den != 0.0 ? (d4 - d3) / den : 0.0;
        return {0.0, 1.0 - w, w};
    }
    const double sum = va + vb + vc;
    if (!(sum != 0.0)) return {1, 0, 0}; // a degenerate triangle: its first corner
    const double v = vb / sum, w = vc / sum;
    return {1.0 - v - w, v, w};
}

namespace {

/// The triangle at `t` of part `p` when all three corners index `pos` and the part's own
/// positions; false otherwise.
bool corners(const MeshPart& p, const std::vector<glm::vec3>& pos, std::size_t t, std::uint32_t (&i)[3]) {
    for (int k = 0; k < 3; ++k) {
        i[k] = p.indices[t + static_cast<std::size_t>(k)];
        if (i[k] >= pos.size() || i[k] >= p.positions.size()) return false;
    }
    return true;
}

/// fn(part, first index, a, b, c) for every triangle of `m` whose corners index `positions[part]`
/// (and the part's own positions).
template <class Fn>
void forEachTriangle(const Model& m, const std::vector<const std::vector<glm::vec3>*>& positions, Fn&& fn) {
    for (std::size_t pi = 0; pi < m.parts.size() && pi < positions.size(); ++pi) {
        const MeshPart& p = m.parts[pi];
        const auto& pos = *positions[pi];
        for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
            std::uint32_t i[3];
            if (!corners(p, pos, t, i)) continue;
            fn(pi, t, glm::dvec3(pos[i[0]]), glm::dvec3(pos[i[1]]), glm::dvec3(pos[i[2]]));
        }
    }
}

} // namespace

std::optional<SurfacePoint> nearestSurfacePoint(const Model& m,
                                                const std::vector<const std::vector<glm::vec3>*>& positions,
                                                glm::dvec3 q) {
    double best = std::numeric_limits<double>::max();
    std::optional<SurfacePoint> out;
    forEachTriangle(m, positions, [&](std::size_t pi, std::size_t t, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
        const glm::dvec3 w = closestBary(q, a, b, c);
        const double d = glm::length(w.x * a + w.y * b + w.z * c - q);
        if (d < best) {
            best = d;
            out = SurfacePoint{pi, t, w};
        }
    });
    return out;
}

std::optional<RayHit> castRay(const Model& m, const std::vector<const std::vector<glm::vec3>*>& positions,
                              glm::dvec3 origin, glm::dvec3 dir, double maxDistance,
                              const std::function<bool(std::size_t, int)>& accept) {
    std::optional<RayHit> out;
    double best = maxDistance;
    forEachTriangle(m, positions, [&](std::size_t pi, std::size_t t, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
        const glm::dvec3 e1 = b - a, e2 = c - a, pv = glm::cross(dir, e2);
        const double det = glm::dot(e1, pv);
        if (std::abs(det) < 1e-20) return;
        const double inv = 1.0 / det;
        const glm::dvec3 tv = origin - a;
        const double u = glm::dot(tv, pv) * inv;
        if (u < 0.0 || u > 1.0) return;
        const glm::dvec3 qv = glm::cross(tv, e1);
        const double v = glm::dot(dir, qv) * inv;
        if (v < 0.0 || u + v > 1.0) return;
        const double s = glm::dot(e2, qv) * inv;
        if (!(s > 0.0) || s > best) return;
        if (accept && !accept(pi, static_cast<int>(t / 3))) return;
        best = s;
        out = RayHit{SurfacePoint{pi, t, {1.0 - u - v, u, v}}, s};
    });
    return out;
}

glm::dmat4 restSkinningAt(const Model& m, const RestSkin& rest, const SurfacePoint& sp) {
    const MeshPart& p = m.parts[sp.part];
    glm::dmat4 sum(0.0);
    double total = 0.0;
    for (int c = 0; c < 3; ++c) {
        const std::uint32_t v = p.indices[sp.base + static_cast<std::size_t>(c)];
        const bool weighted = v < p.joints.size() && v < p.weights.size();
        for (int k = 0; k < (weighted ? 4 : 1); ++k) {
            const std::size_t inf = weighted ? p.joints[v][k] : 0;
            const double w = sp.bary[c] * (weighted ? p.weights[v][k] : 1.0);
            if (!(w > 0.0) || inf >= p.influences.size()) continue;
            const int node = p.influences[inf].node;
            const glm::dmat4 world = node >= 0 && static_cast<std::size_t>(node) < rest.world.size()
                                         ? glm::dmat4(rest.world[static_cast<std::size_t>(node)])
                                         : glm::dmat4(1.0);
            sum += w * (world * glm::dmat4(p.influences[inf].inverseBind));
            total += w;
        }
    }
    return total > 0.0 ? sum / total : glm::dmat4(1.0);
}

namespace {

glm::dvec3 blend(const std::vector<glm::vec3>& v, const MeshPart& p, const SurfacePoint& sp) {
    glm::dvec3 out(0.0);
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t i = p.indices[sp.base + static_cast<std::size_t>(k)];
        if (i < v.size()) out += sp.bary[k] * glm::dvec3(v[i]);
    }
    return out;
}

glm::dvec3 normalAt(const std::vector<glm::vec3>& pos, const std::vector<glm::vec3>& nrm, const MeshPart& p,
                    const SurfacePoint& sp) {
    glm::dvec3 n = nrm.size() == pos.size() ? blend(nrm, p, sp) : glm::dvec3(0.0);
    if (!(glm::length(n) > 1e-12)) {
        glm::dvec3 c[3];
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t i = p.indices[sp.base + static_cast<std::size_t>(k)];
            c[k] = i < pos.size() ? glm::dvec3(pos[i]) : glm::dvec3(0.0);
        }
        n = glm::cross(c[1] - c[0], c[2] - c[0]);
    }
    return glm::length(n) > 0.0 ? glm::normalize(n) : glm::dvec3(0, 0, 1);
}

} // namespace

glm::dvec3 bindPositionAt(const Model& m, const SurfacePoint& sp) {
    return blend(m.parts[sp.part].positions, m.parts[sp.part], sp);
}

glm::dvec3 bindNormalAt(const Model& m, const SurfacePoint& sp) {
    const MeshPart& p = m.parts[sp.part];
    return normalAt(p.positions, p.normals, p, sp);
}

glm::dvec3 restPositionAt(const Model& m, const RestSkin& rest, const SurfacePoint& sp) {
    if (sp.part >= rest.parts.size()) return bindPositionAt(m, sp);
    return blend(rest.parts[sp.part].positions, m.parts[sp.part], sp);
}

glm::dvec3 restNormalAt(const Model& m, const RestSkin& rest, const SurfacePoint& sp) {
    if (sp.part >= rest.parts.size()) return bindNormalAt(m, sp);
    return normalAt(rest.parts[sp.part].positions, rest.parts[sp.part].normals, m.parts[sp.part], sp);
}

bool triangleWeighsOn(const MeshPart& p, std::size_t base, const std::set<int>& nodes, float minWeight) {
    for (int c = 0; c < 3; ++c) {
        const std::size_t at = base + static_cast<std::size_t>(c);
        if (at >= p.indices.size()) return false;
        const std::uint32_t v = p.indices[at];
        if (v >= p.joints.size() || v >= p.weights.size()) continue;
        for (int k = 0; k < 4; ++k) {
            const std::size_t inf = p.joints[v][k];
            if (p.weights[v][k] >= minWeight && inf < p.influences.size() && nodes.count(p.influences[inf].node)) return true;
        }
    }
    return false;
}

std::vector<const std::vector<glm::vec3>*> bindPositions(const Model& m) {
    std::vector<const std::vector<glm::vec3>*> out;
    for (const MeshPart& p : m.parts) out.push_back(&p.positions);
    return out;
}

std::vector<const std::vector<glm::vec3>*> restPositions(const RestSkin& rest) {
    std::vector<const std::vector<glm::vec3>*> out;
    for (const SkinnedPart& p : rest.parts) out.push_back(&p.positions);
    return out;
}

} // namespace dermis
