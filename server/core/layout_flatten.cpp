// Dermis core — the generated layout's flattening (layout_gen_internal.hpp): every chart by
// least-squares conformal maps (core/uv_flatten.hpp) from a projection on its mean plane, scaled
// to its surface area, then checked — genus 0 with boundary, no flipped triangle, boundary loops
// that cross neither themselves nor each other and enclose the chart once (one loop
// counter-clockwise, every other clockwise: with no flip that makes the map one-to-one), area
// stretch bounded — and split in two where a check fails.
#include "layout_gen_internal.hpp"

#include "uv_flatten.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dermis::layout_detail {
namespace {

/// True when two boundary edges cross (edges sharing a vertex are not compared): a sweep over
/// the edges sorted by their smallest x.
bool boundaryCrosses(const LocalChart& lc, const std::vector<glm::dvec2>& uv) {
    const std::size_t n = lc.boundary.size();
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::vector<double> lo(n), hi(n);
    for (std::size_t i = 0; i < n; ++i) {
        lo[i] = std::min(uv[lc.boundary[i][0]].x, uv[lc.boundary[i][1]].x);
        hi[i] = std::max(uv[lc.boundary[i][0]].x, uv[lc.boundary[i][1]].x);
    }
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        return lo[a] != lo[b] ? lo[a] < lo[b] : a < b;
    });
    for (std::size_t i = 0; i < n; ++i) {
        const auto& e = lc.boundary[order[i]];
        const glm::dvec2 a = uv[e[0]], b = uv[e[1]];
        const double ylo = std::min(a.y, b.y), yhi = std::max(a.y, b.y);
        for (std::size_t j = i + 1; j < n && lo[order[j]] <= hi[order[i]]; ++j) {
            const auto& f = lc.boundary[order[j]];
            if (f[0] == e[0] || f[0] == e[1] || f[1] == e[0] || f[1] == e[1]) continue;
            const glm::dvec2 c = uv[f[0]], d = uv[f[1]];
            if (std::max(c.y, d.y) < ylo || std::min(c.y, d.y) > yhi) continue;
            if (segmentsCross(a, b, c, d)) return true;
        }
    }
    return false;
}

/// True when exactly one boundary loop encloses a positive area and every other a negative one.
bool loopsNested(const LocalChart& lc, const std::vector<glm::dvec2>& uv) {
    std::vector<std::int64_t> next(uv.size(), -1);
    for (const auto& e : lc.boundary)
        next[e[0]] = e[1];
    std::vector<char> seen(uv.size(), 0);
    int positive = 0;
    for (const auto& e : lc.boundary) {
        if (seen[e[0]]) continue;
        double area = 0;
        for (std::int64_t v = e[0]; v >= 0 && !seen[static_cast<std::size_t>(v)];
             v = next[static_cast<std::size_t>(v)]) {
            seen[static_cast<std::size_t>(v)] = 1;
            const glm::dvec2 p = uv[static_cast<std::size_t>(v)],
                             q = uv[static_cast<std::size_t>(next[static_cast<std::size_t>(v)])];
            area += p.x * q.y - q.x * p.y;
        }
        if (area > 0)
            ++positive;
        else if (!(area < 0))
            return false;
    }
    return positive == 1;
}

/// Flattens one disk-like chart; false when a check fails.
bool flattenOne(const PartMesh& mesh, const LocalChart& lc, const LayoutGenOptions& options,
                std::vector<glm::dvec2>& uv, double& area) {
    const std::size_t nv = lc.welded.size();
    ChartMesh cm;
    cm.positions.resize(nv);
    for (std::size_t v = 0; v < nv; ++v)
        cm.positions[v] = mesh.positions[lc.welded[v]];
    cm.triangles = lc.local;
    glm::dvec3 sum(0), origin(0);
    area = 0;
    for (std::uint32_t t : lc.tris) {
        sum += mesh.normals[t] * mesh.areas[t];
        area += mesh.areas[t];
    }
    for (const glm::dvec3& p : cm.positions)
        origin += p;
    origin /= static_cast<double>(nv);
    const double sl = glm::length(sum);
    if (!(sl > 0) || !(area > 0)) return false;
    const glm::dvec3 n = sum / sl;
    // A basis of the mean plane, counter-clockwise seen from the normal's side.
    const glm::dvec3 axis =
        std::abs(n.x) <= std::abs(n.y) && std::abs(n.x) <= std::abs(n.z)
            ? glm::dvec3(1, 0, 0)
            : (std::abs(n.y) <= std::abs(n.z) ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1));
    const glm::dvec3 e1 = glm::normalize(glm::cross(axis, n)), e2 = glm::cross(n, e1);
    std::vector<glm::dvec2> proj(nv);
    glm::dvec2 mean(0);
    for (std::size_t v = 0; v < nv; ++v) {
        proj[v] = {glm::dot(cm.positions[v] - origin, e1), glm::dot(cm.positions[v] - origin, e2)};
        mean += proj[v];
    }
    mean /= static_cast<double>(nv);
    if (lc.tris.size() == 1) {
        // Isometric: a, b on the x axis, c above it (positive for any non-degenerate triangle).
        const glm::uvec3& t = lc.local[0];
        const glm::dvec3 a = cm.positions[t[0]], b = cm.positions[t[1]], c = cm.positions[t[2]];
        const double len = glm::length(b - a);
        const glm::dvec3 f1 = (b - a) / len, f2 = glm::cross(mesh.normals[lc.tris[0]], f1);
        uv.assign(nv, glm::dvec2(0));
        uv[t[1]] = {len, 0.0};
        uv[t[2]] = {glm::dot(c - a, f1), glm::dot(c - a, f2)};
        mean = (uv[t[0]] + uv[t[1]] + uv[t[2]]) / 3.0;
    } else {
        // Pins: the extreme vertices along the projection's principal axis.
        double cxx = 0, cxy = 0, cyy = 0;
        for (const glm::dvec2& p : proj) {
            const glm::dvec2 d = p - mean;
            cxx += d.x * d.x;
            cxy += d.x * d.y;
            cyy += d.y * d.y;
        }
        const double ang = 0.5 * std::atan2(2 * cxy, cxx - cyy);
        const glm::dvec2 dir(std::cos(ang), std::sin(ang));
        std::uint32_t pins[2] = {0, 0};
        for (std::uint32_t v = 0; v < nv; ++v) {
            if (glm::dot(proj[v], dir) < glm::dot(proj[pins[0]], dir)) pins[0] = v;
            if (glm::dot(proj[v], dir) > glm::dot(proj[pins[1]], dir)) pins[1] = v;
        }
        if (pins[0] == pins[1]) return false;
        const glm::dvec2 pinUv[2] = {proj[pins[0]], proj[pins[1]]};
        const int maxIter = static_cast<int>(std::min<std::size_t>(4000, 200 + 4 * nv));
        uv = flattenLscm(cm, pins, pinUv, proj, maxIter, 1e-9);
        if (uv.size() != nv) return false;
    }
    double uvArea = 0;
    for (const glm::uvec3& t : lc.local) {
        const double a = signedArea(uv[t[0]], uv[t[1]], uv[t[2]]);
        if (!(a > 0)) return false; // flipped, collapsed or not finite
        uvArea += a;
    }
    // Area-preserving scale, centred on the origin.
    const double k = std::sqrt(area / uvArea);
    for (glm::dvec2& p : uv)
        p = (p - mean) * k;
    if (lc.tris.size() == 1) return true;
    double stretched = 0;
    for (std::size_t i = 0; i < lc.local.size(); ++i) {
        const glm::uvec3& t = lc.local[i];
        const double r = signedArea(uv[t[0]], uv[t[1]], uv[t[2]]) / mesh.areas[lc.tris[i]];
        if (!(r > 0)) return false;
        if (r > options.maxAreaStretch || r * options.maxAreaStretch < 1.0)
            stretched += mesh.areas[lc.tris[i]];
    }
    if (stretched > 0.02 * area) return false;
    return loopsNested(lc, uv) && !boundaryCrosses(lc, uv);
}

} // namespace

void flattenCharts(const PartMesh& mesh, int part, std::vector<std::vector<std::uint32_t>> charts,
                   const LayoutGenOptions& options, std::vector<FlatChart>& out, int& splits) {
    std::vector<int> member(mesh.tris.size(), -1);
    // Depth first, in the given order: a split chart's halves are done before the next chart.
    std::vector<std::vector<std::uint32_t>> stack(std::make_move_iterator(charts.rbegin()),
                                                  std::make_move_iterator(charts.rend()));
    while (!stack.empty()) {
        std::vector<std::uint32_t> tris = std::move(stack.back());
        stack.pop_back();
        if (tris.empty()) continue;
        FlatChart fc;
        fc.part = part;
        fc.chart = buildLocalChart(mesh, tris, member);
        if (fc.chart.isDiskLike() && flattenOne(mesh, fc.chart, options, fc.uv, fc.area)) {
            out.push_back(std::move(fc));
            continue;
        }
        // A single non-degenerate triangle always flattens; anything that fails has ≥ 2.
        auto halves = splitChart(mesh, tris, member);
        ++splits;
        stack.push_back(std::move(halves[1]));
        stack.push_back(std::move(halves[0]));
    }
}

} // namespace dermis::layout_detail
