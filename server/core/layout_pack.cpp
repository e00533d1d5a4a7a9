// Dermis core — the generated layout's packing (layout_gen_internal.hpp): each chart turned to
// its smallest bounding box (rotating calipers over its convex hull), mirrored to v-down, then
// all of them packed on the texel grid (core/uv_pack.hpp skylinePackGrid) at one density, the
// largest that fits (bisection). A chart of extent w×h texels takes floor(w)+1 × floor(h)+1
// cells, centred in them, plus gutterTexels cells on its right and upper side; the packed area
// starts gutterTexels cells from the border, so every chart has that many free texels on every
// side.
#include "layout_gen_internal.hpp"

#include "uv_pack.hpp"

#include <algorithm>
#include <cmath>

namespace dermis::layout_detail {
namespace {

double cross2(const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, without collinear points.
std::vector<glm::dvec2> hull(std::vector<glm::dvec2> p) {
    std::sort(p.begin(), p.end(),
              [](const glm::dvec2& a, const glm::dvec2& b) { return a.x != b.x ? a.x < b.x : a.y < b.y; });
    p.erase(std::unique(p.begin(), p.end()), p.end());
    if (p.size() < 3) return p;
    std::vector<glm::dvec2> h(2 * p.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && cross2(h[k - 2], h[k - 1], p[i]) <= 0)
            --k;
        h[k++] = p[i];
    }
    for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross2(h[k - 2], h[k - 1], p[i]) <= 0)
            --k;
        h[k++] = p[i];
    }
    h.resize(k - 1);
    return h;
}

/// A chart's map to its box frame (metres): q = m·uv, q − lo ∈ [0, size].
struct Frame {
    glm::dmat2 m{1.0};
    glm::dvec2 lo{0}, size{0};
};

Frame frameOf(const std::vector<glm::dvec2>& uv) {
    const std::vector<glm::dvec2> h = hull(uv);
    glm::dvec2 dir(1, 0);
    double best = -1;
    for (std::size_t i = 0; i < h.size(); ++i) {
        const glm::dvec2 e = h[(i + 1) % h.size()] - h[i];
        const double len = glm::length(e);
        if (!(len > 0)) continue;
        const glm::dvec2 d = e / len;
        glm::dvec2 lo(1e300), hi(-1e300);
        for (const glm::dvec2& p : h) {
            const glm::dvec2 q(glm::dot(p, d), d.x * p.y - d.y * p.x);
            lo = glm::min(lo, q);
            hi = glm::max(hi, q);
        }
        const double area = (hi.x - lo.x) * (hi.y - lo.y);
        if (best < 0 || area < best) best = area, dir = d;
    }
    Frame f;
    // Rotation taking dir to +x, then v = −y (front faces read clockwise in (u, v-down) terms).
    f.m = glm::dmat2(dir.x, dir.y, -dir.y, dir.x); // columns: rotation rows (d.x, d.y), (−d.y, d.x)
    f.m = glm::transpose(f.m);
    f.m = glm::dmat2(1, 0, 0, -1) * f.m;
    glm::dvec2 lo(1e300), hi(-1e300);
    for (const glm::dvec2& p : uv) {
        const glm::dvec2 q = f.m * p;
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    }
    f.lo = lo;
    f.size = hi - lo;
    return f;
}

/// Cells for an extent of `extent` texels: at least 0.05 texel to spare, so that the chart,
/// centred, stays clear of the cell borders by more than any float rounding.
int cellsFor(double extent) {
    return static_cast<int>(std::floor(extent + 0.05)) + 1;
}

} // namespace

bool packCharts(const std::vector<FlatChart>& charts, std::size_t degenerateCount,
                const LayoutGenOptions& options, Packing& packing) {
    const int res = options.resolution, g = options.gutterTexels;
    std::vector<Frame> frames(charts.size());
    double total = 0;
    for (std::size_t c = 0; c < charts.size(); ++c) {
        frames[c] = frameOf(charts[c].uv);
        total += charts[c].area;
    }
    int cols = 0, rows = 0;
    if (degenerateCount > 0) {
        cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(degenerateCount))));
        rows = static_cast<int>((degenerateCount + static_cast<std::size_t>(cols) - 1) /
                                static_cast<std::size_t>(cols));
    }
    const int side = res - g; // boxes carry their gutter on the right and upper side
    std::vector<GridBox> boxes(charts.size() + (degenerateCount > 0 ? 1 : 0));
    auto tryPack = [&](double s) {
        for (std::size_t c = 0; c < charts.size(); ++c) {
            boxes[c] = GridBox{};
            boxes[c].w = cellsFor(frames[c].size.x * s) + g;
            boxes[c].h = cellsFor(frames[c].size.y * s) + g;
        }
        if (degenerateCount > 0) boxes.back() = GridBox{cols + 1 + g, rows + 1 + g};
        return skylinePackGrid(boxes, side, side, true);
    };
    if (side <= g || !tryPack(0.0)) return false;
    std::vector<GridBox> best = boxes;
    double lo = 0.0, hi = total > 0 ? static_cast<double>(res - 2 * g) / std::sqrt(total) : 0.0;
    if (hi > 0 && tryPack(hi)) {
        lo = hi;
        best = boxes;
    } else {
        for (int it = 0; it < 22 && hi > 0; ++it) {
            const double mid = 0.5 * (lo + hi);
            if (tryPack(mid)) {
                lo = mid;
                best = boxes;
            } else {
                hi = mid;
            }
        }
    }
    const double s = lo;
    packing = Packing{};
    packing.texelsPerMetre = s;
    packing.charts.resize(charts.size());
    const glm::dmat2 turn(0, 1, -1, 0); // (x, y) → (−y, x)
    for (std::size_t c = 0; c < charts.size(); ++c) {
        const Frame& f = frames[c];
        const GridBox& box = best[c];
        const glm::dvec2 extent = f.size * s;
        glm::dmat2 lin = s * f.m;
        glm::dvec2 origin = -f.lo * s; // box frame: [0, extent]
        glm::dvec2 ext = extent;
        if (box.turned) {
            lin = turn * lin;
            origin = turn * origin + glm::dvec2(extent.y, 0.0);
            ext = {extent.y, extent.x};
        }
        const glm::dvec2 cells(cellsFor(box.turned ? extent.y : extent.x),
                               cellsFor(box.turned ? extent.x : extent.y));
        origin += glm::dvec2(g + box.x, g + box.y) + 0.5 * (cells - ext);
        packing.charts[c].linear = lin / static_cast<double>(res);
        packing.charts[c].origin = origin / static_cast<double>(res);
    }
    if (degenerateCount > 0) {
        const GridBox& box = best.back();
        packing.degenerateCell = {g + box.x, g + box.y};
        packing.degenerateColumns = box.turned ? rows : cols;
    }
    return true;
}

glm::dvec2 degenerateUv(const Packing& packing, const LayoutGenOptions& options, std::size_t cell,
                        int corner) {
    // Cell (i, r) is the triangle L(i, r), L(i + r mod 2, r + 1), L(i + 1, r) of the lattice
    // L(i, r) = (i + ½ (r mod 2), r) + ¼: one texel wide and high, clockwise in (u, v-down)
    // terms like every front face of the layout, sharing its corners with its neighbours (one
    // connected piece, so the gutter rule holds around the grid, not between its cells).
    const auto cols = static_cast<std::size_t>(std::max(packing.degenerateColumns, 1));
    const auto i = static_cast<double>(cell % cols);
    const std::size_t r = cell / cols;
    const double shift = 0.5 * static_cast<double>(r % 2);
    glm::dvec2 p;
    if (corner == 0) p = {i + shift, static_cast<double>(r)};
    else if (corner == 1) p = {i + shift + 0.5, static_cast<double>(r + 1)};
    else p = {i + shift + 1.0, static_cast<double>(r)};
    return (glm::dvec2(packing.degenerateCell) + p + 0.25) / static_cast<double>(options.resolution);
}

} // namespace dermis::layout_detail
