// SurfaceOutlineTest — the outline of a placement's footprint in the height-map layout (core
// surfaceFootprintOutline, footprintContains; SPEC §8), pure: on a hand-built cylinder whose UV
// layout has a seam, a decal inside the chart is one closed loop whose ends lie on the decal's
// border and whose bounds are the decal's UV extent (rotation turns it), a decal across the seam
// falls into two pieces (two open chains ending on the seam), a decal smaller than a triangle is
// a 4-segment loop inside that triangle, a decal off the body or facing away gives no piece; the
// hit test agrees; the cap truncates with a flag; errors name the field; a UV placement is its
// rotated rectangle; the anchor's UV is that of the nearest surface point facing the anchor within
// the decal's reach (else of the nearest triangle), a UV placement's is its center; on the KayKit
// Barbarian (tests/models) through its generated layout, a decal at a pick anchor on the forearm
// gives pieces inside [0,1]² holding the picked point, which is its anchor UV.
#include "BuildPaths.hpp"
#include "core/bake.hpp"
#include "core/heightmap.hpp"
#include "core/layout_gen.hpp"
#include "core/mirror.hpp"
#include "core/pick.hpp"
#include "core/surface_outline.hpp"
#include "core/texture_layout.hpp"
#include "core/uv_lookup.hpp"
#include "io/gltf_loader.hpp"

#include "SeamCylinder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <utility>

using namespace dermis;
using namespace dermis::test::seam_cylinder; // cylinder(), kPi, kRadius, kHeight (SeamCylinder.hpp)

namespace {



/// A surface placement anchored on the cylinder at angle `a` (radians) and height y: normal
/// outwards, tangent around the cylinder (towards growing angle), size w × h, rotation degrees.
Placement decalOnCylinder(double a, double y, double w, double h, double rotation = 0.0) {
    Placement p;
    p.id = "decal";
    p.pattern = "round_bulge";
    p.projection = Projection::Surface;
    p.anchor.position = {kRadius * std::cos(a), y, kRadius * std::sin(a)};
    p.anchor.normal = {std::cos(a), 0.0, std::sin(a)};
    p.anchor.tangent = {-std::sin(a), 0.0, std::cos(a)};
    p.size = {w, h};
    p.rotation = rotation;
    return p;
}

std::pair<double, double> keyOf(double u, double v) { return {u, v}; }

/// How many segment ends sit at each point (exact coordinates).
std::map<std::pair<double, double>, int> endCounts(const SurfaceOutline& o, std::size_t piece = SIZE_MAX) {
    std::map<std::pair<double, double>, int> ends;
    for (std::size_t k = 0; k < o.segments.size(); ++k) {
        if (piece != SIZE_MAX && o.segmentPiece[k] != piece) continue;
        ++ends[keyOf(o.segments[k][0], o.segments[k][1])];
        ++ends[keyOf(o.segments[k][2], o.segments[k][3])];
    }
    return ends;
}

/// Expects every segment end to lie on the decal's border: mapped back to the mesh (the triangle
/// covering it in UV, barycentrically), max(|x| − w/2, |y| − h/2, |z| − depth) is 0.
void expectEndsOnBorder(const Model& m, const Placement& p, const SurfaceOutline& o, double tol = 1e-6) {
    BakePlacement b;
    ASSERT_TRUE(surfaceFrameOf(p, b));
    const SurfaceFrame f(b);
    const UvLookup lookup(m);
    for (const auto& s : o.segments)
        for (int e = 0; e < 2; ++e) {
            const glm::dvec2 uv(s[2 * e], s[2 * e + 1]);
            const auto hit = lookup.find(uv);
            ASSERT_TRUE(hit) << uv.x << ", " << uv.y;
            const glm::dvec3 d = glm::dvec3(lookup.position(*hit)) - f.c;
            const double g = std::max({std::abs(glm::dot(d, f.t)) - 0.5 * b.size.x,
                                       std::abs(glm::dot(d, f.b)) - 0.5 * b.size.y,
                                       std::abs(glm::dot(d, f.n)) - b.depth});
            EXPECT_NEAR(g, 0.0, tol) << "end " << uv.x << ", " << uv.y;
        }
}

// The UV extent of a decal of width w (around) and height h (along y) on the cylinder, centred at
// angle a0 and height y0, on the faceted mesh: half the angle is where the chord position reaches
// w/2 along the tangent — asin(w / 2r) on the true circle, a little more on the chords.
constexpr double kExtentTol = 2e-3;

} // namespace

TEST(SurfaceOutlineTest, ADecalInsideOneChartIsOneClosedLoopOnItsBorder) {
    const Model m = cylinder();
    const Placement p = decalOnCylinder(kPi, 1.0, 0.4, 0.3);
    auto o = surfaceFootprintOutline(m, p);
    ASSERT_TRUE(o) << o.error().message;
    EXPECT_EQ(o->projection, Projection::Surface);
    ASSERT_EQ(o->pieces.size(), 1u);
    EXPECT_FALSE(o->truncated);
    // More than a rectangle's 4: one segment per crossed triangle.
    EXPECT_GT(o->segments.size(), 20u);
    ASSERT_EQ(o->segmentPiece.size(), o->segments.size());
    // A closed loop: every end is shared by exactly two segments.
    const auto ends = endCounts(*o);
    for (const auto& [pt, n] : ends) EXPECT_EQ(n, 2) << pt.first << ", " << pt.second;
    EXPECT_EQ(ends.size(), o->segments.size()) << "one loop: as many distinct ends as segments";
    expectEndsOnBorder(m, p, *o);
    // The piece's bounds: u around 0.5 ± asin(0.4)/2π, v = 0.5 ± 0.075.
    const OutlinePiece& piece = o->pieces[0];
    const double du = std::asin(0.2 / kRadius) / (2 * kPi);
    EXPECT_NEAR(piece.min.x, 0.5 - du, kExtentTol);
    EXPECT_NEAR(piece.max.x, 0.5 + du, kExtentTol);
    EXPECT_NEAR(piece.min.y, 0.5 - 0.075, 1e-6);
    EXPECT_NEAR(piece.max.y, 0.5 + 0.075, 1e-6);
    EXPECT_GT(piece.triangles, 20u);
    // The hit test agrees.
    const UvLookup lookup(m);
    EXPECT_TRUE(footprintContains(m, lookup, p, {0.5, 0.5}));
    EXPECT_TRUE(footprintContains(m, lookup, p, {0.5 + 0.9 * du, 0.5 + 0.07}));
    EXPECT_FALSE(footprintContains(m, lookup, p, {0.5, 0.5 + 0.08}));
    EXPECT_FALSE(footprintContains(m, lookup, p, {0.5 + du + 0.005, 0.5}));
    EXPECT_FALSE(footprintContains(m, lookup, p, {0.0, 0.5}));
}

TEST(SurfaceOutlineTest, RotationTurnsTheOutline) {
    const Model m = cylinder();
    // Turned by 90°: the decal's w runs along the cylinder's height, its h around it.
    const Placement p = decalOnCylinder(kPi, 1.0, 0.4, 0.3, 90.0);
    auto o = surfaceFootprintOutline(m, p);
    ASSERT_TRUE(o) << o.error().message;
    ASSERT_EQ(o->pieces.size(), 1u);
    const double du = std::asin(0.15 / kRadius) / (2 * kPi);
    EXPECT_NEAR(o->pieces[0].min.x, 0.5 - du, kExtentTol);
    EXPECT_NEAR(o->pieces[0].max.x, 0.5 + du, kExtentTol);
    EXPECT_NEAR(o->pieces[0].min.y, 0.5 - 0.1, 1e-6);
    EXPECT_NEAR(o->pieces[0].max.y, 0.5 + 0.1, 1e-6);
    expectEndsOnBorder(m, p, *o);
}

TEST(SurfaceOutlineTest, ADecalAcrossTheSeamFallsIntoTwoPieces) {
    const Model m = cylinder();
    const Placement p = decalOnCylinder(0.0, 1.0, 0.4, 0.3);
    auto o = surfaceFootprintOutline(m, p);
    ASSERT_TRUE(o) << o.error().message;
    ASSERT_EQ(o->pieces.size(), 2u);
    // The pieces are ordered by their first triangle: u = 0's side comes first.
    const double du = std::asin(0.2 / kRadius) / (2 * kPi);
    EXPECT_NEAR(o->pieces[0].min.x, 0.0, 1e-9);
    EXPECT_NEAR(o->pieces[0].max.x, du, kExtentTol);
    EXPECT_NEAR(o->pieces[1].min.x, 1.0 - du, kExtentTol);
    EXPECT_NEAR(o->pieces[1].max.x, 1.0, 1e-9);
    for (const OutlinePiece& piece : o->pieces) {
        EXPECT_NEAR(piece.min.y, 0.425, 1e-6);
        EXPECT_NEAR(piece.max.y, 0.575, 1e-6);
    }
    expectEndsOnBorder(m, p, *o);
    // Each piece's border is one open chain whose two loose ends lie on the seam.
    for (std::size_t k = 0; k < 2; ++k) {
        SCOPED_TRACE(k);
        int loose = 0;
        for (const auto& [pt, n] : endCounts(*o, k)) {
            EXPECT_LE(n, 2);
            if (n == 1) {
                ++loose;
                EXPECT_EQ(pt.first, k == 0 ? 0.0 : 1.0);
            }
        }
        EXPECT_EQ(loose, 2);
    }
    const UvLookup lookup(m);
    EXPECT_TRUE(footprintContains(m, lookup, p, {0.001, 0.5}));
    EXPECT_TRUE(footprintContains(m, lookup, p, {0.999, 0.5}));
    EXPECT_FALSE(footprintContains(m, lookup, p, {0.5, 0.5}));
}

TEST(SurfaceOutlineTest, ADecalSmallerThanATriangleIsALoopInsideIt) {
    const Model m = cylinder();
    const MeshPart& part = m.parts[0];
    // Triangle 2·(10·96 + 40): its centroid, face normal, a tangent in its plane.
    const std::size_t t = 2 * (10 * kSegments + 40);
    glm::dvec3 c(0.0), pos[3];
    glm::dvec2 uv(0.0);
    for (int k = 0; k < 3; ++k) {
        pos[k] = glm::dvec3(part.positions[part.indices[3 * t + k]]);
        c += pos[k] / 3.0;
        uv += glm::dvec2(part.uvs[part.indices[3 * t + k]]) / 3.0;
    }
    const glm::dvec3 n = glm::normalize(glm::cross(pos[1] - pos[0], pos[2] - pos[0]));
    const glm::dvec3 tan = glm::normalize(glm::cross(glm::dvec3(0, 1, 0), n));
    Placement p = decalOnCylinder(0.0, 0.0, 0.004, 0.006);
    p.anchor.position = {c.x, c.y, c.z};
    p.anchor.normal = {n.x, n.y, n.z};
    p.anchor.tangent = {tan.x, tan.y, tan.z};
    auto o = surfaceFootprintOutline(m, p);
    ASSERT_TRUE(o) << o.error().message;
    ASSERT_EQ(o->pieces.size(), 1u);
    EXPECT_EQ(o->pieces[0].triangles, 1u);
    ASSERT_EQ(o->segments.size(), 4u);
    for (const auto& [pt, k] : endCounts(*o)) EXPECT_EQ(k, 2);
    expectEndsOnBorder(m, p, *o, 1e-7);
    // Around the triangle's UV centroid, inside its bounds.
    EXPECT_LT(o->pieces[0].min.x, uv.x);
    EXPECT_GT(o->pieces[0].max.x, uv.x);
    EXPECT_LT(o->pieces[0].min.y, uv.y);
    EXPECT_GT(o->pieces[0].max.y, uv.y);
    EXPECT_LT(o->pieces[0].max.x - o->pieces[0].min.x, 1.0 / kSegments);
    EXPECT_TRUE(footprintContains(m, UvLookup(m), p, uv));
    // Anchored at the triangle's centroid: its anchor UV is the centroid's UV.
    ASSERT_TRUE(o->anchorUv);
    EXPECT_NEAR(o->anchorUv->x, uv.x, 1e-9);
    EXPECT_NEAR(o->anchorUv->y, uv.y, 1e-9);
}

TEST(SurfaceOutlineTest, ADecalOnNoSurfaceHasNoPiece) {
    const Model m = cylinder();
    // Far from the body.
    Placement off = decalOnCylinder(kPi, 1.0, 0.4, 0.3);
    off.anchor.position = {10.0, 10.0, 10.0};
    auto far = surfaceFootprintOutline(m, off);
    ASSERT_TRUE(far) << far.error().message;
    EXPECT_TRUE(far->pieces.empty());
    EXPECT_TRUE(far->segments.empty());
    // On the surface, but facing away from it (every normal there has normal·n < 0).
    Placement away = decalOnCylinder(kPi, 1.0, 0.4, 0.3);
    away.anchor.normal = {1.0, 0.0, 0.0};
    auto back = surfaceFootprintOutline(m, away);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_TRUE(back->pieces.empty());
    EXPECT_TRUE(back->segments.empty());
    EXPECT_FALSE(footprintContains(m, UvLookup(m), away, {0.5, 0.5}));
}

TEST(SurfaceOutlineTest, TheCapTruncatesWithAFlag) {
    const Model m = cylinder();
    auto o = surfaceFootprintOutline(m, decalOnCylinder(kPi, 1.0, 0.4, 0.3), 5);
    ASSERT_TRUE(o) << o.error().message;
    EXPECT_TRUE(o->truncated);
    EXPECT_EQ(o->segments.size(), 5u);
    EXPECT_EQ(o->segmentPiece.size(), 5u);
    EXPECT_EQ(o->pieces.size(), 1u) << "the pieces are still counted";
}

TEST(SurfaceOutlineTest, ErrorsNameTheField) {
    const Model m = cylinder();
    auto expectField = [&](const Model& model, const Placement& p, const std::string& field) {
        auto r = surfaceFootprintOutline(model, p);
        ASSERT_FALSE(r) << field;
        EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
        EXPECT_EQ(r.error().field, field);
        EXPECT_NE(r.error().message.find("dermis::surfaceFootprintOutline"), std::string::npos) << r.error().message;
        EXPECT_NE(r.error().message.find(field), std::string::npos) << r.error().message;
    };
    Placement p = decalOnCylinder(kPi, 1.0, 0.4, 0.3);
    p.anchor.normal = {0, 0, 0};
    expectField(m, p, "anchor");
    p = decalOnCylinder(kPi, 1.0, 0.4, 0.3);
    p.anchor.tangent = p.anchor.normal;
    expectField(m, p, "anchor");
    p = decalOnCylinder(kPi, 1.0, 0.0, 0.3);
    expectField(m, p, "size");
    p = decalOnCylinder(kPi, 1.0, 0.4, 0.3);
    p.depth = -1.0;
    expectField(m, p, "depth");
    Model noUvs = cylinder();
    noUvs.parts[0].uvs.clear();
    expectField(noUvs, decalOnCylinder(kPi, 1.0, 0.4, 0.3), "uv_layout");
    Placement uv;
    uv.scale = {0.0, 0.1};
    expectField(m, uv, "scale");
    uv.scale = {0.1, 0.1};
    uv.rotation = NAN;
    expectField(m, uv, "rotation");
}

TEST(SurfaceOutlineTest, AUvPlacementIsItsRotatedRectangle) {
    Placement p;
    p.center = {0.3, 0.6};
    p.scale = {0.2, 0.1};
    p.rotation = 30.0;
    auto o = surfaceFootprintOutline(Model{}, p); // the model is not read
    ASSERT_TRUE(o) << o.error().message;
    EXPECT_EQ(o->projection, Projection::Uv);
    ASSERT_EQ(o->segments.size(), 4u);
    ASSERT_EQ(o->pieces.size(), 1u);
    // Corners s = (0,0), (1,0), (1,1), (0,1): center + R(30°)·((s − ½)·scale).
    const double c = std::cos(kPi / 6), s = std::sin(kPi / 6);
    const double corners[4][2] = {{-0.1, -0.05}, {0.1, -0.05}, {0.1, 0.05}, {-0.1, 0.05}};
    for (int k = 0; k < 4; ++k) {
        SCOPED_TRACE(k);
        const double x = corners[k][0], y = corners[k][1];
        EXPECT_NEAR(o->segments[k][0], 0.3 + c * x - s * y, 1e-12);
        EXPECT_NEAR(o->segments[k][1], 0.6 + s * x + c * y, 1e-12);
        // Each side ends where the next begins.
        EXPECT_EQ(o->segments[k][2], o->segments[(k + 1) % 4][0]);
        EXPECT_EQ(o->segments[k][3], o->segments[(k + 1) % 4][1]);
    }
    // The corner s = (1, 0) is at 0.3 + 0.1·cos30° + 0.05·sin30°, 0.6 + 0.1·sin30° − 0.05·cos30°.
    EXPECT_NEAR(o->segments[1][0], 0.4116025, 1e-7);
    EXPECT_NEAR(o->segments[1][1], 0.6066987, 1e-7);
    EXPECT_NEAR(o->pieces[0].min.x, 0.3 - 0.1116025, 1e-7);
    ASSERT_TRUE(o->anchorUv);
    EXPECT_EQ(*o->anchorUv, glm::dvec2(0.3, 0.6)) << "a UV placement's anchor is its center";
    const Model empty;
    const UvLookup none(empty);
    EXPECT_TRUE(footprintContains(empty, none, p, {0.3, 0.6}));
    EXPECT_TRUE(footprintContains(empty, none, p, {0.39, 0.62})); // along the turned u axis
    EXPECT_FALSE(footprintContains(empty, none, p, {0.39, 0.56}));
}

// The anchor's UV: the UV of the rest-surface point nearest to the anchor — here a point on the
// true circle between two vertex columns, which lies just off the faceted mesh: its nearest point
// is its projection onto the chord's (planar) quad, whose UV the test computes.
TEST(SurfaceOutlineTest, TheAnchorUvIsTheNearestSurfacePointsUv) {
    const Model m = cylinder();
    const double a0 = 2.0 * kPi * 40 / kSegments, a1 = 2.0 * kPi * 41 / kSegments;
    const double a = a0 + 0.3 * (a1 - a0), y = 0.77;
    const Placement p = decalOnCylinder(a, y, 0.2, 0.2);
    auto o = surfaceFootprintOutline(m, p);
    ASSERT_TRUE(o) << o.error().message;
    ASSERT_TRUE(o->anchorUv);
    // In the xz-plane: the parameter of the anchor's projection onto the chord from a0 to a1.
    const glm::dvec2 A(kRadius * std::cos(a0), kRadius * std::sin(a0));
    const glm::dvec2 B(kRadius * std::cos(a1), kRadius * std::sin(a1));
    const glm::dvec2 P(kRadius * std::cos(a), kRadius * std::sin(a));
    const double t = glm::dot(P - A, B - A) / glm::dot(B - A, B - A);
    EXPECT_NEAR(o->anchorUv->x, (40 + t) / kSegments, 1e-6);
    EXPECT_NEAR(o->anchorUv->y, 1.0 - y / kHeight, 1e-6);
    // On a vertex column: that column's u.
    auto onColumn = surfaceFootprintOutline(m, decalOnCylinder(kPi, 1.0, 0.4, 0.3));
    ASSERT_TRUE(onColumn && onColumn->anchorUv);
    EXPECT_NEAR(onColumn->anchorUv->x, 0.5, 1e-9);
    EXPECT_NEAR(onColumn->anchorUv->y, 0.5, 1e-9);
    // Facing away from every surface near it: the nearest triangle all the same.
    Placement away = decalOnCylinder(kPi, 1.0, 0.4, 0.3);
    away.anchor.normal = {1.0, 0.0, 0.0};
    auto back = surfaceFootprintOutline(m, away);
    ASSERT_TRUE(back && back->anchorUv);
    EXPECT_TRUE(back->pieces.empty());
    EXPECT_NEAR(back->anchorUv->x, 0.5, 1e-9);
    EXPECT_NEAR(back->anchorUv->y, 0.5, 1e-9);
}

TEST(SurfaceOutlineTest, TheAnchorUvPrefersASurfaceFacingTheAnchorWithinReach) {
    // Two parallel squares x, y ∈ [−1, 1]: at z = 0 facing −z (u in [0, ½]), at z = −0.1 facing +z
    // (u in [½, 1]); v = (y + 1)/2 on both — a layer over the skin, seen from its back.
    Model m;
    MeshPart part;
    for (int layer = 0; layer < 2; ++layer)
        for (int k = 0; k < 4; ++k) {
            const float x = k == 1 || k == 2 ? 1.0f : -1.0f, y = k >= 2 ? 1.0f : -1.0f;
            part.positions.emplace_back(x, y, layer == 0 ? 0.0f : -0.1f);
            part.normals.emplace_back(0.0f, 0.0f, layer == 0 ? -1.0f : 1.0f);
            part.uvs.emplace_back(0.5f * layer + (x + 1.0f) / 4.0f, (y + 1.0f) / 2.0f);
        }
    part.indices = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
    m.parts.push_back(part);
    // Anchored 0.02 in front of the first square, looking along +z.
    Placement p = decalOnCylinder(0.0, 0.0, 0.3, 0.3);
    p.anchor.position = {0.2, -0.4, 0.02};
    p.anchor.normal = {0.0, 0.0, 1.0};
    p.anchor.tangent = {1.0, 0.0, 0.0};
    p.depth = 0.05;
    // Reach ≈ 0.22: both squares within it; the nearer one faces away, the other one is taken.
    auto wide = surfaceFootprintOutline(m, p);
    ASSERT_TRUE(wide) << wide.error().message;
    ASSERT_TRUE(wide->anchorUv);
    EXPECT_NEAR(wide->anchorUv->x, 0.5 + 1.2 / 4.0, 1e-7);
    EXPECT_NEAR(wide->anchorUv->y, 0.3, 1e-7);
    // Reach ≈ 0.06: only the square facing away is within it: the nearest triangle all the same.
    p.size = {0.05, 0.05};
    auto small = surfaceFootprintOutline(m, p);
    ASSERT_TRUE(small) << small.error().message;
    ASSERT_TRUE(small->anchorUv);
    EXPECT_TRUE(small->pieces.empty());
    EXPECT_NEAR(small->anchorUv->x, 1.2 / 4.0, 1e-7);
    EXPECT_NEAR(small->anchorUv->y, 0.3, 1e-7);
    // Far off both (behind the second square): the nearest triangle's UV, whatever the reach.
    p.anchor.position = {-5.0, 0.6, -3.0};
    auto far = surfaceFootprintOutline(m, p);
    ASSERT_TRUE(far && far->anchorUv);
    EXPECT_NEAR(far->anchorUv->x, 0.5, 1e-7) << "the second square's corner edge x = −1";
    EXPECT_NEAR(far->anchorUv->y, 0.8, 1e-7);
    // No triangle in the layout (every one of zero UV area): no anchor UV.
    for (glm::vec2& uv : m.parts[0].uvs) uv = glm::vec2(0.25f);
    auto none = surfaceFootprintOutline(m, p);
    ASSERT_TRUE(none) << none.error().message;
    EXPECT_FALSE(none->anchorUv);
}

// --- a real character --------------------------------------------------------------------------

TEST(SurfaceOutlineTest, TheBarbariansForearmDecalInItsGeneratedLayout) {
    auto loaded = loadGltfFile(std::string(dermis::build::testModelsDir()) +
                               "/KayKitBarbarian/Barbarian.glb");
    ASSERT_TRUE(loaded) << loaded.error().message;
    const Model& own = *loaded;
    auto layout = generateTextureLayout(own);
    ASSERT_TRUE(layout) << layout.error().message;
    const Model m = modelThroughLayout(own, *layout);
    const UvLookup lookup(m);
    // A pick on the right forearm: the UV centroid of one of its part's triangles.
    std::optional<PickHit> hit;
    for (std::size_t pi = 0; pi < m.parts.size() && !hit; ++pi) {
        const MeshPart& part = m.parts[pi];
        if (part.node != "Barbarian_ArmRight" || part.uvs.empty()) continue;
        const std::size_t t = part.indices.size() / 6; // a triangle half way through the arm
        glm::dvec2 uv(0.0);
        for (int k = 0; k < 3; ++k) uv += glm::dvec2(part.uvs[part.indices[3 * t + k]]) / 3.0;
        hit = pickUv(m, lookup, uv);
    }
    ASSERT_TRUE(hit) << "no triangle of Barbarian_ArmRight in the generated layout";
    const int joint = m.findJoint("lowerarm.r");
    ASSERT_GE(joint, 0);
    const PickAnchor a = pickAnchor(m, *hit, joint, restSkin(m).world);
    Placement p;
    p.id = "elbow";
    p.projection = Projection::Surface;
    p.anchor.position = {a.position.x, a.position.y, a.position.z};
    p.anchor.normal = {a.normal.x, a.normal.y, a.normal.z};
    p.anchor.tangent = {a.tangent.x, a.tangent.y, a.tangent.z};
    p.size = {0.18, 0.18};
    auto o = surfaceFootprintOutline(m, p);
    ASSERT_TRUE(o) << o.error().message;
    ASSERT_GE(o->pieces.size(), 1u);
    EXPECT_FALSE(o->truncated);
    EXPECT_GE(o->segments.size(), 8u);
    std::printf("Barbarian forearm decal: %zu pieces, %zu segments\n", o->pieces.size(), o->segments.size());
    for (const auto& s : o->segments)
        for (double x : s) {
            EXPECT_GE(x, 0.0);
            EXPECT_LE(x, 1.0);
        }
    // The picked point is inside the footprint, within one piece's bounds.
    const glm::dvec2 at(hit->uv);
    EXPECT_TRUE(footprintContains(m, lookup, p, at));
    bool within = false;
    for (const OutlinePiece& piece : o->pieces)
        within = within || (piece.min.x <= at.x && at.x <= piece.max.x && piece.min.y <= at.y && at.y <= piece.max.y);
    EXPECT_TRUE(within) << at.x << ", " << at.y;
    // The anchor's UV is the picked point's.
    ASSERT_TRUE(o->anchorUv);
    EXPECT_NEAR(o->anchorUv->x, at.x, 1e-3);
    EXPECT_NEAR(o->anchorUv->y, at.y, 1e-3);
    // The generated layout's charts are separate: every piece's border ends are shared by at most
    // two segments (a piece cut by a chart border is an open chain, never a fork).
    for (const auto& [pt, n] : endCounts(*o)) EXPECT_LE(n, 2) << pt.first << ", " << pt.second;
}
