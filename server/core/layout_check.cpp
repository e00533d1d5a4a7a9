// Dermis core — measuring a texture layout (layout_gen.hpp checkTextureLayout): structure, range
// and orientation per triangle; charts as connected pieces; two rasters at the map's resolution —
// texel centres covered (used and overlapping texels) and texels touched at all (conservative:
// the gutters) — and the distortion of the map surface → UV.
#include "disjoint_sets.hpp"
#include "layout_gen.hpp"

#include "uv_flatten.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

namespace dermis {
namespace {

struct Tri {
    glm::dvec2 uv[3];
    glm::dvec3 p[3];
    std::size_t chart = 0; ///< union-find root first, then dense chart index
};

/// Calls f(row offset, i0, i1, c0, c1) for every texel row j of an n×n map that triangle t
/// reaches: [i0, i1] the closed texel squares of the row it touches (its x range over the strip
/// [j, j+1]: its corners inside, its edges' crossings of the strip's sides), [c0, c1] the texel
/// centres of the row inside it, edges included (empty, c0 > c1, for a zero-area triangle).
template <class F> void forRows(const Tri& t, int n, F&& f) {
    glm::dvec2 q[3];
    for (int c = 0; c < 3; ++c)
        q[c] = t.uv[c] * static_cast<double>(n);
    const bool solid = signedArea(q[0], q[1], q[2]) != 0;
    const double ylo = std::min({q[0].y, q[1].y, q[2].y}), yhi = std::max({q[0].y, q[1].y, q[2].y});
    const int j0 = std::clamp(static_cast<int>(std::ceil(ylo)) - 1, 0, n - 1),
              j1 = std::clamp(static_cast<int>(std::floor(yhi)), 0, n - 1);
    for (int j = j0; j <= j1; ++j) {
        double xlo = 1e300, xhi = -1e300, clo = 1e300, chi = -1e300;
        for (int e = 0; e < 3; ++e) {
            glm::dvec2 a = q[e], b = q[(e + 1) % 3];
            if (a.y > b.y) std::swap(a, b);
            if (b.y < j || a.y > j + 1) continue;
            if (b.y > a.y) {
                for (double y :
                     {std::clamp<double>(j, a.y, b.y), std::clamp<double>(j + 1, a.y, b.y)}) {
                    const double x = a.x + (b.x - a.x) * ((y - a.y) / (b.y - a.y));
                    xlo = std::min(xlo, x);
                    xhi = std::max(xhi, x);
                }
                const double yc = j + 0.5;
                if (a.y <= yc && yc <= b.y) { // crossing of the centre line
                    const double x = a.x + (b.x - a.x) * ((yc - a.y) / (b.y - a.y));
                    clo = std::min(clo, x);
                    chi = std::max(chi, x);
                }
            } else {
                xlo = std::min({xlo, a.x, b.x});
                xhi = std::max({xhi, a.x, b.x});
            }
        }
        if (xlo > xhi) continue;
        const int i0 = std::clamp(static_cast<int>(std::ceil(xlo)) - 1, 0, n - 1),
                  i1 = std::clamp(static_cast<int>(std::floor(xhi)), 0, n - 1);
        int c0 = 1, c1 = 0;
        if (solid && clo <= chi) {
            c0 = std::max(static_cast<int>(std::ceil(clo - 0.5)), 0);
            c1 = std::min(static_cast<int>(std::floor(chi - 0.5)), n - 1);
        }
        f(static_cast<std::size_t>(j) * static_cast<std::size_t>(n), i0, i1, c0, c1);
    }
}

} // namespace

LayoutCheck checkTextureLayout(const Model& model, const TextureLayout& layout, int resolution,
                               int gutterCap) {
    LayoutCheck check;
    const int n = std::max(resolution, 1);
    std::vector<Tri> tris;
    DisjointSets pieces; // by triangle: those sharing a layout vertex or UV point
    for (std::size_t k = 0; k < layout.parts.size() && k < model.parts.size(); ++k) {
        const PartLayout& pl = layout.parts[k];
        const MeshPart& part = model.parts[k];
        if (pl.indices.empty()) continue;
        const std::size_t nt = pl.indices.size() / 3;
        check.triangles += nt;
        if (pl.indices.size() != part.indices.size() || pl.source.size() != pl.uvs.size()) {
            check.malformed += nt;
            continue;
        }
        // Layout vertices at the same UV point are one point of a chart.
        std::vector<std::uint32_t> order(pl.uvs.size());
        std::iota(order.begin(), order.end(), 0u);
        auto bits = [&](std::uint32_t v) {
            std::uint64_t b = 0;
            std::memcpy(&b, &pl.uvs[v], sizeof b);
            return b;
        };
        std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
            return bits(a) != bits(b) ? bits(a) < bits(b) : a < b;
        });
        std::vector<std::uint32_t> point(pl.uvs.size());
        for (std::size_t i = 0; i < order.size(); ++i)
            point[order[i]] =
                i > 0 && bits(order[i]) == bits(order[i - 1]) ? point[order[i - 1]] : order[i];
        std::vector<std::int64_t> firstTri(pl.uvs.size(), -1);
        for (std::size_t t = 0; t < nt; ++t) {
            Tri tri;
            bool ok = true, inside = true;
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t v = pl.indices[3 * t + static_cast<std::size_t>(c)];
                if (v >= pl.uvs.size() ||
                    pl.source[v] != part.indices[3 * t + static_cast<std::size_t>(c)] ||
                    pl.source[v] >= part.positions.size()) {
                    ok = false;
                    break;
                }
                tri.uv[c] = glm::dvec2(pl.uvs[v]);
                tri.p[c] = glm::dvec3(part.positions[pl.source[v]]);
                if (!(tri.uv[c].x >= 0 && tri.uv[c].x <= 1 && tri.uv[c].y >= 0 && tri.uv[c].y <= 1))
                    inside = false;
            }
            if (!ok) {
                ++check.malformed;
                continue;
            }
            if (!inside) {
                ++check.outside;
                continue;
            }
            if (!(signedArea(tri.uv[0], tri.uv[1], tri.uv[2]) < 0)) ++check.flipped;
            const std::size_t id = tris.size();
            tris.push_back(tri);
            pieces.add();
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t p = point[pl.indices[3 * t + static_cast<std::size_t>(c)]];
                if (firstTri[p] < 0)
                    firstTri[p] = static_cast<std::int64_t>(id);
                else
                    pieces.joinToSmaller(static_cast<std::size_t>(firstTri[p]), id);
            }
        }
    }
    // Dense chart numbers in order of first triangle.
    std::vector<std::int64_t> dense(tris.size(), -1);
    for (std::size_t i = 0; i < tris.size(); ++i) {
        const std::size_t r = pieces.root(i);
        if (dense[r] < 0) dense[r] = static_cast<std::int64_t>(check.charts++);
        tris[i].chart = static_cast<std::size_t>(dense[r]);
    }

    // Two rasters in one buffer of chart ids (−1 none, −2 two charts): texel centres covered
    // (used, overlapping), then closed texel squares touched (the gutters).
    const std::size_t texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    std::vector<int> owner(texels, -1);
    auto claim = [&](std::size_t at, int id) {
        int& o = owner[at];
        if (o == -1) {
            o = id;
            return 1;
        }
        if (o != id && o != -2) {
            o = -2;
            return 2;
        }
        return 0;
    };
    for (int pass = 0; pass < 2; ++pass) {
        for (const Tri& t : tris)
            forRows(t, n, [&](std::size_t row, int i0, int i1, int c0, int c1) {
                if (pass == 0) {
                    for (int i = c0; i <= c1; ++i) {
                        const int r =
                            claim(row + static_cast<std::size_t>(i), static_cast<int>(t.chart));
                        check.usedTexels += r == 1;
                        check.overlapTexels += r == 2;
                    }
                } else {
                    for (int i = i0; i <= i1; ++i)
                        claim(row + static_cast<std::size_t>(i), static_cast<int>(t.chart));
                }
            });
        if (pass == 0) std::fill(owner.begin(), owner.end(), -1);
    }
    check.usedFraction = static_cast<double>(check.usedTexels) / static_cast<double>(texels);

    // Gutters: the border; then, from every touched texel on its chart's edge (an 8-neighbour
    // elsewhere: the nearest texel of another chart is always seen from one), the nearest touched
    // texel of another chart within the best gap so far (Chebyshev distance d: d − 1 free texels).
    int gutter = std::max(gutterCap, 0);
    auto at = [n](int i, int j) {
        return static_cast<std::size_t>(j) * static_cast<std::size_t>(n) +
               static_cast<std::size_t>(i);
    };
    for (int j = 0; j < n && gutter > 0; ++j)
        for (int i = 0; i < n && gutter > 0; ++i) {
            const int id = owner[at(i, j)];
            if (id == -1) continue;
            if (id == -2) {
                gutter = 0;
                break;
            }
            gutter = std::min({gutter, i, j, n - 1 - i, n - 1 - j});
            bool edge = false;
            for (int dj = -1; dj <= 1 && !edge; ++dj)
                for (int di = -1; di <= 1 && !edge; ++di)
                    edge =
                        owner[at(std::clamp(i + di, 0, n - 1), std::clamp(j + dj, 0, n - 1))] != id;
            if (!edge) continue;
            for (int dj = -gutter; dj <= gutter; ++dj) {
                const int y = j + dj;
                if (y < 0 || y >= n) continue;
                for (int di = -gutter; di <= gutter; ++di) {
                    const int x = i + di;
                    if (x < 0 || x >= n) continue;
                    const int o = owner[at(x, y)];
                    if (o != -1 && o != id)
                        gutter = std::min(gutter, std::max(std::abs(di), std::abs(dj)) - 1);
                }
            }
        }
    check.minGutterTexels = gutter;

    // Distortion against the layout's mean density.
    double sum3 = 0, sumUv = 0;
    std::vector<double> chart3(check.charts, 0.0), chartUv(check.charts, 0.0);
    for (const Tri& t : tris) {
        const double a3 = 0.5 * glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
        const double auv = std::abs(signedArea(t.uv[0], t.uv[1], t.uv[2]));
        chart3[t.chart] += a3;
        chartUv[t.chart] += auv;
        if (a3 > 0 && auv > 0) {
            sum3 += a3;
            sumUv += auv;
        }
    }
    if (sum3 > 0 && sumUv > 0) {
        const double mean = sumUv / sum3;
        double stretch = 0, conformal = 0, weight = 0;
        for (const Tri& t : tris) {
            const double a3 = 0.5 * glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
            const double auv = std::abs(signedArea(t.uv[0], t.uv[1], t.uv[2]));
            if (!(a3 > 0 && auv > 0)) continue;
            const double r = auv / a3 / mean;
            const MapSingularValues sv =
                mapSingularValues(t.p[0], t.p[1], t.p[2], t.uv[0], t.uv[1], t.uv[2]);
            if (!(sv.smin > 0) || !std::isfinite(sv.smax)) continue;
            stretch += a3 * std::max(r, 1.0 / r);
            conformal += a3 * sv.smax / sv.smin;
            weight += a3;
        }
        if (weight > 0) {
            check.areaStretch = stretch / weight;
            check.conformal = conformal / weight;
        }
        bool first = true;
        for (std::size_t c = 0; c < check.charts; ++c) {
            if (!(chart3[c] > 1e-9 * sum3) || !(chartUv[c] > 0)) continue;
            const double d = std::sqrt(chartUv[c] / chart3[c] / mean);
            check.chartDensityMin = first ? d : std::min(check.chartDensityMin, d);
            check.chartDensityMax = first ? d : std::max(check.chartDensityMax, d);
            first = false;
        }
    }
    return check;
}

} // namespace dermis
