// SurfaceInspectTest — what the inspection tools make of surface placements (SPEC §8) on the
// default character, pure (no GL, no HTTP): pick's anchor (on the surface, unit normal, tangent
// across the suggested joint's bone) and its UV in a layout; mirror (the twin's anchor on the
// other side, its joint mirrored, mirroring twice gives the original back, one pattern axis kept);
// lint (no_influence from the skin weights under the decal, off_surface, overlaps between surface
// and UV placements, no no_uvs for surface placements on a model without UVs); the probe through
// the rest-surface map; ModelDerived's layout and rest-map cache.
#include "core/lint.hpp"
#include "core/mirror.hpp"
#include "core/model_derived.hpp"
#include "core/pick.hpp"
#include "core/probe.hpp"

#include "DefaultSceneFixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace dermis;

namespace {

class SurfaceInspectTest : public test::DefaultSceneTest {
protected:
    static const Model& model() { return loaded_->model; }

    /// The rest-mesh vertex with the most skin weight on joint `name` whose bind position has
    /// x of sign `side` (+1 left, −1 right).
    static std::pair<std::size_t, std::size_t> vertexOf(const std::string& name, double side = 0.0) {
        const int node = model().findJoint(name);
        std::pair<std::size_t, std::size_t> best{0, 0};
        float bestW = -1.0f;
        for (std::size_t pi = 0; pi < model().parts.size(); ++pi) {
            const MeshPart& part = model().parts[pi];
            for (std::size_t v = 0; v < part.positions.size() && v < part.joints.size(); ++v) {
                if (side * part.positions[v].x < 0.0) continue;
                for (int c = 0; c < 4; ++c)
                    if (part.joints[v][c] < part.influences.size() &&
                        part.influences[part.joints[v][c]].node == node && part.weights[v][c] > bestW) {
                        bestW = part.weights[v][c];
                        best = {pi, v};
                    }
            }
        }
        return best;
    }

    /// A surface placement anchored at a vertex (tangent ⟂ normal), driven by `joint`.
    static Placement surfaceAt(const std::string& id, std::pair<std::size_t, std::size_t> at,
                               const std::string& joint, double size = 0.08) {
        const MeshPart& part = model().parts[at.first];
        const glm::dvec3 p(part.positions[at.second]), n = glm::normalize(glm::dvec3(part.normals[at.second]));
        const glm::dvec3 t = glm::normalize(glm::cross(n, glm::dvec3(0, 1, 0)));
        Placement pl;
        pl.id = id;
        pl.pattern = "round_bulge";
        pl.joint = joint;
        pl.thetaMin = 0;
        pl.thetaMax = 90;
        pl.projection = Projection::Surface;
        pl.anchor.position = {p.x, p.y, p.z};
        pl.anchor.normal = {n.x, n.y, n.z};
        pl.anchor.tangent = {t.x, t.y, t.z};
        pl.size = {size, size};
        return pl;
    }

    static std::vector<LintFinding> lint(const std::vector<Placement>& placements, const Model* m = nullptr) {
        Scene s = loaded_->scene;
        s.placements = placements;
        const ModelDerived derived(std::make_shared<const Model>(m ? *m : model()));
        return lintScene(s, derived, loaded_->images);
    }
    static bool has(const std::vector<LintFinding>& f, const std::string& code, int placement) {
        for (const LintFinding& x : f)
            if (x.code == code && x.placement == placement) return true;
        return false;
    }
};

glm::dvec3 vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

} // namespace

// --- pick ------------------------------------------------------------------------------------------

TEST_F(SurfaceInspectTest, PickAnchorLiesOnTheHitTriangleWithATangentAcrossTheBone) {
    const Model& m = model();
    const RestSkin rest = restSkin(m);
    const auto [pi, v] = vertexOf("forearm.l", +1);
    const MeshPart& part = m.parts[pi];
    // A hit at the middle of a triangle using that vertex.
    std::size_t tri = 0;
    for (std::size_t t = 0; t + 2 < part.indices.size(); t += 3)
        if (part.indices[t] == v || part.indices[t + 1] == v || part.indices[t + 2] == v) {
            tri = t / 3;
            break;
        }
    PickHit hit;
    hit.part = static_cast<int>(pi);
    hit.triangle = static_cast<int>(tri);
    hit.bary = glm::vec3(0.2f, 0.3f, 0.5f);
    hit.joints = {{m.findJoint("forearm.l"), 1.0f}};
    const PickAnchor a = pickAnchor(m, hit, m.findJoint("forearm.l"), rest.world);
    glm::dvec3 expected(0.0);
    for (int k = 0; k < 3; ++k) expected += static_cast<double>(hit.bary[k]) * glm::dvec3(part.positions[part.indices[3 * tri + k]]);
    EXPECT_LT(glm::length(a.position - expected), 1e-6);
    EXPECT_NEAR(glm::length(a.normal), 1.0, 1e-9);
    EXPECT_NEAR(glm::length(a.tangent), 1.0, 1e-9);
    EXPECT_NEAR(glm::dot(a.normal, a.tangent), 0.0, 1e-9);
    // Across the forearm's bone (forearm.l → hand.l): the tangent is ⟂ the bone.
    const int j = m.findJoint("forearm.l"), child = m.findJoint("hand.l");
    ASSERT_GE(child, 0);
    const glm::dvec3 bone = glm::normalize(glm::dvec3(rest.world[static_cast<std::size_t>(child)][3]) -
                                           glm::dvec3(rest.world[static_cast<std::size_t>(j)][3]));
    EXPECT_LT(std::abs(glm::dot(a.tangent, bone)), 1e-6);
    // No joint: still a unit tangent ⟂ normal.
    const PickAnchor b = pickAnchor(m, hit, -1, rest.world);
    EXPECT_NEAR(glm::dot(b.normal, b.tangent), 0.0, 1e-9);
    // The UV in a layout: the model's own gives the model's UV; another layout its own.
    const TextureLayout own = modelTextureLayout(m);
    auto uv = layoutUv(own, hit);
    ASSERT_TRUE(uv);
    glm::vec2 modelUv(0.0f);
    for (int k = 0; k < 3; ++k) modelUv += hit.bary[k] * part.uvs[part.indices[3 * tri + k]];
    EXPECT_LT(glm::length(*uv - modelUv), 1e-6f);
    TextureLayout moved = own;
    for (PartLayout& p : moved.parts)
        for (glm::vec2& q : p.uvs) q = glm::vec2(1.0f) - q;
    auto uv2 = layoutUv(moved, hit);
    ASSERT_TRUE(uv2);
    EXPECT_LT(glm::length(*uv2 - (glm::vec2(1.0f) - modelUv)), 1e-6f);
    PickHit outside = hit;
    outside.triangle = 1 << 28;
    EXPECT_FALSE(layoutUv(own, outside));
}

// --- mirror ------------------------------------------------------------------------------------------

TEST_F(SurfaceInspectTest, MirrorTakesTheAnchorToTheOtherSideAndBack) {
    const Model& m = model();
    const ModelDerived derived(std::make_shared<const Model>(m));
    const SymmetryPlane& plane = derived.symmetryPlane();
    Placement p = surfaceAt("elbow_l", vertexOf("forearm.l", +1), "forearm.l");
    p.rotation = 20.0;
    p.depth = 0.03;
    auto twin = mirrorPlacement(p, m, derived.uvLookup(), plane, derived.restSkin());
    ASSERT_TRUE(twin) << twin.error().message;
    EXPECT_EQ(twin->joint, "forearm.r");
    EXPECT_EQ(twin->projection, Projection::Surface);
    EXPECT_EQ(twin->size, p.size);
    EXPECT_EQ(twin->depth, p.depth);
    EXPECT_EQ(twin->rotation, p.rotation);
    // On the other side of the plane (the default character: bind space = rest world, x = 0).
    glm::dvec3 reflected = vec(p.anchor.position);
    reflected[plane.axis] = 2.0 * plane.offset - reflected[plane.axis];
    EXPECT_LT(glm::length(vec(twin->anchor.position) - reflected), 0.01);
    glm::dvec3 rn = vec(p.anchor.normal);
    rn[plane.axis] = -rn[plane.axis];
    EXPECT_GT(glm::dot(glm::normalize(vec(twin->anchor.normal)), rn), 0.99);
    // Back again: the original anchor (to the mesh's asymmetry).
    auto back = mirrorPlacement(*twin, m, derived.uvLookup(), plane, derived.restSkin());
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->joint, "forearm.l");
    EXPECT_LT(glm::length(vec(back->anchor.position) - vec(p.anchor.position)), 0.01);
    EXPECT_GT(glm::dot(vec(back->anchor.normal), vec(p.anchor.normal)), 0.99);
    EXPECT_GT(glm::dot(vec(back->anchor.tangent), vec(p.anchor.tangent)), 0.99);
    // One axis of the pattern as the mirror image has it: the tangent (nearly in the plane here:
    // t = n × y has little x) reflected, so "up along the arm" stays up.
    Placement flat = p;
    flat.rotation = 0.0;
    auto t0 = mirrorPlacement(flat, m, derived.uvLookup(), plane, derived.restSkin());
    ASSERT_TRUE(t0);
    glm::dvec3 rt = vec(flat.anchor.tangent);
    const glm::dvec3 b = glm::cross(vec(flat.anchor.normal), rt);
    rt[plane.axis] = -rt[plane.axis];
    glm::dvec3 rb = b;
    rb[plane.axis] = -rb[plane.axis];
    const glm::dvec3 t2 = vec(t0->anchor.tangent), b2 = glm::cross(vec(t0->anchor.normal), t2);
    if (std::abs(vec(flat.anchor.tangent)[plane.axis]) <= std::abs(b[plane.axis]))
        EXPECT_GT(glm::dot(t2, rt), 0.95);
    else
        EXPECT_GT(glm::dot(b2, rb), 0.95);
    // The twin of a surface placement is found as such (the mirror route's duplicate check).
    Scene s;
    s.placements = {p, *twin};
    s.placements[1].id = "elbow_r";
    EXPECT_EQ(findMirrorTwin(s, *twin), 1);
    Placement far = *twin;
    far.anchor.position[1] += 0.5;
    EXPECT_EQ(findMirrorTwin(s, far), -1);
}

TEST_F(SurfaceInspectTest, MirrorOfASurfacePlacementNeedsNoUvs) {
    Model noUv = model();
    for (MeshPart& part : noUv.parts) part.uvs.clear();
    const ModelDerived derived(std::make_shared<const Model>(noUv));
    const Placement p = surfaceAt("elbow_l", vertexOf("forearm.l", +1), "forearm.l");
    auto twin = mirrorPlacement(p, noUv, derived.uvLookup(), derived.symmetryPlane(), derived.restSkin());
    ASSERT_TRUE(twin) << twin.error().message;
    EXPECT_EQ(twin->joint, "forearm.r");
    Placement uv = p;
    uv.projection = Projection::Uv;
    EXPECT_FALSE(mirrorPlacement(uv, noUv, derived.uvLookup(), derived.symmetryPlane(), derived.restSkin()));
}

// --- lint ---------------------------------------------------------------------------------------------

TEST_F(SurfaceInspectTest, LintReadsTheSkinUnderTheDecal) {
    const auto elbow = vertexOf("forearm.l", +1);
    const Placement good = surfaceAt("good", elbow, "forearm.l");
    // The left forearm's skin does not bend with the right knee.
    Placement wrong = surfaceAt("wrong", elbow, "shin.r");
    if (model().findJoint("shin.r") < 0) wrong.joint = "thigh.r";
    auto f = lint({good, wrong});
    EXPECT_FALSE(has(f, "no_influence", 0));
    EXPECT_TRUE(has(f, "no_influence", 1));
    // Seamless: never off_chart or across_seam.
    for (const LintFinding& x : f) {
        EXPECT_NE(x.code, "off_chart");
        EXPECT_NE(x.code, "across_seam");
    }
    // Two decals at one place on one target overlap; on another target they do not.
    EXPECT_TRUE(has(f, "overlap", 0));
    Placement other = wrong;
    other.target = Target::Displacement;
    auto g = lint({good, other});
    EXPECT_FALSE(has(g, "overlap", 0));
    // Off the body: no skin within the decal's depth.
    Placement off = good;
    off.anchor.position = {5.0, 5.0, 5.0};
    auto h = lint({off});
    EXPECT_TRUE(has(h, "off_surface", 0));
    EXPECT_FALSE(has(h, "no_influence", 0));
}

TEST_F(SurfaceInspectTest, LintCountsOverlapsBetweenSurfaceAndUvPlacements) {
    const auto [pi, v] = vertexOf("forearm.l", +1);
    Placement decal = surfaceAt("decal", {pi, v}, "forearm.l", 0.1);
    decal.target = Target::Bump;
    Placement uv;
    uv.id = "uv";
    uv.pattern = "round_bulge";
    uv.joint = "forearm.l";
    uv.target = Target::Bump;
    const glm::vec2 at = model().parts[pi].uvs[v];
    uv.center = {at.x, at.y};
    uv.scale = {0.05, 0.05};
    auto f = lint({decal, uv});
    EXPECT_TRUE(has(f, "overlap", 0));
    auto g = lint({uv, decal});
    EXPECT_TRUE(has(g, "overlap", 0));
    Placement away = uv;
    away.center = {at.x > 0.5 ? 0.05 : 0.95, at.y > 0.5 ? 0.05 : 0.95};
    EXPECT_FALSE(has(lint({decal, away}), "overlap", 0));
}

TEST_F(SurfaceInspectTest, LintOnAModelWithoutUvsSpeaksOfUvPlacementsOnly) {
    Model noUv = model();
    for (MeshPart& part : noUv.parts) part.uvs.clear();
    const Placement decal = surfaceAt("decal", vertexOf("forearm.l", +1), "forearm.l");
    auto f = lint({decal}, &noUv);
    for (const LintFinding& x : f) EXPECT_NE(x.code, "no_uvs") << x.message;
    Placement uv = decal;
    uv.id = "uv";
    uv.projection = Projection::Uv;
    auto g = lint({decal, uv}, &noUv);
    EXPECT_TRUE(has(g, "no_uvs", -1));
}

TEST_F(SurfaceInspectTest, LintComparesSurfaceMirrorPairsByAnchor) {
    const Model& m = model();
    const ModelDerived derived(std::make_shared<const Model>(m));
    const Placement left = surfaceAt("elbow_l", vertexOf("forearm.l", +1), "forearm.l");
    auto twin = mirrorPlacement(left, m, derived.uvLookup(), derived.symmetryPlane(), derived.restSkin());
    ASSERT_TRUE(twin);
    twin->id = "elbow_r";
    for (const LintFinding& x : lint({left, *twin})) EXPECT_NE(x.code, "mirror_asymmetric") << x.message;
    Placement moved = *twin;
    moved.anchor.position[1] -= 0.1;
    EXPECT_TRUE(has(lint({left, moved}), "mirror_asymmetric", 0));
}

// --- probe and the derived data -------------------------------------------------------------------

TEST_F(SurfaceInspectTest, ProbeReadsTheRestSurfaceMap) {
    const auto [pi, v] = vertexOf("forearm.l", +1);
    Scene s = loaded_->scene;
    s.placements = {surfaceAt("decal", {pi, v}, "forearm.l", 0.1)};
    s.placements[0].thetaMin = -360;
    s.placements[0].thetaMax = -359; // t = 1
    s.heightmapSize = {512, 512};
    auto plan = planFrame(s, model(), loaded_->images, nullptr);
    ASSERT_TRUE(plan) << plan.error().message;
    const glm::vec2 uv = model().parts[pi].uvs[v];
    auto r = probeHeights(plan->heights, uv.x, uv.y);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->contributions.size(), 1u);
    EXPECT_EQ(r->contributions[0].source, 0);
    EXPECT_GT(r->contributions[0].height, 0.5f);
    EXPECT_FLOAT_EQ(r->bump, r->contributions[0].height);
    // The CPU map agrees at that texel.
    auto maps = bakeHeightMaps(plan->heights);
    ASSERT_TRUE(maps);
    EXPECT_FLOAT_EQ(maps->bump.at(r->texelX, r->texelY), r->bump);
    HeightMapInput noRest = plan->heights;
    noRest.rest.reset();
    auto bad = probeHeights(noRest, uv.x, uv.y);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().field, "/placements/0/projection");
}

TEST_F(SurfaceInspectTest, ModelDerivedKeepsTheLayoutAndRestMapsPerSize) {
    const ModelDerived derived(std::make_shared<const Model>(model()));
    const auto& layout = derived.modelLayout();
    ASSERT_TRUE(layout);
    EXPECT_EQ(layout, derived.modelLayout()); // one object
    EXPECT_EQ(layout->kind, "model");
    auto a = derived.restSurface(layout, 64, 64);
    EXPECT_EQ(derived.restSurfaceBuilds(), 1);
    EXPECT_EQ(derived.restSurface(nullptr, 64, 64), a); // null = the model's layout
    EXPECT_EQ(derived.restSurfaceBuilds(), 1);
    auto b = derived.restSurface(layout, 32, 64);
    EXPECT_NE(a, b);
    EXPECT_EQ(b->width, 32);
    auto c = derived.restSurface(layout, 16, 16); // a third size: the least recent (64²) goes
    EXPECT_EQ(derived.restSurfaceBuilds(), 3);
    EXPECT_EQ(derived.restSurface(layout, 32, 64), b);
    EXPECT_NE(derived.restSurface(layout, 64, 64), a);
    EXPECT_EQ(derived.restSurfaceBuilds(), 4);
    // Another layout object is another key.
    auto other = std::make_shared<const TextureLayout>(modelTextureLayout(model()));
    EXPECT_NE(derived.restSurface(other, 16, 16), c);
}
