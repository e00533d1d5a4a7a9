// Dermis core — the generated layout's packing (layout_gen_internal.hpp): each chart turned to
// its smallest bounding box (rotating calipers over its convex hull) and mirrored to v-down, then
// packed on the texel grid at one density (texels per metre), the largest found by bisection:
//   1. boxes (core/uv_pack.hpp skylinePackGrid): a chart of extent w×h texels takes
//      floor(w + 0.05) + 1 × floor(h + 0.05) + 1 cells, centred in them, plus gutterTexels cells
//      on its right and upper side, in a square that starts gutterTexels cells from the border;
//   2. outlines (horizonPack, up to kMaxHorizonCharts charts): the rows each chart touches per
//      column, dropped onto a horizon in any of four quarter turns, from the boxes' density up
//      to 1.3 times it; kept when it reaches a higher density than the boxes.
// Either way every chart has gutterTexels free texels on every side (closed texel squares, with a
// margin for the float rounding of the final UVs).
#include "layout_gen_internal.hpp"

#include "uv_pack.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace dermis::layout_detail {
namespace {

double cross2(const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, without collinear points.
std::vector<glm::dvec2> hull(std::vector<glm::dvec2> p) {
    std::sort(p.begin(), p.end(), [](const glm::dvec2& a, const glm::dvec2& b) {
        return a.x != b.x ? a.x < b.x : a.y < b.y;
    });
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
    double best = -1, bestSide = 0;
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
        // Smallest area; within 0.1 % of it, the smaller longest side (a right triangle sits on
        // a leg, not on its hypotenuse).
        const double area = (hi.x - lo.x) * (hi.y - lo.y);
        const double side = std::max(hi.x - lo.x, hi.y - lo.y);
        if (best < 0 || area < best * (1 - 1e-3) || (area <= best * (1 + 1e-3) && side < bestSide))
            best = std::min(best < 0 ? area : best, area), bestSide = side, dir = d;
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

/// Where a chart goes, in texels: p = origin + linear · uv (uv in metres).
struct Placed {
    glm::dmat2 linear{1.0};
    glm::dvec2 origin{0};
};

/// T^k, T: (x, y) → (−y, x) (a quarter turn counter-clockwise, y up).
glm::dmat2 quarterTurns(int k) {
    const glm::dmat2 turn(0, 1, -1, 0);
    glm::dmat2 m(1.0);
    for (int i = 0; i < k; ++i)
        m = turn * m;
    return m;
}

/// A chart at density s turned by k quarter turns inside its cells: p = origin + linear · uv
/// lies in (0, cells) on both axes.
Placed inCells(const Frame& f, double s, int k, glm::ivec2& cells) {
    const glm::dvec2 ext = f.size * s;
    const glm::dvec2 turned = k % 2 ? glm::dvec2(ext.y, ext.x) : ext;
    cells = {cellsFor(turned.x), cellsFor(turned.y)};
    const glm::dmat2 t = quarterTurns(k);
    static const glm::dvec2 kShift[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}}; // × turned extent
    Placed p;
    p.linear = t * (s * f.m);
    p.origin = t * (-f.lo * s) + kShift[k] * turned + 0.5 * (glm::dvec2(cells) - turned);
    return p;
}

/// The texel rows a chart touches per column (closed texel squares, like checkTextureLayout,
/// with `eps` texels to spare for the float rounding of the final UVs): bottom[i] ≤ row <
/// top[i]; bottom > top where a column is empty.
struct Profile {
    glm::ivec2 cells{0};
    std::vector<int> bottom, top;
};

/// From the chart's boundary edges alone: over a column strip, the extremes of y on the chart
/// lie on its boundary.
Profile profileOf(const FlatChart& chart, const Placed& p, glm::ivec2 cells, double eps) {
    Profile pr;
    pr.cells = cells;
    pr.bottom.assign(static_cast<std::size_t>(cells.x), cells.y);
    pr.top.assign(static_cast<std::size_t>(cells.x), 0);
    for (const auto& e : chart.chart.boundary) {
        glm::dvec2 u = p.origin + p.linear * chart.uv[e[0]],
                   w = p.origin + p.linear * chart.uv[e[1]];
        if (u.x > w.x) std::swap(u, w);
        const int i0 = std::max(static_cast<int>(std::ceil(u.x - eps)) - 1, 0),
                  i1 = std::min(static_cast<int>(std::floor(w.x + eps)), cells.x - 1);
        for (int i = i0; i <= i1; ++i) {
            double ylo, yhi;
            if (w.x > u.x) {
                const double xa = std::clamp<double>(i, u.x, w.x),
                             xb = std::clamp<double>(i + 1, u.x, w.x);
                const double ya = u.y + (w.y - u.y) * ((xa - u.x) / (w.x - u.x)),
                             yb = u.y + (w.y - u.y) * ((xb - u.x) / (w.x - u.x));
                ylo = std::min(ya, yb);
                yhi = std::max(ya, yb);
            } else {
                ylo = std::min(u.y, w.y);
                yhi = std::max(u.y, w.y);
            }
            const auto col = static_cast<std::size_t>(i);
            pr.bottom[col] =
                std::min(pr.bottom[col], std::max(static_cast<int>(std::ceil(ylo - eps)) - 1, 0));
            pr.top[col] = std::max(pr.top[col],
                                   std::min(static_cast<int>(std::floor(yhi + eps)) + 1, cells.y));
        }
    }
    return pr;
}

/// Horizon ("Tetris") packing (Lévy et al. 2002, §6): charts largest first, each dropped onto the
/// horizon — per column the top of what is placed plus the gutter, spread by the gutter
/// sideways — at the column and quarter turn where it rests lowest (its top, then the area it
/// leaves empty under it, then leftmost). Gaps under overhangs are lost, valleys are used.
bool horizonPack(const std::vector<FlatChart>& charts, const std::vector<Frame>& frames,
                 glm::ivec2 degenerateCells, int res, int g, double s, std::vector<Placed>& out,
                 glm::ivec2& degenerateAt, int& degenerateTurns) {
    const std::size_t n = charts.size() + (degenerateCells.x > 0 ? 1 : 0);
    std::vector<double> size(n, 0.0);
    for (std::size_t c = 0; c < charts.size(); ++c)
        size[c] = std::max(frames[c].size.x, frames[c].size.y) * s;
    if (degenerateCells.x > 0) size.back() = std::max(degenerateCells.x, degenerateCells.y);
    std::vector<std::size_t> order(n);
    for (std::size_t i = 0; i < n; ++i)
        order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return size[a] > size[b]; });
    constexpr int kEmpty = std::numeric_limits<int>::max() / 4; // bottom of an empty column
    const double eps = std::max(1e-3, res * 2.5e-7);            // ≈ 4 float ulps of a UV
    std::vector<int> horizon(static_cast<std::size_t>(res), g);
    out.assign(charts.size(), Placed{});
    Profile profiles[4];
    Placed placed[4];
    std::vector<int> windowMax, deque;
    for (std::size_t idx : order) {
        bool found = false;
        int bestTop = 0, bestX = 0, bestY = 0, bestK = 0;
        std::int64_t bestWaste = 0;
        const bool isGrid = idx == charts.size();
        for (int k = 0; k < (isGrid ? 2 : 4); ++k) {
            Profile& pr = profiles[k];
            if (isGrid) {
                pr.cells = k ? glm::ivec2(degenerateCells.y, degenerateCells.x) : degenerateCells;
                pr.bottom.assign(static_cast<std::size_t>(pr.cells.x), 0);
                pr.top.assign(static_cast<std::size_t>(pr.cells.x), pr.cells.y);
            } else {
                glm::ivec2 cells;
                placed[k] = inCells(frames[idx], s, k, cells);
                pr = profileOf(charts[idx], placed[k], cells, eps);
            }
            int height = 0;
            for (int i = 0; i < pr.cells.x; ++i) {
                const auto col = static_cast<std::size_t>(i);
                if (pr.bottom[col] >= pr.top[col])
                    pr.bottom[col] = kEmpty;
                else
                    height = std::max(height, pr.top[col]);
            }
            const int* b = pr.bottom.data();
            int highestBottom = 0;
            for (int i = 0; i < pr.cells.x; ++i)
                if (b[i] != kEmpty) highestBottom = std::max(highestBottom, b[i]);
            // Sliding maximum of the horizon over the chart's width: y ≥ that − highestBottom.
            const int w = pr.cells.x;
            windowMax.assign(static_cast<std::size_t>(res), 0);
            std::size_t head = 0;
            deque.clear();
            for (int x = 0; x < res; ++x) {
                while (deque.size() > head && horizon[static_cast<std::size_t>(deque.back())] <=
                                                  horizon[static_cast<std::size_t>(x)])
                    deque.pop_back();
                deque.push_back(x);
                if (deque[head] <= x - w) ++head;
                if (x >= w - 1)
                    windowMax[static_cast<std::size_t>(x - w + 1)] =
                        horizon[static_cast<std::size_t>(deque[head])];
            }
            for (int x = g; x + pr.cells.x <= res - g; ++x) {
                // The chart rests at y = max(horizon − bottom); give up on x as soon as it would
                // end above the map or above the best top so far.
                const int limit = (found ? std::min(bestTop, res - g) : res - g) - height;
                if (windowMax[static_cast<std::size_t>(x)] - highestBottom > limit) continue;
                const int* h = horizon.data() + x;
                int y = std::numeric_limits<int>::min();
                for (int i0 = 0; i0 < pr.cells.x && y <= limit; i0 += 16) {
                    const int i1 = std::min(i0 + 16, pr.cells.x);
                    for (int i = i0; i < i1; ++i)
                        y = std::max(y, h[i] - b[i]);
                }
                if (y > limit) continue;
                const int top = y + height;
                std::int64_t waste = 0;
                for (int i = 0; i < pr.cells.x; ++i)
                    if (b[i] != kEmpty) waste += y + b[i] - h[i];
                if (!found || top < bestTop || (top == bestTop && waste < bestWaste)) {
                    found = true;
                    bestTop = top;
                    bestWaste = waste;
                    bestX = x;
                    bestY = y;
                    bestK = k;
                }
            }
        }
        if (!found) return false;
        const Profile& pr = profiles[bestK];
        for (int i = 0; i < pr.cells.x; ++i) {
            const auto col = static_cast<std::size_t>(i);
            if (pr.bottom[col] == kEmpty) continue;
            const int h = bestY + pr.top[col] + g;
            for (int j = std::max(bestX + i - g, 0); j <= std::min(bestX + i + g, res - 1); ++j)
                horizon[static_cast<std::size_t>(j)] =
                    std::max(horizon[static_cast<std::size_t>(j)], h);
        }
        if (isGrid) {
            degenerateAt = {bestX, bestY};
            degenerateTurns = bestK;
        } else {
            out[idx] = placed[bestK];
            out[idx].origin += glm::dvec2(bestX, bestY);
        }
    }
    return true;
}

/// Above this many charts only boxes are packed (horizon packing costs charts × width × 4 per
/// density tried; a model in thousands of pieces gains little from outlines).
constexpr std::size_t kMaxHorizonCharts = 3000;

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
    const glm::ivec2 gridCells =
        degenerateCount > 0 ? glm::ivec2(cols + 1, rows + 1) : glm::ivec2(0);

    // 1. Boxes (skylinePackGrid): fast, a density every layout reaches.
    const int side = res - g; // boxes carry their gutter on the right and upper side
    std::vector<GridBox> boxes(charts.size() + (degenerateCount > 0 ? 1 : 0));
    auto tryBoxes = [&](double s) {
        for (std::size_t c = 0; c < charts.size(); ++c) {
            boxes[c] = GridBox{};
            boxes[c].w = cellsFor(frames[c].size.x * s) + g;
            boxes[c].h = cellsFor(frames[c].size.y * s) + g;
        }
        if (degenerateCount > 0) boxes.back() = GridBox{gridCells.x + g, gridCells.y + g};
        return skylinePackGrid(boxes, side, side, true);
    };
    if (side <= g || !tryBoxes(0.0)) return false;
    std::vector<GridBox> bestBoxes = boxes;
    double lo = 0.0, hi = total > 0 ? static_cast<double>(res - 2 * g) / std::sqrt(total) : 0.0;
    for (int it = 0; it < 16 && hi > 0; ++it) {
        const double mid = 0.5 * (lo + hi);
        if (tryBoxes(mid)) {
            lo = mid;
            bestBoxes = boxes;
        } else {
            hi = mid;
        }
    }
    const double boxDensity = lo;

    // 2. Horizon packing of the charts' outlines, from the boxes' density up.
    std::vector<Placed> placed, bestPlaced;
    glm::ivec2 gridAt(0), bestGridAt(0);
    int gridTurns = 0, bestGridTurns = 0;
    double horizonDensity = 0.0;
    if (boxDensity > 0 && charts.size() <= kMaxHorizonCharts) {
        double a = boxDensity, b = boxDensity * 1.3;
        if (horizonPack(charts, frames, gridCells, res, g, a, placed, gridAt, gridTurns)) {
            horizonDensity = a;
            bestPlaced = placed;
            bestGridAt = gridAt;
            bestGridTurns = gridTurns;
            for (int it = 0; it < 7; ++it) {
                const double mid = 0.5 * (a + b);
                if (horizonPack(charts, frames, gridCells, res, g, mid, placed, gridAt,
                                gridTurns)) {
                    a = mid;
                    horizonDensity = mid;
                    bestPlaced = placed;
                    bestGridAt = gridAt;
                    bestGridTurns = gridTurns;
                } else {
                    b = mid;
                }
            }
        }
    }

    packing = Packing{};
    packing.charts.resize(charts.size());
    const double r = static_cast<double>(res);
    if (horizonDensity > boxDensity) {
        packing.texelsPerMetre = horizonDensity;
        for (std::size_t c = 0; c < charts.size(); ++c) {
            packing.charts[c].linear = bestPlaced[c].linear / r;
            packing.charts[c].origin = bestPlaced[c].origin / r;
        }
        if (degenerateCount > 0) {
            packing.degenerateCell = bestGridAt;
            packing.degenerateColumns = bestGridTurns ? rows : cols;
        }
        return true;
    }
    const double s = boxDensity;
    packing.texelsPerMetre = s;
    for (std::size_t c = 0; c < charts.size(); ++c) {
        const GridBox& box = bestBoxes[c];
        glm::ivec2 cells;
        const Placed p = inCells(frames[c], s, box.turned ? 1 : 0, cells);
        packing.charts[c].linear = p.linear / r;
        packing.charts[c].origin = (p.origin + glm::dvec2(g + box.x, g + box.y)) / r;
    }
    if (degenerateCount > 0) {
        const GridBox& box = bestBoxes.back();
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
    if (corner == 0)
        p = {i + shift, static_cast<double>(r)};
    else if (corner == 1)
        p = {i + shift + 0.5, static_cast<double>(r + 1)};
    else
        p = {i + shift + 1.0, static_cast<double>(r)};
    return (glm::dvec2(packing.degenerateCell) + p + 0.25) /
           static_cast<double>(options.resolution);
}

} // namespace dermis::layout_detail
