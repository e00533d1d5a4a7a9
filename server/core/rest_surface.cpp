// Dermis core — the rest-surface map of a texture layout (texture_layout.hpp, SPEC §8 "Surface
// placements"): every texel centre of the layout's UV space → the bind-space point and normal of
// the surface there. Three passes, each split into row bands between threads and each reading
// only what the previous pass finished, so the result does not depend on the thread count:
//   1. rasterise every layout triangle (part, then index order; the later one wins) at the texel
//      centres of the band's rows, interpolating the part's positions and normals;
//   2. per row, the signed column offset of the nearest covered texel within `dilate`;
//   3. per uncovered texel, the nearest covered texel (Euclidean, fixed tie rule) within
//      `dilate`: its position and normal (the gutters), then the tile bounds.
#include "texture_layout.hpp"

#include "heightmap.hpp"
#include "row_bands.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace dermis {

namespace {

/// One layout triangle in texel units (x = u·W, y = v·H; texel (i, j)'s centre at (i+½, j+½)).
struct RasterTriangle {
    glm::dvec2 a, b, c;
    double area2 = 0.0; ///< twice the signed area
    int x0 = 0, x1 = 0, y0 = 0, y1 = 0; ///< texel rectangle [x0, x1) × [y0, y1) it may cover
    const MeshPart* part = nullptr;
    std::uint32_t v[3] = {0, 0, 0}; ///< part vertices of its corners
};

double edge(glm::dvec2 p, glm::dvec2 q, glm::dvec2 r) {
    return (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
}

std::vector<RasterTriangle> rasterTriangles(const Model& model, const TextureLayout& layout, int W,
                                            int H) {
    std::vector<RasterTriangle> out;
    for (std::size_t k = 0; k < layout.parts.size() && k < model.parts.size(); ++k) {
        const PartLayout& pl = layout.parts[k];
        const MeshPart& part = model.parts[k];
        const std::size_t nv = std::min(pl.source.size(), pl.uvs.size());
        for (std::size_t t = 0; t + 2 < pl.indices.size(); t += 3) {
            RasterTriangle r;
            bool ok = true;
            glm::dvec2 corner[3];
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t lv = pl.indices[t + static_cast<std::size_t>(c)];
                if (lv >= nv || pl.source[lv] >= part.positions.size()) {
                    ok = false;
                    break;
                }
                r.v[c] = pl.source[lv];
                const glm::vec2 uv = pl.uvs[lv];
                if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
                    ok = false;
                    break;
                }
                corner[c] = glm::dvec2(static_cast<double>(uv.x) * W, static_cast<double>(uv.y) * H);
            }
            if (!ok) continue;
            r.a = corner[0];
            r.b = corner[1];
            r.c = corner[2];
            r.area2 = edge(r.a, r.b, r.c);
            if (!(std::abs(r.area2) > 1e-12)) continue; // degenerate in UV
            const glm::dvec2 lo = glm::min(r.a, glm::min(r.b, r.c)), hi = glm::max(r.a, glm::max(r.b, r.c));
            // Centres i + ½ within [lo, hi]: i ∈ [ceil(lo − ½), floor(hi − ½)].
            auto clampTo = [](double v, int n) {
                return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(n)));
            };
            r.x0 = clampTo(std::ceil(lo.x - 0.5), W);
            r.x1 = clampTo(std::floor(hi.x - 0.5) + 1.0, W);
            r.y0 = clampTo(std::ceil(lo.y - 0.5), H);
            r.y1 = clampTo(std::floor(hi.y - 0.5) + 1.0, H);
            if (r.x0 >= r.x1 || r.y0 >= r.y1) continue;
            r.part = &part;
            out.push_back(r);
        }
    }
    return out;
}

} // namespace

RestSurfaceMap bakeRestSurface(const Model& model, const TextureLayout& layout, int W, int H,
                               int dilate, int threads) {
    RestSurfaceMap m;
    if (W < 1 || H < 1 || W > kMaxHeightmapSize || H > kMaxHeightmapSize) return m;
    static std::atomic<std::uint64_t> next{1};
    m.contentId = (std::uint64_t{1} << 62) | next.fetch_add(1);
    m.width = W;
    m.height = H;
    const std::size_t n = static_cast<std::size_t>(W) * H;
    m.position.assign(n, glm::vec3(0.0f));
    m.normal.assign(n, glm::vec3(0.0f));
    m.coverage.assign(n, 0);
    if (threads <= 0) threads = automaticThreadCount();
    threads = std::clamp(threads, 1, 64);
    const int bands = std::min(threads, std::max(1, H / 16)); // bands of at least 16 rows
    dilate = std::max(0, dilate);

    // Pass 1: rasterise.
    const std::vector<RasterTriangle> tris = rasterTriangles(model, layout, W, H);
    forRowBands(H, bands, [&](int, int y0, int y1) {
        for (const RasterTriangle& r : tris) {
            const int j0 = std::max(y0, r.y0), j1 = std::min(y1, r.y1);
            if (j0 >= j1) continue;
            const double inv = 1.0 / r.area2;
            const MeshPart& part = *r.part;
            const bool hasNormals = part.normals.size() == part.positions.size();
            const glm::dvec3 p0(part.positions[r.v[0]]), p1(part.positions[r.v[1]]),
                p2(part.positions[r.v[2]]);
            glm::dvec3 face = glm::cross(p1 - p0, p2 - p0);
            const double faceLen = glm::length(face);
            face = faceLen > 0.0 ? face / faceLen : glm::dvec3(0, 0, 1);
            const glm::dvec3 n0 = hasNormals ? glm::dvec3(part.normals[r.v[0]]) : face;
            const glm::dvec3 n1 = hasNormals ? glm::dvec3(part.normals[r.v[1]]) : face;
            const glm::dvec3 n2 = hasNormals ? glm::dvec3(part.normals[r.v[2]]) : face;
            for (int j = j0; j < j1; ++j)
                for (int i = r.x0; i < r.x1; ++i) {
                    const glm::dvec2 p(i + 0.5, j + 0.5);
                    // Barycentrics of the corners; a centre on an edge (to rounding) is inside.
                    double w0 = edge(r.b, r.c, p) * inv, w1 = edge(r.c, r.a, p) * inv;
                    double w2 = 1.0 - w0 - w1;
                    constexpr double kEps = -1e-9;
                    if (w0 < kEps || w1 < kEps || w2 < kEps) continue;
                    w0 = std::max(w0, 0.0);
                    w1 = std::max(w1, 0.0);
                    w2 = std::max(w2, 0.0);
                    const double sum = w0 + w1 + w2;
                    w0 /= sum;
                    w1 /= sum;
                    w2 /= sum;
                    glm::dvec3 nn = w0 * n0 + w1 * n1 + w2 * n2;
                    const double len = glm::length(nn);
                    nn = len > 1e-12 ? nn / len : face;
                    const std::size_t idx = static_cast<std::size_t>(j) * W + i;
                    m.position[idx] = glm::vec3(w0 * p0 + w1 * p1 + w2 * p2);
                    m.normal[idx] = glm::vec3(nn);
                    m.coverage[idx] = 1;
                }
        }
    });

    // Pass 2: per texel, the signed column offset of the nearest covered texel of its row within
    // `dilate` (the left one on a tie); kNone when there is none.
    constexpr int kNone = std::numeric_limits<int>::max();
    std::vector<int> nearestInRow(dilate > 0 ? n : 0, kNone);
    if (dilate > 0)
        forRowBands(H, bands, [&](int, int y0, int y1) {
            for (int j = y0; j < y1; ++j) {
                const std::uint8_t* cov = &m.coverage[static_cast<std::size_t>(j) * W];
                int* out = &nearestInRow[static_cast<std::size_t>(j) * W];
                int last = -1; // the last covered column at or left of i
                for (int i = 0; i < W; ++i) {
                    if (cov[i]) last = i;
                    if (last >= 0 && i - last <= dilate) out[i] = last - i;
                }
                last = -1;
                for (int i = W - 1; i >= 0; --i) {
                    if (cov[i]) last = i;
                    if (last >= 0 && last - i <= dilate && (out[i] == kNone || last - i < -out[i]))
                        out[i] = last - i;
                }
            }
        });

    // Pass 3: the gutters, from pass 1's covered texels only.
    if (dilate > 0)
        forRowBands(H, bands, [&](int, int y0, int y1) {
            const long long limit = static_cast<long long>(dilate) * dilate;
            for (int j = y0; j < y1; ++j)
                for (int i = 0; i < W; ++i) {
                    const std::size_t idx = static_cast<std::size_t>(j) * W + i;
                    if (m.coverage[idx] == 1) continue;
                    long long best = limit + 1;
                    std::size_t from = 0;
                    // Row offsets 0, −1, +1, −2, +2, …: a strictly smaller distance replaces.
                    for (int k = 0; k <= 2 * dilate; ++k) {
                        const int dy = (k + 1) / 2 * (k % 2 ? -1 : 1);
                        const int y = j + dy;
                        if (y < 0 || y >= H) continue;
                        const std::size_t row = static_cast<std::size_t>(y) * W;
                        const int dx = nearestInRow[row + static_cast<std::size_t>(i)];
                        if (dx == kNone) continue;
                        const long long d2 = static_cast<long long>(dx) * dx + static_cast<long long>(dy) * dy;
                        if (d2 < best) {
                            best = d2;
                            from = row + static_cast<std::size_t>(i + dx);
                        }
                    }
                    if (best > limit) continue;
                    m.position[idx] = m.position[from];
                    m.normal[idx] = m.normal[from];
                    m.coverage[idx] = 2;
                }
        });

    // Tile bounds.
    constexpr int T = RestSurfaceMap::kTile;
    m.tilesX = (W + T - 1) / T;
    m.tilesY = (H + T - 1) / T;
    const std::size_t tiles = static_cast<std::size_t>(m.tilesX) * m.tilesY;
    m.tileMin.assign(tiles, glm::vec3(std::numeric_limits<float>::infinity()));
    m.tileMax.assign(tiles, glm::vec3(-std::numeric_limits<float>::infinity()));
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            const std::size_t idx = static_cast<std::size_t>(j) * W + i;
            if (!m.coverage[idx]) continue;
            const std::size_t t = static_cast<std::size_t>(j / T) * m.tilesX + static_cast<std::size_t>(i / T);
            m.tileMin[t] = glm::min(m.tileMin[t], m.position[idx]);
            m.tileMax[t] = glm::max(m.tileMax[t], m.position[idx]);
        }
    return m;
}

} // namespace dermis
