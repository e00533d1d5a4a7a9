// Dermis core — measuring a texture layout (layout_gen.hpp checkTextureLayout): structure, range
// and orientation per triangle; charts as connected pieces; two rasters at the map's resolution —
// texel centres covered (used and overlapping texels) and texels touched at all (conservative:
// the gutters) — and the distortion of the map surface → UV.
#include "layout_gen.hpp"

#include "uv_flatten.hpp"

#include <algorithm>
#include <climits>
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

/// One pass of a 3×3 min (or max) filter, separable, in place (scratch reused).
void filter3(std::vector<int>& a, int n, bool isMin, std::vector<int>& tmp) {
    tmp.resize(a.size());
    auto pick = [isMin](int x, int y) { return isMin ? std::min(x, y) : std::max(x, y); };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t at = static_cast<std::size_t>(j) * static_cast<std::size_t>(n) +
                                   static_cast<std::size_t>(i);
            int v = a[at];
            if (i > 0) v = pick(v, a[at - 1]);
            if (i + 1 < n) v = pick(v, a[at + 1]);
            tmp[at] = v;
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t at = static_cast<std::size_t>(j) * static_cast<std::size_t>(n) +
                                   static_cast<std::size_t>(i);
            int v = tmp[at];
            if (j > 0) v = pick(v, tmp[at - static_cast<std::size_t>(n)]);
            if (j + 1 < n) v = pick(v, tmp[at + static_cast<std::size_t>(n)]);
            a[at] = v;
        }
}

} // namespace

LayoutCheck checkTextureLayout(const Model& model, const TextureLayout& layout, int resolution,
                               int gutterCap) {
    LayoutCheck check;
    const int n = std::max(resolution, 1);
    std::vector<Tri> tris;
    std::vector<std::size_t> parent;
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
            parent.push_back(id);
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t p = point[pl.indices[3 * t + static_cast<std::size_t>(c)]];
                if (firstTri[p] < 0)
                    firstTri[p] = static_cast<std::int64_t>(id);
                else
                    unite(static_cast<std::size_t>(firstTri[p]), id);
            }
        }
    }
    // Dense chart numbers in order of first triangle.
    std::vector<std::int64_t> dense(tris.size(), -1);
    for (std::size_t i = 0; i < tris.size(); ++i) {
        const std::size_t r = find(i);
        if (dense[r] < 0) dense[r] = static_cast<std::int64_t>(check.charts++);
        tris[i].chart = static_cast<std::size_t>(dense[r]);
    }

    // Rasters: centre owner (−1 none) with an overlap flag, touched owner (−1 none, −2 two).
    const std::size_t texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    std::vector<int> centre(texels, -1), touched(texels, -1);
    std::vector<char> overlap(texels, 0);
    for (const Tri& t : tris) {
        glm::dvec2 q[3];
        for (int c = 0; c < 3; ++c)
            q[c] = t.uv[c] * static_cast<double>(n);
        const bool solid = signedArea(q[0], q[1], q[2]) != 0;
        const double ylo = std::min({q[0].y, q[1].y, q[2].y}),
                     yhi = std::max({q[0].y, q[1].y, q[2].y});
        const int j0 = std::clamp(static_cast<int>(std::ceil(ylo)) - 1, 0, n - 1),
                  j1 = std::clamp(static_cast<int>(std::floor(yhi)), 0, n - 1);
        const int id = static_cast<int>(t.chart);
        for (int j = j0; j <= j1; ++j) {
            // Closed texel squares of row j touched: the triangle's x range over the strip
            // [j, j+1] (its corners inside, its edges' crossings of the strip's sides).
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
            const std::size_t row = static_cast<std::size_t>(j) * static_cast<std::size_t>(n);
            for (int i = i0; i <= i1; ++i) {
                int& o = touched[row + static_cast<std::size_t>(i)];
                if (o == -1)
                    o = id;
                else if (o != id)
                    o = -2;
            }
            if (!solid || clo > chi) continue;
            // Texel centres of row j inside (edges included).
            const int c0 = std::max(static_cast<int>(std::ceil(clo - 0.5)), 0),
                      c1 = std::min(static_cast<int>(std::floor(chi - 0.5)), n - 1);
            for (int i = c0; i <= c1; ++i) {
                int& o = centre[row + static_cast<std::size_t>(i)];
                if (o == -1)
                    o = id;
                else if (o != id)
                    overlap[row + static_cast<std::size_t>(i)] = 1;
            }
        }
    }
    for (std::size_t at = 0; at < texels; ++at) {
        check.usedTexels += centre[at] >= 0;
        check.overlapTexels += overlap[at];
    }
    check.usedFraction = static_cast<double>(check.usedTexels) / static_cast<double>(texels);

    // Gutters: the border, then the smallest Chebyshev radius r at which another chart's touched
    // texel appears (min/max chart id filters grown one ring at a time): r − 1 free texels.
    int gutter = std::max(gutterCap, 0);
    bool any = false, twice = false;
    std::vector<int> mn(texels), mx(texels), tmp;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t at = static_cast<std::size_t>(j) * static_cast<std::size_t>(n) +
                                   static_cast<std::size_t>(i);
            mn[at] = touched[at] >= 0 ? touched[at] : INT_MAX;
            mx[at] = touched[at] >= 0 ? touched[at] : -1;
            if (touched[at] == -1) continue;
            any = true;
            twice = twice || touched[at] == -2;
            gutter = std::min({gutter, i, j, n - 1 - i, n - 1 - j});
        }
    if (twice) gutter = 0;
    for (int r = 1; any && r <= gutter; ++r) {
        filter3(mn, n, true, tmp);
        filter3(mx, n, false, tmp);
        bool conflict = false;
        for (std::size_t at = 0; at < texels && !conflict; ++at)
            conflict = touched[at] >= 0 && (mn[at] < touched[at] || mx[at] > touched[at]);
        if (conflict) gutter = r - 1;
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
