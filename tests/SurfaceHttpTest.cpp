// SurfaceHttpTest — surface placements (SPEC §8) over real HTTP (HttpTestFixture.hpp): pick
// answers an anchor; a surface placement added there (POST) changes the frame only near the
// picked pixel (frame-diff against patterns=off); PATCHing its anchor to another pick moves the
// change; the canonical document echoes projection / anchor / size / depth and uv_layout; the
// probe, lint, maps and the batch route take it; the outline route draws it (and a UV placement's
// rectangle) in the layout in use; on CesiumMan the same; on RiggedFigure (no UVs) uv_layout
// "model" refuses it with a clear error naming /uv_layout.
#include "HttpTestFixture.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

class SurfaceHttpTest : public SharedServerTest {
protected:
    /// A scene of `model` with no placements, frames of 256² at msaa 1.
    static json emptyScene(const std::string& model) {
        return {{"format", "dermis.scene/1"},
                {"model", model},
                {"heightmap", {{"size", {512, 512}}}},
                {"placements", json::array()},
                {"render", {{"size", {256, 256}}, {"msaa", 1}, {"bump_strength", 4.0}}}};
    }

    /// A surface placement at a pick's anchor with the pick's suggested joint, active in any pose
    /// (θ range [−360, −359]).
    static json decalAt(const json& pick, const std::string& id, double size) {
        return {{"id", id},
                {"pattern", "round_bulge"},
                {"joint", pick["suggested"]["joint"]},
                {"theta_min", -360},
                {"theta_max", -359},
                {"target", "bump"},
                {"projection", "surface"},
                {"anchor", pick["anchor"]},
                {"size", {size, size}}};
    }

    /// Bounds of the lit pixels of a frame-diff heat image, and their count.
    struct Lit {
        long count = 0;
        int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
    };
    static Lit litOf(const Reply& diff) {
        Lit l;
        auto heat = decodeFrame(diff.bytes());
        EXPECT_TRUE(heat);
        if (!heat) return l;
        for (int y = 0; y < heat->height; ++y)
            for (int x = 0; x < heat->width; ++x)
                if (heat->rgba[(static_cast<std::size_t>(y) * heat->width + x) * 4] > 0) {
                    ++l.count;
                    l.x0 = std::min(l.x0, x);
                    l.y0 = std::min(l.y0, y);
                    l.x1 = std::max(l.x1, x);
                    l.y1 = std::max(l.y1, y);
                }
        return l;
    }

    /// The first pixel of a scan (centre column outwards, `rows`) that hits the body: its pick.
    static json pickOnBody(const std::string& s, std::initializer_list<int> rows, int& px, int& py) {
        Http h = http();
        for (int y : rows)
            for (int dx : {0, 6, -6, 12, -12}) {
                Reply r = h.get(s + "/pick?x=" + std::to_string(128 + dx) + "&y=" + std::to_string(y));
                EXPECT_EQ(r.status, 200) << r;
                if (r.status == 200 && r.js()["hit"] == true) {
                    px = 128 + dx;
                    py = y;
                    return r.js();
                }
            }
        return json();
    }

    /// Adds a decal at the pick of (px, py) and checks the frame changes only near it.
    static void expectLocalDecal(const std::string& s, const json& pick, int px, int py, double size,
                                 int reach) {
        Http h = http();
        Reply add = h.post(s + "/placements", decalAt(pick, "decal", size));
        ASSERT_EQ(add.status, 201) << add;
        Reply diff = h.get(s + "/frame-diff?against=off");
        ASSERT_EQ(diff.status, 200) << diff;
        const Lit l = litOf(diff);
        EXPECT_GT(l.count, 20) << "the decal changes the frame";
        EXPECT_EQ(std::to_string(l.count), diff.header("X-Dermis-Changed-Pixels"));
        EXPECT_LE(std::max(std::abs(l.x0 - px), std::abs(l.x1 - px)), reach) << l.x0 << ".." << l.x1 << " vs " << px;
        EXPECT_LE(std::max(std::abs(l.y0 - py), std::abs(l.y1 - py)), reach) << l.y0 << ".." << l.y1 << " vs " << py;
    }
};

} // namespace

TEST_F(SurfaceHttpTest, PickAnchorThenASurfacePlacementOnTheDefaultCharacter) {
    Http h = http();
    const std::string id = createScene(emptyScene("builtin:default"));
    const std::string s = "/scenes/" + id;
    int px = 0, py = 0;
    const json pick = pickOnBody(s, {110, 120, 100}, px, py);
    ASSERT_TRUE(pick.is_object()) << "no pixel of the torso hit";
    ASSERT_TRUE(pick.contains("anchor")) << pick;
    for (const char* key : {"position", "normal", "tangent"}) ASSERT_EQ(pick["anchor"][key].size(), 3u) << key;
    double nn = 0, nt = 0;
    for (int k = 0; k < 3; ++k) {
        nn += std::pow(pick["anchor"]["normal"][k].get<double>(), 2);
        nt += pick["anchor"]["normal"][k].get<double>() * pick["anchor"]["tangent"][k].get<double>();
    }
    EXPECT_NEAR(nn, 1.0, 1e-6);
    EXPECT_NEAR(nt, 0.0, 1e-6);

    expectLocalDecal(s, pick, px, py, 0.12, 40);

    // The canonical document echoes what SPEC §8 lists.
    Reply got = h.get(s);
    ASSERT_EQ(got.status, 200);
    const json doc = got.js()["scene"];
    EXPECT_EQ(doc["uv_layout"], "auto");
    const json& p = doc["placements"][0];
    EXPECT_EQ(p["projection"], "surface");
    EXPECT_EQ(p["anchor"]["position"].size(), 3u);
    EXPECT_EQ(p["size"], json({0.12, 0.12}));
    EXPECT_EQ(p["depth"], "auto");

    // The probe at the pick's UV names the decal; the served map holds its value.
    const double u = pick["uv"][0], v = pick["uv"][1];
    Reply probe = h.get(s + "/probe?u=" + std::to_string(u) + "&v=" + std::to_string(v));
    ASSERT_EQ(probe.status, 200) << probe;
    ASSERT_EQ(probe.js()["contributions"].size(), 1u) << probe;
    EXPECT_EQ(probe.js()["contributions"][0]["placement"], "decal");
    EXPECT_GT(probe.js()["bump"].get<double>(), 0.0);
    Reply map = h.get(s + "/heightmaps/bump?format=f32");
    ASSERT_EQ(map.status, 200) << map;
    const int x = probe.js()["texel"][0], y = probe.js()["texel"][1];
    float served = 0;
    std::memcpy(&served, map.body.data() + (static_cast<std::size_t>(y) * 512 + x) * 4, 4);
    EXPECT_NEAR(served, probe.js()["bump"].get<double>(), 2e-3);

    // Lint: the decal lies on the skin.
    Reply lint = h.get(s + "/lint");
    ASSERT_EQ(lint.status, 200) << lint;
    for (const json& f : lint.js()) EXPECT_NE(f["code"], "off_surface") << f;

    // Pick elsewhere, PATCH the anchor there: the change moves with it.
    int qx = 0, qy = 0;
    const json other = pickOnBody(s, {190, 200, 180}, qx, qy);
    ASSERT_TRUE(other.is_object()) << "no pixel of the legs hit";
    Reply patched = h.patch(s + "/placements/decal", {{"anchor", other["anchor"]}});
    ASSERT_EQ(patched.status, 200) << patched;
    Reply moved = h.get(s + "/frame-diff?against=off");
    ASSERT_EQ(moved.status, 200);
    const Lit l = litOf(moved);
    EXPECT_GT(l.count, 20);
    EXPECT_LE(std::max(std::abs(l.y0 - qy), std::abs(l.y1 - qy)), 40);

    // Bad surface members are 422 with the field named.
    expectError(h.patch(s + "/placements/decal", {{"size", {0, 1}}}), 422, "/placements/0/size/0");
    // A merge patch merges into the anchor: null removes a member, which is required.
    expectError(h.patch(s + "/placements/decal", {{"anchor", {{"normal", nullptr}}}}), 422,
                "/placements/0/anchor/normal");
    expectError(h.patch(s + "/placements/decal", {{"anchor", {{"tangent", other["anchor"]["normal"]}}}}),
                422, "/placements/0/anchor/tangent");
    // The same decal in the generated layout (SPEC §8: identical in every layout) changes the
    // frame at the same place.
    json generated = h.get(s).js()["scene"];
    generated["uv_layout"] = "generated";
    Reply put = h.put(s, generated);
    ASSERT_EQ(put.status, 200) << put;
    EXPECT_EQ(put.js()["scene"]["uv_layout"], "generated");
    Reply inGenerated = h.get(s + "/frame-diff?against=off");
    ASSERT_EQ(inGenerated.status, 200) << inGenerated;
    const Lit g = litOf(inGenerated);
    EXPECT_GT(g.count, 20);
    EXPECT_LE(std::max(std::abs(g.y0 - qy), std::abs(g.y1 - qy)), 40);
    ASSERT_EQ(h.del(s).status, 204);
}

// The texture view's outline (GET /scenes/{id}/placements/{pid}/outline): a surface decal's border
// in the layout the scene uses, in pieces, inside [0,1]², with its hit test and its anchor's UV
// (the pick's); a UV placement's rotated rectangle and centre; 404 naming the field for an
// unknown placement or scene.
TEST_F(SurfaceHttpTest, OutlinesOfASurfaceAndAUvPlacement) {
    Http h = http();
    const std::string id = createScene(emptyScene("builtin:default"));
    const std::string s = "/scenes/" + id;
    int px = 0, py = 0;
    const json pick = pickOnBody(s, {110, 120, 100}, px, py);
    ASSERT_TRUE(pick.is_object()) << "no pixel of the torso hit";
    ASSERT_EQ(h.post(s + "/placements", decalAt(pick, "decal", 0.12)).status, 201);
    const double u = pick["uv"][0], v = pick["uv"][1];
    auto expectInside = [](const json& o) {
        ASSERT_GE(o["pieces"].get<int>(), 1) << o;
        ASSERT_EQ(o["bounds"].size(), o["pieces"].get<std::size_t>());
        EXPECT_GE(o["segments"].size(), 8u) << "a decal crossing triangles has more than a rectangle's sides";
        for (const json& seg : o["segments"]) {
            ASSERT_EQ(seg.size(), 4u);
            for (const json& x : seg) {
                EXPECT_GE(x.get<double>(), 0.0);
                EXPECT_LE(x.get<double>(), 1.0);
            }
        }
        EXPECT_EQ(o["truncated"], false);
    };
    const std::string at = "?u=" + std::to_string(u) + "&v=" + std::to_string(v);
    Reply r = h.get(s + "/placements/decal/outline" + at);
    ASSERT_EQ(r.status, 200) << r;
    json o = r.js();
    EXPECT_EQ(o["placement"], "decal");
    EXPECT_EQ(o["projection"], "surface");
    // The layout the scene's maps use (auto: what the model's uv-layout route answers).
    EXPECT_EQ(o["layout"], h.get("/models/builtin:default/uv-layout").js()["layout"]);
    expectInside(o);
    EXPECT_EQ(o["hit"], true) << "the picked point is inside the decal";
    // Its anchor in UV: the pick's UV (the decal is anchored where the pick landed).
    ASSERT_TRUE(o["anchor_uv"].is_array()) << o;
    ASSERT_EQ(o["anchor_uv"].size(), 2u);
    EXPECT_NEAR(o["anchor_uv"][0].get<double>(), u, 0.01) << o["anchor_uv"];
    EXPECT_NEAR(o["anchor_uv"][1].get<double>(), v, 0.01) << o["anchor_uv"];
    // Its piece's bounds hold the picked point; a point far from it is outside.
    bool within = false;
    for (const json& b : o["bounds"])
        within = within || (b[0].get<double>() <= u + 1e-5 && u - 1e-5 <= b[2].get<double>() &&
                            b[1].get<double>() <= v + 1e-5 && v - 1e-5 <= b[3].get<double>());
    EXPECT_TRUE(within) << o["bounds"];
    int qx = 0, qy = 0;
    const json legs = pickOnBody(s, {190, 200, 180}, qx, qy);
    ASSERT_TRUE(legs.is_object());
    Reply far = h.get(s + "/placements/decal/outline?u=" + std::to_string(legs["uv"][0].get<double>()) +
                      "&v=" + std::to_string(legs["uv"][1].get<double>()));
    ASSERT_EQ(far.status, 200) << far;
    EXPECT_EQ(far.js()["hit"], false);
    EXPECT_FALSE(h.get(s + "/placements/decal/outline").js().contains("hit")) << "hit only with u, v";

    // In the generated layout the same decal lies elsewhere in UV, still inside [0,1]².
    json generated = h.get(s).js()["scene"];
    generated["uv_layout"] = "generated";
    ASSERT_EQ(h.put(s, generated).status, 200);
    Reply g = h.get(s + "/placements/decal/outline");
    ASSERT_EQ(g.status, 200) << g;
    EXPECT_EQ(g.js()["layout"], "generated");
    expectInside(g.js());
    EXPECT_NE(g.js()["segments"], o["segments"]);
    // The anchor's UV in that layout lies within one of its pieces' bounds.
    const json gj = g.js();
    ASSERT_TRUE(gj["anchor_uv"].is_array()) << gj;
    const double gu = gj["anchor_uv"][0], gv = gj["anchor_uv"][1];
    bool anchorWithin = false;
    for (const json& b : gj["bounds"])
        anchorWithin = anchorWithin || (b[0].get<double>() <= gu + 1e-5 && gu - 1e-5 <= b[2].get<double>() &&
                                        b[1].get<double>() <= gv + 1e-5 && gv - 1e-5 <= b[3].get<double>());
    EXPECT_TRUE(anchorWithin) << gj["anchor_uv"] << " " << gj["bounds"];

    // A UV placement: its rectangle turned by 30° (SPEC: s = R(−rotation)·(p − center)/scale + ½).
    Reply add = h.post(s + "/placements", {{"id", "rect"}, {"pattern", "crease"}, {"joint", pick["suggested"]["joint"]},
                                           {"center", {0.3, 0.6}}, {"scale", {0.2, 0.1}}, {"rotation", 30}});
    ASSERT_EQ(add.status, 201) << add;
    Reply rect = h.get(s + "/placements/rect/outline");
    ASSERT_EQ(rect.status, 200) << rect;
    EXPECT_EQ(rect.js()["projection"], "uv");
    EXPECT_EQ(rect.js()["pieces"], 1);
    ASSERT_EQ(rect.js()["segments"].size(), 4u);
    // Corner s = (0, 0): 0.3 − 0.1·cos30° + 0.05·sin30°, 0.6 − 0.1·sin30° − 0.05·cos30°.
    EXPECT_NEAR(rect.js()["segments"][0][0].get<double>(), 0.23840, 1e-5);
    EXPECT_NEAR(rect.js()["segments"][0][1].get<double>(), 0.50670, 1e-5);
    EXPECT_EQ(h.get(s + "/placements/rect/outline?u=0.3&v=0.6").js()["hit"], true);
    EXPECT_EQ(rect.js()["anchor_uv"], json({0.3, 0.6})) << "a UV placement's anchor is its center";

    // Unknown placement or scene: 404 naming the field; half a texture point: 422.
    expectError(h.get(s + "/placements/nope/outline"), 404, "placement");
    expectError(h.get("/scenes/s_0000000000000000/placements/decal/outline"), 404, "id");
    expectError(h.get(s + "/placements/decal/outline?u=0.5"), 422, "v");
    expectError(h.get(s + "/placements/decal/outline?u=2&v=0.5"), 422, "u");
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(SurfaceHttpTest, BatchAndSweepTakeSurfacePlacements) {
    Http h = http();
    const std::string id = createScene(emptyScene("builtin:default"));
    const std::string s = "/scenes/" + id;
    int px = 0, py = 0;
    const json pick = pickOnBody(s, {110, 120, 100}, px, py);
    ASSERT_TRUE(pick.is_object());
    json doc = emptyScene("builtin:default");
    doc["placements"].push_back(decalAt(pick, "decal", 0.12));
    json off = doc;
    off["placements"][0]["enabled"] = false;
    auto frame = [&](const json& scene) {
        Reply r = h.post("/render", {{"scene", scene}, {"frames", json::array({json{{"time", 0.0}}})},
                                     {"format", "png"}});
        EXPECT_EQ(r.status, 200) << r;
        const auto parts = multipartAnswerParts(r);
        EXPECT_EQ(parts.size(), 1u) << r;
        return parts.empty() ? std::string() : parts[0].content;
    };
    const std::string with = frame(doc), without = frame(off);
    ASSERT_FALSE(with.empty());
    EXPECT_NE(with, without) << "the batch renders the decal";
    EXPECT_EQ(with, frame(doc)) << "deterministic";
    // The scene's own frame at that time is the batch's.
    json stored = doc;
    ASSERT_EQ(h.put(s, stored).status, 200);
    Reply own = h.get(s + "/frame?time=0");
    ASSERT_EQ(own.status, 200) << own;
    EXPECT_EQ(own.body, with);
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(SurfaceHttpTest, CesiumManTakesASurfacePlacement) {
    const std::string model = uploadModel(kCesiumMan);
    const std::string id = createScene(emptyScene(model));
    const std::string s = "/scenes/" + id;
    int px = 0, py = 0;
    const json pick = pickOnBody(s, {110, 120, 100, 130}, px, py);
    ASSERT_TRUE(pick.is_object()) << "no pixel of CesiumMan's body hit";
    ASSERT_TRUE(pick.contains("anchor"));
    expectLocalDecal(s, pick, px, py, 0.12, 50);
    Http h = http();
    // SPEC §8: the decal is the same in every layout — CesiumMan's own UVs and the generated
    // layout give the same frame up to the maps' sampling (different texel densities).
    Reply own = h.get(s + "/frame?format=png");
    ASSERT_EQ(own.status, 200);
    json doc = h.get(s).js()["scene"];
    doc["uv_layout"] = "generated";
    ASSERT_EQ(h.put(s, doc).status, 200);
    Reply gen = h.get(s + "/frame?format=png");
    ASSERT_EQ(gen.status, 200);
    auto a = decodeFrame(own.bytes()), b = decodeFrame(gen.bytes());
    ASSERT_TRUE(a && b);
    ASSERT_EQ(a->rgba.size(), b->rgba.size());
    double sum = 0;
    int worst = 0;
    long far = 0;
    for (std::size_t k = 0; k < a->rgba.size(); ++k) {
        const int d = std::abs(int(a->rgba[k]) - int(b->rgba[k]));
        sum += d;
        worst = std::max(worst, d);
        far += d > 24;
    }
    const double mean = sum / double(a->rgba.size());
    std::printf("CesiumMan decal, model vs generated layout: mean |d| %.4f, max %d, %ld channels > 24\n", mean, worst,
                far);
    EXPECT_LT(mean, 0.05);  // seen: 0.0008
    EXPECT_LE(worst, 8);    // seen: 2 (of 255)
    EXPECT_EQ(far, 0);
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(SurfaceHttpTest, RiggedFigureWithoutUvsRefusesSurfacePlacementsInItsOwnLayout) {
    Http h = http();
    const std::string model = uploadModel(kRiggedFigure);
    const std::string id = createScene(emptyScene(model));
    const std::string s = "/scenes/" + id;
    // Pick works without UVs and answers an anchor.
    int px = 0, py = 0;
    const json pick = pickOnBody(s, {110, 120, 100, 130, 90}, px, py);
    ASSERT_TRUE(pick.is_object()) << "no pixel of the figure hit";
    ASSERT_TRUE(pick.contains("anchor"));
    // The model's own (missing) UVs cannot hold the maps: a clear error naming /uv_layout.
    json doc = emptyScene(model);
    doc["uv_layout"] = "model";
    doc["placements"].push_back(decalAt(pick, "decal", 0.1));
    Reply r = h.put(s, doc);
    expectError(r, 422, "/uv_layout");
    EXPECT_NE(r.body.find("generated"), std::string::npos) << r;
    ASSERT_EQ(h.del(s).status, 204);
}

// Issue #22's acceptance: on a palette atlas (the KayKit Barbarian: texels shared by the hat, the
// body and both arms) and on a model without UVs (RiggedFigure), one surface placement at one
// elbow with `uv_layout: auto` changes frame pixels only near that elbow — auto lays the height
// maps out anew (the generated layout), so no other region shares the decal's texels. In the
// model's own UVs the Barbarian's decal shows elsewhere too (checked, so the test can fail).
TEST_F(SurfaceHttpTest, OneElbowDecalStaysAtThatElbowOnAnyCharacter) {
    struct Case {
        std::string path;
        std::vector<std::string> elbow;
        double size; // model units: the Barbarian's elbow is wider than RiggedFigure's
    };
    // Scans a grid of the frame for a pick whose suggested driver is one of `joints`.
    auto pickDrivenBy = [](const std::string& s, const std::vector<std::string>& joints, int& px, int& py) {
        Http h = http();
        for (int y = 24; y < 232; y += 8)
            for (int x = 8; x < 248; x += 8) {
                Reply r = h.get(s + "/pick?x=" + std::to_string(x) + "&y=" + std::to_string(y));
                if (r.status != 200 || r.js()["hit"] != true || !r.js().contains("suggested")) continue;
                const std::string j = r.js()["suggested"].value("joint", "");
                if (std::find(joints.begin(), joints.end(), j) == joints.end()) continue;
                px = x;
                py = y;
                return r.js();
            }
        return json();
    };
    for (const Case& c : {Case{kBarbarian, {"lowerarm.r", "lowerarm.l"}, 0.18},
                          Case{kRiggedFigure, {"arm_joint_R_2", "arm_joint_L_2", "arm_joint_R_3", "arm_joint_L_3"}, 0.08}}) {
        SCOPED_TRACE(c.path);
        Http h = http();
        const std::string model = uploadModel(c.path, false); // RiggedFigure's test may have sent it
        const std::string id = createScene(emptyScene(model));
        const std::string s = "/scenes/" + id;
        int px = 0, py = 0;
        const json pick = pickDrivenBy(s, c.elbow, px, py);
        ASSERT_TRUE(pick.is_object()) << "no pixel of an elbow found";
        expectLocalDecal(s, pick, px, py, c.size, 45);
        EXPECT_EQ(h.get("/models/" + model + "/uv-layout").js()["layout"], "generated");
        if (c.path == kBarbarian) {
            // The same decal in the model's own (shared) texels lights pixels far from the elbow.
            json own = h.get(s).js()["scene"];
            own["uv_layout"] = "model";
            ASSERT_EQ(h.put(s, own).status, 200);
            const Lit l = litOf(h.get(s + "/frame-diff?against=off"));
            EXPECT_GT(std::max({std::abs(l.x0 - px), std::abs(l.x1 - px), std::abs(l.y0 - py), std::abs(l.y1 - py)}), 40)
                << "in the palette atlas the decal also shows on the regions sharing its texels";
        }
        ASSERT_EQ(h.del(s).status, 204);
    }
}

// The editor's outlines of surface placements (SPEC §8): a selected decal is outlined on the rest
// surface and the surface place brush is a circle there — both only near the decal's pixel; the
// frame without them is unchanged; a bad brush is 422 naming it.
TEST_F(SurfaceHttpTest, SelectedDecalAndSurfaceBrushAreOutlinedWhereTheyAre) {
    Http h = http();
    const std::string id = createScene(emptyScene("builtin:default"));
    const std::string s = "/scenes/" + id;
    int px = 0, py = 0;
    const json pick = pickOnBody(s, {110, 120, 100}, px, py);
    ASSERT_TRUE(pick.is_object()) << "no pixel of the torso hit";
    ASSERT_EQ(h.post(s + "/placements", decalAt(pick, "decal", 0.12)).status, 201);

    auto frame = [&](const std::string& extra) {
        Reply r = h.get(s + "/frame?patterns=off" + extra);
        EXPECT_EQ(r.status, 200) << r;
        auto img = decodeFrame(r.bytes());
        EXPECT_TRUE(img);
        return img ? *img : Image8{};
    };
    const auto plain = frame("");
    auto changed = [&](const std::string& extra) {
        const auto other = frame(extra);
        Lit l;
        if (other.rgba.size() != plain.rgba.size()) return l;
        for (int y = 0; y < plain.height; ++y)
            for (int x = 0; x < plain.width; ++x) {
                const std::size_t i = (static_cast<std::size_t>(y) * plain.width + x) * 4;
                if (std::memcmp(&plain.rgba[i], &other.rgba[i], 3) == 0) continue;
                ++l.count;
                l.x0 = std::min(l.x0, x);
                l.y0 = std::min(l.y0, y);
                l.x1 = std::max(l.x1, x);
                l.y1 = std::max(l.y1, y);
            }
        return l;
    };
    auto expectNear = [&](const Lit& l, const char* what) {
        EXPECT_GT(l.count, 20) << what << " drew nothing";
        EXPECT_LE(std::max(std::abs(l.x0 - px), std::abs(l.x1 - px)), 40) << what << ": " << l.x0 << ".." << l.x1 << " vs " << px;
        EXPECT_LE(std::max(std::abs(l.y0 - py), std::abs(l.y1 - py)), 40) << what << ": " << l.y0 << ".." << l.y1 << " vs " << py;
    };
    expectNear(changed("&highlight=decal"), "the selected decal");
    expectNear(changed("&hover=decal"), "the hovered decal");
    std::string brush;
    for (const char* key : {"position", "normal"})
        for (int k = 0; k < 3; ++k) brush += std::to_string(pick["anchor"][key][k].get<double>()) + ",";
    expectNear(changed("&surface_brush=" + brush + "0.12"), "the surface brush");
    EXPECT_EQ(changed("&surface_brush=" + brush + "0.12").count, changed("&surface_brush=" + brush + "0.12").count)
        << "deterministic";
    // A smaller brush draws a smaller circle.
    const Lit small = changed("&surface_brush=" + brush + "0.04");
    const Lit large = changed("&surface_brush=" + brush + "0.12");
    EXPECT_LT(small.x1 - small.x0, large.x1 - large.x0);

    for (const std::string bad : {"1,2,3,0,0,1", "0,0,0,0,0,0,0.1", "0,0,0,0,0,1,0", "0,0,0,0,0,1,20000", "a,0,0,0,0,1,1"}) {
        Reply r = h.get(s + "/frame?surface_brush=" + bad);
        EXPECT_EQ(r.status, 422) << bad << ": " << r;
        EXPECT_EQ(r.js()["error"]["field"], "surface_brush") << bad;
    }
}
