#include "edge_aa.hpp"

#include "row_bands.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace dermis {
namespace {

constexpr float kEdgeThreshold = 0.125f;     // relative contrast that makes an edge (FXAA "high")
constexpr float kEdgeThresholdMin = 0.0312f; // absolute contrast below which nothing is an edge
constexpr float kSubpixel = 0.5f;            // strength of the sub-pixel term (FXAA's default 0.75 blurs texture
                                             // detail MSAA keeps: SSIM vs MSAA 4x 0.9961 → 0.9966)
constexpr int kSteps = 10;
constexpr float kStepScale[kSteps] = {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.5f, 2.0f, 2.0f, 4.0f, 8.0f};

/// Luma of every pixel on the encoded values, 0..255 (BT.601 weights, 8-bit fixed point), and
/// clamped lookups in 0..1.
struct LumaImage {
    int w = 0, h = 0;
    std::vector<std::uint8_t> l;
    /// Per row, the first and last x whose luma differs from `flat` (first > last: none).
    std::vector<std::pair<int, int>> spans;
    std::uint8_t flat = 0; ///< the luma of pixel (0, 0): the background's in a rendered frame

    const std::uint8_t* row(int y) const { return l.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(w); }
    float at(int x, int y) const {
        x = std::clamp(x, 0, w - 1);
        y = std::clamp(y, 0, h - 1);
        return row(y)[x] * (1.0f / 255.0f);
    }
    /// Bilinear at (x, y) in pixel units (pixel (i, j)'s centre at (i, j)), clamped at the borders.
    float bilinear(float x, float y) const {
        const float fx = std::floor(x), fy = std::floor(y);
        const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
        const float tx = x - fx, ty = y - fy;
        const float a = at(x0, y0) + (at(x0 + 1, y0) - at(x0, y0)) * tx;
        const float b = at(x0, y0 + 1) + (at(x0 + 1, y0 + 1) - at(x0, y0 + 1)) * tx;
        return a + (b - a) * ty;
    }
};

void computeLuma(const std::vector<std::uint8_t>& rgba, LumaImage& luma, int y0, int y1) {
    const std::size_t n = static_cast<std::size_t>(y1 - y0) * static_cast<std::size_t>(luma.w);
    const std::uint8_t* p = rgba.data() + static_cast<std::size_t>(y0) * static_cast<std::size_t>(luma.w) * 4;
    std::uint8_t* out = luma.l.data() + static_cast<std::size_t>(y0) * static_cast<std::size_t>(luma.w);
    for (std::size_t i = 0; i < n; ++i)
        out[i] = static_cast<std::uint8_t>((77u * p[4 * i] + 150u * p[4 * i + 1] + 29u * p[4 * i + 2] + 128u) >> 8);
}

/// luma.spans of rows [y0, y1) (luma.l and luma.flat set).
void computeSpans(LumaImage& luma, int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
        const std::uint8_t* m = luma.row(y);
        int a = 0, b = luma.w - 1;
        while (a < luma.w && m[a] == luma.flat) ++a;
        while (b > a && m[b] == luma.flat) --b;
        luma.spans[static_cast<std::size_t>(y)] = {a, b};
    }
}

/// A changed pixel: its byte offset and new colour (applied after every band has read `rgba`).
struct Change {
    std::size_t at;
    std::uint8_t rgb[3];
};

/// The pass at pixel (x, y), an edge by the early test: appends its new colour to `changes`.
void edgePixel(const std::vector<std::uint8_t>& rgba, const LumaImage& L, int x, int y,
               std::vector<Change>& changes) {
    const float lM = L.at(x, y);
    const float lN = L.at(x, y - 1), lS = L.at(x, y + 1);
    const float lW = L.at(x - 1, y), lE = L.at(x + 1, y);
    const float range = std::max({lM, lN, lS, lW, lE}) - std::min({lM, lN, lS, lW, lE});
    const float lNW = L.at(x - 1, y - 1), lNE = L.at(x + 1, y - 1);
    const float lSW = L.at(x - 1, y + 1), lSE = L.at(x + 1, y + 1);
    const float lNS = lN + lS, lWE = lW + lE;
    const float lWest = lNW + lSW, lEast = lNE + lSE, lNorth = lNW + lNE, lSouth = lSW + lSE;
    // A horizontal edge changes luma along y: second differences across rows outweigh those
    // across columns.
    const float edgeH = std::abs(-2.0f * lW + lWest) + 2.0f * std::abs(-2.0f * lM + lNS) +
                        std::abs(-2.0f * lE + lEast);
    const float edgeV = std::abs(-2.0f * lN + lNorth) + 2.0f * std::abs(-2.0f * lM + lWE) +
                        std::abs(-2.0f * lS + lSouth);
    const bool horizontal = edgeH >= edgeV;

    // The side the edge lies on: the neighbour across it with the steeper gradient.
    const float l1 = horizontal ? lN : lW, l2 = horizontal ? lS : lE;
    const float g1 = l1 - lM, g2 = l2 - lM;
    const bool side1 = std::abs(g1) >= std::abs(g2);
    const float gradientScaled = 0.25f * std::max(std::abs(g1), std::abs(g2));
    const int step = side1 ? -1 : 1;
    const float half = side1 ? -0.5f : 0.5f;
    const float lLocal = 0.5f * ((side1 ? l1 : l2) + lM);
    const float fx = static_cast<float>(x), fy = static_cast<float>(y);

    // Walk along the edge, half a pixel towards it, both ways until the luma leaves the edge's.
    const float ex = horizontal ? fx : fx + half, ey = horizontal ? fy + half : fy;
    const float ax = horizontal ? 1.0f : 0.0f, ay = horizontal ? 0.0f : 1.0f;
    float p1x = ex - ax, p1y = ey - ay, p2x = ex + ax, p2y = ey + ay;
    float end1 = L.bilinear(p1x, p1y) - lLocal, end2 = L.bilinear(p2x, p2y) - lLocal;
    bool done1 = std::abs(end1) >= gradientScaled, done2 = std::abs(end2) >= gradientScaled;
    if (!done1) p1x -= ax, p1y -= ay;
    if (!done2) p2x += ax, p2y += ay;
    for (int i = 1; i < kSteps && !(done1 && done2); ++i) {
        if (!done1) {
            end1 = L.bilinear(p1x, p1y) - lLocal;
            done1 = std::abs(end1) >= gradientScaled;
            if (!done1) p1x -= ax * kStepScale[i], p1y -= ay * kStepScale[i];
        }
        if (!done2) {
            end2 = L.bilinear(p2x, p2y) - lLocal;
            done2 = std::abs(end2) >= gradientScaled;
            if (!done2) p2x += ax * kStepScale[i], p2y += ay * kStepScale[i];
        }
    }
    const float d1 = horizontal ? fx - p1x : fy - p1y;
    const float d2 = horizontal ? p2x - fx : p2y - fy;
    const bool nearer1 = d1 < d2;
    const float edgeOffset = 0.5f - std::min(d1, d2) / (d1 + d2);
    // Shift only when the luma at the nearer end varies the other way than at the centre.
    const bool centreDarker = lM < lLocal;
    const bool rightWay = ((nearer1 ? end1 : end2) < 0.0f) != centreDarker;
    float offset = rightWay ? edgeOffset : 0.0f;

    // Sub-pixel: how much the centre stands out of its 3×3 average (thin features).
    const float average = (2.0f * (lNS + lWE) + lWest + lEast) / 12.0f;
    const float s = std::clamp(std::abs(average - lM) / range, 0.0f, 1.0f);
    const float s2 = (-2.0f * s + 3.0f) * s * s;
    offset = std::max(offset, s2 * s2 * kSubpixel);
    if (!(offset > 0.0f)) return;

    // The frame sampled `offset` pixels across the edge: a blend with that neighbour.
    const int nx = std::clamp(horizontal ? x : x + step, 0, L.w - 1);
    const int ny = std::clamp(horizontal ? y + step : y, 0, L.h - 1);
    const auto index = [&](int px, int py) {
        return (static_cast<std::size_t>(py) * static_cast<std::size_t>(L.w) + static_cast<std::size_t>(px)) * 4;
    };
    const std::size_t i = index(x, y), j = index(nx, ny);
    Change c{i, {}};
    for (std::size_t k = 0; k < 3; ++k)
        c.rgb[k] = static_cast<std::uint8_t>(std::lround(rgba[i + k] * (1.0f - offset) + rgba[j + k] * offset));
    changes.push_back(c);
}

/// Whether (x, y) is an edge by FXAA's early test: its luma range over itself and its 4
/// neighbours reaches max(kEdgeThresholdMin, kEdgeThreshold · the largest), in 8-bit steps.
inline std::uint8_t isEdge(int m, int n, int s, int w, int e) {
    const int lo = std::min(std::min(std::min(m, n), std::min(s, w)), e);
    const int hi = std::max(std::max(std::max(m, n), std::max(s, w)), e);
    return (hi - lo) * 8 >= std::max(8 * 8, hi); // 8/255 ≈ 0.0312; hi/8 = 0.125·hi
}

/// Rows [y0, y1) of the pass: reads `rgba` and `luma`, appends the changed pixels.
void edgeRows(const std::vector<std::uint8_t>& rgba, const LumaImage& L, int y0, int y1,
              std::vector<Change>& changes) {
    const int w = L.w, h = L.h;
    std::vector<std::uint8_t> flags(static_cast<std::size_t>(w));
    for (int y = y0; y < y1; ++y) {
        const std::uint8_t* __restrict n = L.row(std::max(y - 1, 0));
        const std::uint8_t* __restrict m = L.row(y);
        const std::uint8_t* __restrict s = L.row(std::min(y + 1, h - 1));
        std::uint8_t* __restrict f = flags.data();
        // Outside the spans of this row and the two beside it, widened by a pixel, a pixel and
        // its four neighbours all have the flat luma: no edge there (range 0).
        int x0 = w, x1 = -1;
        for (int r = std::max(y - 1, 0); r <= std::min(y + 1, h - 1); ++r) {
            const auto [a, b] = L.spans[static_cast<std::size_t>(r)];
            if (a > b) continue;
            x0 = std::min(x0, a - 1);
            x1 = std::max(x1, b + 1);
        }
        x0 = std::max(x0, 0);
        x1 = std::min(x1, w - 1);
        if (x0 > x1) continue;
        // The early test over the span's inner pixels without branches (vectorised), then the
        // search at the few edges.
        const int i0 = std::max(x0, 1), i1 = std::min(x1, w - 2);
        for (int x = i0; x <= i1; ++x)
            f[x] = isEdge(m[x], n[x], s[x], m[x - 1], m[x + 1]);
        flags[0] = isEdge(m[0], n[0], s[0], m[0], m[1]);
        flags[static_cast<std::size_t>(w - 1)] = isEdge(m[w - 1], n[w - 1], s[w - 1], m[w - 2], m[w - 1]);
        for (int x = x0; x <= x1; ++x)
            if (flags[static_cast<std::size_t>(x)]) edgePixel(rgba, L, x, y, changes);
    }
}

} // namespace

void antiAliasEdges(Image8& image, int threads) {
    const int w = image.width, h = image.height;
    if (w < 3 || h < 3) return;
    if (image.rgba.size() != static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4) return;
    if (threads <= 0) threads = static_cast<long long>(w) * h < 256 * 256 ? 1 : std::min(2, automaticThreadCount());
    threads = std::clamp(threads, 1, h);
    LumaImage luma;
    luma.w = w;
    luma.h = h;
    luma.l.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    luma.spans.resize(static_cast<std::size_t>(h));
    std::vector<std::vector<Change>> changes(static_cast<std::size_t>(threads));
    forRowBands(h, threads, [&](int, int y0, int y1) { computeLuma(image.rgba, luma, y0, y1); });
    luma.flat = luma.l[0];
    forRowBands(h, threads, [&](int, int y0, int y1) { computeSpans(luma, y0, y1); });
    forRowBands(h, threads, [&](int band, int y0, int y1) {
        edgeRows(image.rgba, luma, y0, y1, changes[static_cast<std::size_t>(band)]);
    });
    for (const std::vector<Change>& band : changes)
        for (const Change& c : band)
            for (std::size_t k = 0; k < 3; ++k) image.rgba[c.at + k] = c.rgb[k];
}

} // namespace dermis
