// LayoutGenTest — the generated height-map layout (core generateTextureLayout, SPEC §8
// `uv_layout: generated`), checked here by the test's own rasterization rather than the core's
// checkTextureLayout (which is compared with it): on hand-built meshes (a cube welded and split by
// face, an open cylinder and a UV sphere welded and split at their UV seams, a grid with a
// repeated-vertex and a zero-area triangle) and on the real models (the built-in default
// character, tests/models' CesiumMan, RiggedFigure without UVs and the KayKit Barbarian with its
// props): the layout's structure (triangle order, `source` the part's corners), every UV in
// [0,1]², no flipped triangle, 0 texels of a 1024² map covered by two triangles, ≥ 4 free texels
// (the default gutter) between texels touched by different charts and along the border, area
// stretch and chart density near the layout's mean, byte-identical output for the same input.
// Also where charts split (UV seams, creases), a triangle soup that fits and one that cannot get
// its gutters, another resolution and gutter, the core's LSCM and grid packing on their own, and
// the refusals. Loads glTF through io (no GL).
#include "BuildPaths.hpp"
#include "core/layout_gen.hpp"
#include "core/uv_flatten.hpp"
#include "core/uv_pack.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <numeric>
#include <string>
#include <vector>

using namespace dermis;

namespace {

const std::string kTestModels = std::string(dermis::build::testModelsDir()) + "/";
constexpr int kRes = 1024;
constexpr double kPi = 3.14159265358979323846;

// --- hand-built meshes ---------------------------------------------------------------------------

Model modelOf(MeshPart part) {
    Model m;
    part.normals = computeNormals(part.positions, part.indices);
    m.parts.push_back(std::move(part));
    return m;
}

/// A unit cube, counter-clockwise outside: 8 shared vertices, or 4 per face with per-face UVs.
MeshPart cube(bool split) {
    MeshPart p;
    const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                             {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    auto corner = [](int i) { return glm::vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1); };
    if (!split)
        for (int i = 0; i < 8; ++i)
            p.positions.push_back(corner(i));
    for (const auto& f : faces) {
        std::uint32_t q[4];
        for (int k = 0; k < 4; ++k) {
            if (split) {
                q[k] = static_cast<std::uint32_t>(p.positions.size());
                p.positions.push_back(corner(f[k]));
                p.uvs.emplace_back(k == 1 || k == 2 ? 1.0f : 0.0f, k >= 2 ? 1.0f : 0.0f);
            } else {
                q[k] = static_cast<std::uint32_t>(f[k]);
            }
        }
        p.indices.insert(p.indices.end(), {q[0], q[2], q[1], q[0], q[3], q[2]});
    }
    return p;
}

/// Orientation fix-up: flips any triangle whose normal points toward `centre` (or, `radialOnly`,
/// toward the y axis through it), so hand-built triangles face outward.
void faceOutward(MeshPart& p, const glm::vec3& centre, bool radialOnly) {
    for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
        const glm::vec3 a = p.positions[p.indices[t]], b = p.positions[p.indices[t + 1]],
                        c = p.positions[p.indices[t + 2]];
        glm::vec3 out = (a + b + c) / 3.0f - centre;
        if (radialOnly) out.y = 0;
        if (glm::dot(glm::cross(b - a, c - a), out) < 0)
            std::swap(p.indices[t + 1], p.indices[t + 2]);
    }
}

/// An open cylinder (radius 0.1, height 0.5, 32 × 8 quads); `split` duplicates the seam column
/// with u = 0 and u = 1, as glTF exporters do.
MeshPart cylinder(bool split) {
    MeshPart p;
    const int seg = 32, rings = 8, cols = split ? seg + 1 : seg;
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s < cols; ++s) {
            const double a = 2 * kPi * s / seg;
            p.positions.emplace_back(0.1 * std::cos(a), 0.5 * r / rings, 0.1 * std::sin(a));
            if (split)
                p.uvs.emplace_back(static_cast<float>(s) / seg, static_cast<float>(r) / rings);
        }
    auto v = [&](int r, int s) {
        return static_cast<std::uint32_t>(r * cols + (split ? s : s % seg));
    };
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < seg; ++s)
            p.indices.insert(p.indices.end(), {v(r, s), v(r + 1, s), v(r, s + 1), v(r, s + 1),
                                               v(r + 1, s), v(r + 1, s + 1)});
    faceOutward(p, glm::vec3(0), true);
    return p;
}

/// A UV sphere (radius 0.3, 32 × 16); `split`: a seam column and a pole vertex per segment.
MeshPart sphere(bool split) {
    MeshPart p;
    const int seg = 32, rings = 16;
    std::vector<std::vector<std::uint32_t>> id(static_cast<std::size_t>(rings + 1));
    for (int r = 0; r <= rings; ++r) {
        const double th = kPi * r / rings;
        const bool pole = r == 0 || r == rings;
        for (int s = 0; s <= seg; ++s) {
            auto& row = id[static_cast<std::size_t>(r)];
            if (!split && (s == seg || (pole && s > 0))) { // welded: the seam and the poles shared
                row.push_back(row[0]);
                continue;
            }
            const double a = 2 * kPi * s / seg;
            row.push_back(static_cast<std::uint32_t>(p.positions.size()));
            p.positions.emplace_back(0.3 * std::sin(th) * std::cos(a), 0.3 * std::cos(th),
                                     0.3 * std::sin(th) * std::sin(a));
            if (split)
                p.uvs.emplace_back((s + (pole ? 0.5f : 0.0f)) / seg, static_cast<float>(r) / rings);
        }
    }
    auto v = [&](int r, int s) {
        return id[static_cast<std::size_t>(r)][static_cast<std::size_t>(s)];
    };
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < seg; ++s) {
            if (r > 0) p.indices.insert(p.indices.end(), {v(r, s), v(r, s + 1), v(r + 1, s)});
            if (r + 1 < rings)
                p.indices.insert(p.indices.end(), {v(r, s + 1), v(r + 1, s + 1), v(r + 1, s)});
        }
    faceOutward(p, glm::vec3(0), false);
    return p;
}

/// A flat 6 × 6 grid of quads (1 m²) plus a triangle with a repeated vertex and a zero-area one.
MeshPart gridWithDegenerates() {
    MeshPart p;
    const int n = 6;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            p.positions.emplace_back(static_cast<float>(i) / n, static_cast<float>(j) / n, 0.0f);
    auto v = [&](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            p.indices.insert(p.indices.end(), {v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j),
                                               v(i + 1, j + 1), v(i, j + 1)});
    p.indices.insert(p.indices.end(), {v(2, 2), v(2, 2), v(3, 3)}); // repeated vertex
    const auto mid = static_cast<std::uint32_t>(p.positions.size());
    p.positions.emplace_back(0.5f / n, 0.0f, 0.0f);             // on the edge v(0,0)–v(1,0)
    p.indices.insert(p.indices.end(), {v(0, 0), mid, v(1, 0)}); // zero area
    return p;
}

// --- the test's own checks
// -------------------------------------------------------------------------

struct UvTri {
    glm::dvec2 q[3]; ///< texel units at kRes
    glm::dvec3 p[3];
    std::size_t chart = 0;
};

/// Checks the structure of `layout` against `model` and collects its triangles (texel units)
/// with charts = pieces sharing a UV point (exact float) within a part.
std::vector<UvTri> collect(const Model& model, const TextureLayout& layout, std::size_t& charts) {
    std::vector<UvTri> out;
    std::vector<std::size_t> parent;
    std::function<std::size_t(std::size_t)> find = [&](std::size_t x) {
        return parent[x] == x ? x : parent[x] = find(parent[x]);
    };
    EXPECT_EQ(layout.kind, "generated");
    EXPECT_EQ(layout.parts.size(), model.parts.size());
    for (std::size_t k = 0; k < model.parts.size() && k < layout.parts.size(); ++k) {
        const MeshPart& part = model.parts[k];
        const PartLayout& pl = layout.parts[k];
        EXPECT_EQ(pl.indices.size(), part.indices.size()) << "part " << k;
        EXPECT_EQ(pl.source.size(), pl.uvs.size()) << "part " << k;
        if (pl.indices.size() != part.indices.size()) continue;
        std::vector<std::pair<std::uint64_t, std::size_t>> points; // UV bits → triangle
        for (std::size_t t = 0; t < part.indices.size() / 3; ++t) {
            UvTri tri;
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t lv = pl.indices[3 * t + static_cast<std::size_t>(c)];
                if (lv >= pl.uvs.size() ||
                    pl.source[lv] != part.indices[3 * t + static_cast<std::size_t>(c)]) {
                    ADD_FAILURE() << "part " << k << " triangle " << t << ": layout vertex " << lv
                                  << " out of range or not the part's corner";
                    return {};
                }
                const glm::vec2 uv = pl.uvs[lv];
                EXPECT_TRUE(uv.x >= 0 && uv.x <= 1 && uv.y >= 0 && uv.y <= 1)
                    << "part " << k << " triangle " << t << ": " << uv.x << ", " << uv.y;
                tri.q[c] = glm::dvec2(uv) * static_cast<double>(kRes);
                tri.p[c] = glm::dvec3(part.positions[pl.source[lv]]);
                std::uint64_t bits = 0;
                std::memcpy(&bits, &uv, sizeof bits);
                points.push_back({bits, out.size()});
            }
            // Front faces read clockwise in (u, v-down) terms: negative area.
            EXPECT_LT(signedArea(tri.q[0], tri.q[1], tri.q[2]), 0.0)
                << "flipped: part " << k << " triangle " << t;
            parent.push_back(out.size());
            out.push_back(tri);
        }
        std::sort(points.begin(), points.end());
        for (std::size_t i = 1; i < points.size(); ++i)
            if (points[i].first == points[i - 1].first) {
                const std::size_t a = find(points[i].second), b = find(points[i - 1].second);
                if (a != b) parent[std::max(a, b)] = std::min(a, b);
            }
    }
    std::vector<std::size_t> dense(out.size(), SIZE_MAX);
    charts = 0;
    for (std::size_t i = 0; i < out.size(); ++i) {
        const std::size_t r = find(i);
        if (dense[r] == SIZE_MAX) dense[r] = charts++;
        out[i].chart = dense[r];
    }
    return out;
}

/// Texels a segment passes through (grid walk, both ends included).
template <class F> void walkSegment(glm::dvec2 a, glm::dvec2 b, F&& mark) {
    const int steps =
        4 * static_cast<int>(std::ceil(std::max(std::abs(b.x - a.x), std::abs(b.y - a.y)))) + 1;
    for (int s = 0; s <= steps; ++s) {
        const glm::dvec2 p = a + (b - a) * (static_cast<double>(s) / steps);
        mark(static_cast<int>(std::floor(p.x)), static_cast<int>(std::floor(p.y)));
    }
}

struct RasterFigures {
    std::int64_t used = 0, overlap = 0;
    int gutter = 0; ///< fewest free texels found between charts or to the border (≤ 8 looked at)
};

/// Texel centres strictly inside triangles (used, and covered twice: overlap — any two triangles,
/// same chart or not), and texels touched (edges walked at ¼ texel, centres inside) per chart:
/// the smallest free gap between two charts' texels or a texel and the border.
RasterFigures raster(const std::vector<UvTri>& tris) {
    RasterFigures f;
    const auto texels = static_cast<std::size_t>(kRes) * kRes;
    std::vector<std::uint8_t> count(texels, 0);
    std::vector<std::int64_t> owner(texels, -1);
    f.gutter = 8;
    bool twoCharts = false;
    auto touch = [&](int i, int j, std::size_t chart) {
        if (i < 0 || j < 0 || i >= kRes || j >= kRes) {
            f.gutter = -1;
            return;
        }
        f.gutter = std::min({f.gutter, i, j, kRes - 1 - i, kRes - 1 - j});
        std::int64_t& o = owner[static_cast<std::size_t>(j) * kRes + static_cast<std::size_t>(i)];
        if (o >= 0 && o != static_cast<std::int64_t>(chart)) twoCharts = true;
        o = static_cast<std::int64_t>(chart);
    };
    for (const UvTri& t : tris) {
        for (int e = 0; e < 3; ++e)
            walkSegment(t.q[e], t.q[(e + 1) % 3], [&](int i, int j) { touch(i, j, t.chart); });
        const glm::dvec2 lo = glm::min(t.q[0], glm::min(t.q[1], t.q[2])),
                         hi = glm::max(t.q[0], glm::max(t.q[1], t.q[2]));
        for (int j = std::max(0, static_cast<int>(lo.y));
             j <= std::min(kRes - 1, static_cast<int>(hi.y)); ++j)
            for (int i = std::max(0, static_cast<int>(lo.x));
                 i <= std::min(kRes - 1, static_cast<int>(hi.x)); ++i) {
                const glm::dvec2 c(i + 0.5, j + 0.5);
                // Clockwise triangles: the centre is inside when every edge sees it on its right.
                if (signedArea(t.q[0], t.q[1], c) < 0 && signedArea(t.q[1], t.q[2], c) < 0 &&
                    signedArea(t.q[2], t.q[0], c) < 0) {
                    std::uint8_t& n =
                        count[static_cast<std::size_t>(j) * kRes + static_cast<std::size_t>(i)];
                    if (n == 1) ++f.overlap;
                    if (n == 0) ++f.used;
                    n = static_cast<std::uint8_t>(std::min(n + 1, 2));
                    touch(i, j, t.chart);
                }
            }
    }
    if (twoCharts) f.gutter = 0;
    for (int j = 0; j < kRes && f.gutter > 0; ++j)
        for (int i = 0; i < kRes; ++i) {
            const std::int64_t o =
                owner[static_cast<std::size_t>(j) * kRes + static_cast<std::size_t>(i)];
            if (o < 0) continue;
            for (int dj = -f.gutter; dj <= f.gutter; ++dj)
                for (int di = -f.gutter; di <= f.gutter; ++di) {
                    const int x = i + di, y = j + dj;
                    if (x < 0 || y < 0 || x >= kRes || y >= kRes) continue;
                    const std::int64_t p =
                        owner[static_cast<std::size_t>(y) * kRes + static_cast<std::size_t>(x)];
                    if (p >= 0 && p != o)
                        f.gutter = std::min(f.gutter, std::max(std::abs(di), std::abs(dj)) - 1);
                }
        }
    return f;
}

/// Generates the layout twice (byte-identical), checks everything, returns the first.
GeneratedLayout expectGoodLayout(const Model& model, const std::string& what) {
    auto a = generateTextureLayoutWithReport(model);
    EXPECT_TRUE(a) << what << ": " << (a ? "" : a.error().message);
    if (!a) return {};
    auto b = generateTextureLayout(model);
    EXPECT_TRUE(b) << what;
    if (b) {
        EXPECT_EQ(a->layout.parts.size(), b->parts.size());
        for (std::size_t k = 0; k < a->layout.parts.size() && k < b->parts.size(); ++k) {
            const PartLayout &x = a->layout.parts[k], &y = b->parts[k];
            EXPECT_EQ(x.source, y.source) << what << " part " << k;
            EXPECT_EQ(x.indices, y.indices) << what << " part " << k;
            EXPECT_TRUE(x.uvs.size() == y.uvs.size() &&
                        std::memcmp(x.uvs.data(), y.uvs.data(), x.uvs.size() * sizeof(glm::vec2)) ==
                            0)
                << what << " part " << k << ": UVs differ between runs";
        }
    }
    std::size_t charts = 0;
    const std::vector<UvTri> tris = collect(model, a->layout, charts);
    EXPECT_EQ(tris.size(), model.triangleCount()) << what;
    const RasterFigures f = raster(tris);
    EXPECT_EQ(f.overlap, 0) << what;
    EXPECT_GE(f.gutter, 4) << what;
    // The core's own measure agrees.
    const LayoutCheck& c = a->check;
    EXPECT_EQ(c.triangles, model.triangleCount()) << what;
    EXPECT_EQ(c.malformed + c.outside + c.flipped, 0u) << what;
    EXPECT_EQ(c.overlapTexels, 0) << what;
    EXPECT_GE(c.minGutterTexels, 4) << what;
    EXPECT_EQ(c.charts, charts) << what;
    EXPECT_EQ(c.charts, a->charts + (a->degenerate > 0 ? 1 : 0)) << what;
    EXPECT_NEAR(c.usedFraction, static_cast<double>(f.used) / (double(kRes) * kRes), 0.01) << what;
    // Distortion: area stretch (test's own) and chart densities near the mean.
    double s3 = 0, suv = 0;
    std::vector<double> c3(charts, 0), cuv(charts, 0);
    for (const UvTri& t : tris) {
        const double a3 = 0.5 * glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
        const double auv = -signedArea(t.q[0], t.q[1], t.q[2]);
        s3 += a3;
        suv += auv;
        c3[t.chart] += a3;
        cuv[t.chart] += auv;
    }
    double stretch = 0, weight = 0;
    for (const UvTri& t : tris) {
        const double a3 = 0.5 * glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
        if (!(a3 > 1e-12)) continue;
        const double r = (-signedArea(t.q[0], t.q[1], t.q[2]) / a3) / (suv / s3);
        stretch += a3 * std::max(r, 1 / r);
        weight += a3;
    }
    EXPECT_LT(stretch / weight, 1.15) << what;
    EXPECT_NEAR(c.areaStretch, stretch / weight, 1e-6) << what;
    for (std::size_t k = 0; k < charts; ++k)
        if (c3[k] > 1e-4 * s3)
            EXPECT_NEAR(std::sqrt(cuv[k] / c3[k] / (suv / s3)), 1.0, 0.02)
                << what << " chart " << k;
    EXPECT_GT(c.usedFraction, 0.3) << what;
    return std::move(*a);
}

Model loadModel(const std::string& path) {
    auto m = loadGltfFile(path);
    EXPECT_TRUE(m) << path << ": " << (m ? "" : m.error().message);
    return m ? std::move(*m) : Model{};
}

// --- tests
// ------------------------------------------------------------------------------------------

TEST(LayoutGenTest, CubeWeldedAndSplitGetOneChartPerFace) {
    const GeneratedLayout welded = expectGoodLayout(modelOf(cube(false)), "welded cube");
    EXPECT_EQ(welded.charts, 6u); // 90° creases
    const GeneratedLayout split = expectGoodLayout(modelOf(cube(true)), "split cube");
    EXPECT_EQ(split.charts, 6u);
    // Six equal squares at one density: the same area each.
    EXPECT_EQ(welded.check.chartDensityMin, welded.check.chartDensityMin);
    EXPECT_NEAR(welded.check.areaStretch, 1.0, 1e-3);
}

TEST(LayoutGenTest, CylinderAndSphereWeldedAndSplit) {
    for (bool split : {false, true}) {
        const std::string s = split ? " (split at the UV seam)" : " (welded)";
        const GeneratedLayout cyl = expectGoodLayout(modelOf(cylinder(split)), "cylinder" + s);
        EXPECT_GE(cyl.charts, 3u); // a 60° cone cannot hold a whole tube
        EXPECT_LE(cyl.charts, 8u);
        EXPECT_LT(cyl.check.areaStretch, 1.01); // developable
        const GeneratedLayout sph = expectGoodLayout(modelOf(sphere(split)), "sphere" + s);
        EXPECT_GE(sph.charts, 4u);
        EXPECT_LE(sph.charts, 40u);
    }
}

TEST(LayoutGenTest, DegenerateTrianglesGetCellsOfTheirOwn) {
    const Model m = modelOf(gridWithDegenerates());
    const GeneratedLayout g = expectGoodLayout(m, "grid with degenerate triangles");
    EXPECT_EQ(g.degenerate, 2u);
    EXPECT_EQ(g.charts, 1u); // the flat grid
}

TEST(LayoutGenTest, ChartsSplitAtTheModelsUvSeams) {
    // Two triangles of a flat square: one chart when their UVs agree on the diagonal, two when
    // the second triangle's UVs are elsewhere (a seam).
    MeshPart p;
    p.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 0}};
    p.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}, {1, 0}, {0, 1}};
    p.indices = {0, 1, 2, 5, 4, 3};
    EXPECT_EQ(expectGoodLayout(modelOf(p), "square, no seam").charts, 1u);
    p.uvs[4] = {0.5f, 0.5f};
    EXPECT_EQ(expectGoodLayout(modelOf(p), "square, UV seam").charts, 2u);
    // A face whose UVs collapse to a point (a palette swatch) makes no seam.
    p.uvs[3] = p.uvs[4] = p.uvs[5] = {0.5f, 0.5f};
    EXPECT_EQ(expectGoodLayout(modelOf(p), "square, palette UVs").charts, 1u);
    // Without UVs, split vertices are welded by position: one chart.
    p.uvs.clear();
    EXPECT_EQ(expectGoodLayout(modelOf(p), "square, no UVs").charts, 1u);
}

TEST(LayoutGenTest, NonManifoldAndMisorientedEdgesAreChartBorders) {
    // Three triangles on one edge (a fin), and a pair whose shared edge runs the same way in
    // both (one of them flipped): each triangle its own chart; a single triangle on its own.
    MeshPart p;
    p.positions = {{0, 0, 0}, {1, 0, 0}, {0.5f, 1, 0}, {0.5f, -1, 0}, {0.5f, 0, 1},
                   {3, 0, 0}, {4, 0, 0}, {3.5f, 1, 0}, {3.5f, -1, 0}};
    p.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4, 5, 6, 7, 5, 6, 8};
    const GeneratedLayout g = expectGoodLayout(modelOf(p), "fin and misoriented pair");
    EXPECT_EQ(g.charts, 5u);
    MeshPart one;
    one.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    one.indices = {0, 1, 2};
    EXPECT_EQ(expectGoodLayout(modelOf(one), "one triangle").charts, 1u);
}

TEST(LayoutGenTest, DefaultCharacter) {
    const Model m = loadModel(resolveModelPath("builtin:default", "", dermis::build::sourceDir()));
    const GeneratedLayout g = expectGoodLayout(m, "default character");
    EXPECT_GE(g.check.usedFraction, 0.4);
}

TEST(LayoutGenTest, CesiumMan) {
    expectGoodLayout(loadModel(kTestModels + "CesiumMan/CesiumMan.glb"), "CesiumMan");
}

TEST(LayoutGenTest, RiggedFigureWithoutUvs) {
    const Model m = loadModel(kTestModels + "RiggedFigure/RiggedFigure.glb");
    EXPECT_FALSE(m.hasUVs());
    expectGoodLayout(m, "RiggedFigure");
}

TEST(LayoutGenTest, BarbarianWithPropsSharesOneSquare) {
    const Model m = loadModel(kTestModels + "KayKitBarbarian/Barbarian.glb");
    ASSERT_GT(m.parts.size(), 5u);
    const GeneratedLayout g = expectGoodLayout(m, "KayKit Barbarian");
    for (std::size_t k = 0; k < m.parts.size(); ++k)
        EXPECT_EQ(g.layout.parts[k].indices.size(), m.parts[k].indices.size()) << "part " << k;
}

TEST(LayoutGenTest, RefusesBadOptionsAndModels) {
    const Model m = modelOf(cube(false));
    auto field = [&](const LayoutGenOptions& o) {
        auto r = generateTextureLayout(m, o);
        EXPECT_FALSE(r);
        return r ? std::string() : r.error().field;
    };
    LayoutGenOptions o;
    o.resolution = 16;
    EXPECT_EQ(field(o), "resolution");
    o.resolution = 2 * kMaxHeightmapSize;
    EXPECT_EQ(field(o), "resolution");
    o = {};
    o.gutterTexels = 1;
    EXPECT_EQ(field(o), "gutterTexels");
    o = {};
    o.gutterTexels = 65; // over resolution / 16
    EXPECT_EQ(field(o), "gutterTexels");
    o = {};
    o.coneDegrees = 90;
    EXPECT_EQ(field(o), "coneDegrees");
    o = {};
    o.creaseDegrees = 0;
    EXPECT_EQ(field(o), "creaseDegrees");
    o = {};
    o.maxAreaStretch = 1.0;
    EXPECT_EQ(field(o), "maxAreaStretch");

    Model bad = m;
    bad.parts[0].indices.back() = 99;
    auto r = generateTextureLayout(bad);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().field, "parts[0].indices");
    EXPECT_NE(r.error().message.find("generateTextureLayout"), std::string::npos);
    bad.parts[0].indices.pop_back();
    EXPECT_FALSE(generateTextureLayout(bad));
    EXPECT_FALSE(generateTextureLayout(Model{}));
}

/// `n` separate triangles (a soup): every one its own chart.
MeshPart soup(int n) {
    MeshPart p;
    for (int i = 0; i < n; ++i) {
        const float x = static_cast<float>(i % 50), y = static_cast<float>(i / 50);
        const auto b = static_cast<std::uint32_t>(p.positions.size());
        p.positions.insert(
            p.positions.end(),
            {{x, y, 0}, {x + 0.5f, y, 0}, {x, y + 0.5f, 0.1f * static_cast<float>(i % 7)}});
        p.indices.insert(p.indices.end(), {b, b + 1, b + 2});
    }
    return p;
}

TEST(LayoutGenTest, ASoupFitsUntilTheGuttersDoNot) {
    // At 256² with 4-texel gutters a chart takes at least 5 × 5 texels: 2,540 fit at most.
    LayoutGenOptions o;
    o.resolution = 256;
    auto fits = generateTextureLayoutWithReport(modelOf(soup(500)), o);
    ASSERT_TRUE(fits) << fits.error().message;
    EXPECT_EQ(fits->charts, 500u);
    EXPECT_EQ(fits->check.overlapTexels, 0);
    EXPECT_GE(fits->check.minGutterTexels, 4);
    auto full = generateTextureLayout(modelOf(soup(3000)), o);
    ASSERT_FALSE(full);
    EXPECT_EQ(full.error().code, ErrorCode::Unsupported);
    EXPECT_NE(full.error().message.find("3000 charts do not fit"), std::string::npos)
        << full.error().message;
}

TEST(LayoutGenTest, OtherGutterAndResolution) {
    // 2 texels at 512²: the layout still verifies at its own resolution.
    const Model m = loadModel(kTestModels + "CesiumMan/CesiumMan.glb");
    LayoutGenOptions o;
    o.resolution = 512;
    o.gutterTexels = 2;
    auto g = generateTextureLayoutWithReport(m, o);
    ASSERT_TRUE(g) << g.error().message;
    EXPECT_GE(g->check.minGutterTexels, 2);
    EXPECT_EQ(g->check.overlapTexels, 0);
    // Measured at 1024², those gutters are about twice as wide.
    EXPECT_GE(checkTextureLayout(m, g->layout, 1024, 8).minGutterTexels, 3);
}

TEST(LayoutGenTest, CoreFlatteningAndPacking) {
    // LSCM reproduces a planar chart up to similarity; skylinePackGrid never overlaps.
    ChartMesh grid;
    const MeshPart g = gridWithDegenerates();
    for (std::size_t i = 0; i < 49; ++i)
        grid.positions.emplace_back(g.positions[i]);
    for (std::size_t t = 0; t < 72; ++t)
        grid.triangles.emplace_back(g.indices[3 * t], g.indices[3 * t + 1], g.indices[3 * t + 2]);
    const std::uint32_t pins[2] = {0, 48};
    const glm::dvec2 pinUv[2] = {{0, 0}, {2, 2}};
    const auto uv = flattenLscm(grid, pins, pinUv, std::vector<glm::dvec2>(49, glm::dvec2(0.3)));
    ASSERT_EQ(uv.size(), 49u);
    for (std::size_t v = 0; v < 49; ++v) {
        EXPECT_NEAR(uv[v].x, 2 * grid.positions[v].x, 1e-6);
        EXPECT_NEAR(uv[v].y, 2 * grid.positions[v].y, 1e-6);
    }
    std::vector<GridBox> boxes;
    for (int i = 0; i < 60; ++i)
        boxes.push_back({1 + (i * 7) % 13, 1 + (i * 5) % 11});
    ASSERT_TRUE(skylinePackGrid(boxes, 64, 64));
    std::vector<int> used(64 * 64, 0);
    for (const GridBox& b : boxes) {
        const int w = b.turned ? b.h : b.w, h = b.turned ? b.w : b.h;
        ASSERT_LE(b.x + w, 64);
        ASSERT_LE(b.y + h, 64);
        for (int y = b.y; y < b.y + h; ++y)
            for (int x = b.x; x < b.x + w; ++x)
                EXPECT_EQ(used[static_cast<std::size_t>(y * 64 + x)]++, 0);
    }
}

} // namespace
