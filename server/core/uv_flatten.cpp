// Dermis core — flattening surface charts (uv_flatten.hpp): the measures, the sparse solver, and
// the Tutte + ARAP disk flattening (moved here from the default character's generator,
// models/src/uv_atlas*, unchanged in arithmetic so that its output stays bit-identical). LSCM is
// in uv_lscm.cpp.
#include "uv_flatten.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

namespace dermis {

// --- sparse symmetric solver ------------------------------------------------------------------

SparseMatrix SparseMatrix::fromTriplets(int n, std::vector<std::tuple<int, int, double>> trip) {
    std::sort(trip.begin(), trip.end(), [](const auto& a, const auto& b) {
        return std::get<0>(a) != std::get<0>(b) ? std::get<0>(a) < std::get<0>(b)
                                                : std::get<1>(a) < std::get<1>(b);
    });
    SparseMatrix m;
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

void SparseMatrix::mul(const std::vector<double>& x, std::vector<double>& y) const {
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

void conjugateGradient(const SparseMatrix& a, const std::vector<double>& b, std::vector<double>& x,
                       int maxIter, double tol) {
    preconditionedConjugateGradient(a, [](std::size_t) { return 1.0; }, b, x, maxIter, tol);
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

namespace {

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

} // namespace

// --- measures -----------------------------------------------------------------------------------

double signedArea(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    return 0.5 * ((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
}

MapSingularValues mapSingularValues(const glm::dvec3& p0, const glm::dvec3& p1,
                                    const glm::dvec3& p2, const glm::dvec2& u0,
                                    const glm::dvec2& u1, const glm::dvec2& u2) {
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
    return {std::sqrt(s1sq + disc), std::sqrt(std::max(s1sq - disc, 0.0)), det};
}

double conformalDistortion(const glm::vec3& q0, const glm::vec3& q1, const glm::vec3& q2,
                           const glm::dvec2& u0, const glm::dvec2& u1, const glm::dvec2& u2) {
    const MapSingularValues sv = mapSingularValues(glm::dvec3(q0), glm::dvec3(q1), glm::dvec3(q2), u0, u1, u2);
    // max(√x, √1e-30) = √max(x, 1e-30) exactly: σ_min clamped at 1e-15.
    return sv.smax / std::max(sv.smin, std::sqrt(1e-30));
}

// --- Tutte + ARAP -------------------------------------------------------------------------------

std::vector<glm::dvec2> flattenDisk(const ChartMesh& chart,
                                    const std::vector<std::uint32_t>& boundary, std::string& note,
                                    int iterations) {
    const std::size_t nv = chart.positions.size();
    const std::vector<std::uint32_t>& loop = boundary;
    const std::vector<glm::dvec3>& P = chart.positions;
    std::vector<char> onLoop(nv, 0);
    for (std::uint32_t v : loop)
        onLoop[v] = 1;

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
        if (!onLoop[v]) unknown[v] = nu++;
    std::vector<std::set<std::uint32_t>> ring(nv);
    for (const auto& t : chart.triangles)
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
        const SparseMatrix a = SparseMatrix::fromTriplets(nu, trip);
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
    for (const auto& t : chart.triangles)
        total += signedArea(uv[t[0]], uv[t[1]], uv[t[2]]);
    if (total < 0)
        for (auto& p : uv)
            p.x = -p.x;
    auto allPositive = [&](const std::vector<glm::dvec2>& u) {
        for (const auto& t : chart.triangles)
            if (!(signedArea(u[t[0]], u[t[1]], u[t[2]]) > 0.0)) return false;
        return true;
    };
    if (!allPositive(uv)) {
        note = "Tutte embedding flipped";
        return {};
    }

    // ARAP (Liu et al. 2008, local/global) with a flip-free backtracking step.
    const std::size_t nt = chart.triangles.size();
    std::vector<std::array<glm::dvec2, 3>> iso(nt); // isometric local triangle
    std::vector<std::array<double, 3>> cot(nt);     // cot of the angle opposite edge (i, i+1)
    for (std::size_t t = 0; t < nt; ++t) {
        const glm::dvec3 a = P[chart.triangles[t][0]], b = P[chart.triangles[t][1]],
                         c = P[chart.triangles[t][2]];
        const glm::dvec3 e1 = glm::normalize(b - a);
        const glm::dvec3 nrm = glm::normalize(glm::cross(b - a, c - a));
        const glm::dvec3 e2 = glm::cross(nrm, e1);
        iso[t] = {glm::dvec2(0, 0), glm::dvec2(glm::length(b - a), 0),
                  glm::dvec2(glm::dot(c - a, e1), glm::dot(c - a, e2))};
        for (int i = 0; i < 3; ++i) {
            const glm::dvec3 pi = P[chart.triangles[t][i]], pj = P[chart.triangles[t][(i + 1) % 3]],
                             pk = P[chart.triangles[t][(i + 2) % 3]];
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
            const std::uint32_t a = chart.triangles[t][i], b = chart.triangles[t][(i + 1) % 3];
            const double w = cot[t][static_cast<std::size_t>(i)];
            const int ia = idx[a], ib = idx[b];
            if (ia >= 0) trip.emplace_back(ia, ia, w);
            if (ib >= 0) trip.emplace_back(ib, ib, w);
            if (ia >= 0 && ib >= 0) {
                trip.emplace_back(ia, ib, -w);
                trip.emplace_back(ib, ia, -w);
            }
        }
    const SparseMatrix lap = SparseMatrix::fromTriplets(n, trip);
    std::vector<std::vector<std::uint32_t>> vertexTris(nv);
    for (std::size_t t = 0; t < nt; ++t)
        for (int c = 0; c < 3; ++c)
            vertexTris[chart.triangles[t][c]].push_back(static_cast<std::uint32_t>(t));
    std::vector<glm::dvec2> best = uv;
    int accepted = 0;
    for (int iter = 0; iter < iterations; ++iter) {
        // Local step: best rotation per triangle.
        std::vector<glm::dmat2> rot(nt);
        for (std::size_t t = 0; t < nt; ++t) {
            glm::dmat2 s(0.0); // Σ cot · (u_i − u_j)(x_i − x_j)ᵀ, column-major
            for (int i = 0; i < 3; ++i) {
                const int j = (i + 1) % 3;
                const glm::dvec2 du = uv[chart.triangles[t][i]] - uv[chart.triangles[t][j]];
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
                const std::uint32_t a = chart.triangles[t][i], b = chart.triangles[t][j];
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
                        if (!(signedArea(trial[chart.triangles[t][0]], trial[chart.triangles[t][1]],
                                         trial[chart.triangles[t][2]]) > 0.0)) {
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

} // namespace dermis
