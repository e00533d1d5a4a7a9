// PatternsHttpTest — the /api/v1/patterns routes end to end on one server (HttpTestFixture.hpp: a
// real dermis::Service + dermis::Api on 127.0.0.1, a GL context on $DERMIS_TEST_GL, cpp-httplib
// clients over loopback). It checks:
//   * patterns: the built-in manifest and previews, a custom PNG upload used by id and through a
//     scene's alias map, 409 while in use, 204 once unused.
#include "HttpTestFixture.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// One server (no token).
class PatternsHttpTest : public SharedServerTest {};

// ================================================================================================
// Patterns
// ================================================================================================

TEST_F(PatternsHttpTest, BuiltinPatternsAndPreviews) {
    Http h = http();
    Reply list = h.get("/patterns");
    ASSERT_EQ(list.status, 200) << list;
    std::set<std::string> builtins;
    for (const json all = list.js(); const json& p : all["patterns"])
        if (p["builtin"].get<bool>()) builtins.insert(p["id"].get<std::string>());
    EXPECT_EQ(builtins.size(), 9u);
    for (const char* id : {"crease", "stomach_wrinkles", "waist_twist", "neck_rings", "round_bulge",
                           "elongated_bulge", "clavicle", "ribs", "scapula"})
        EXPECT_TRUE(builtins.count(id)) << id;

    Reply img = h.get("/patterns/crease/image");
    ASSERT_EQ(img.status, 200) << img;
    EXPECT_EQ(img.header("Content-Type"), "image/png");
    auto dec = decodeFrame(img.bytes());
    ASSERT_TRUE(dec) << dec.error().message;
    EXPECT_EQ(dec->width, 256);
    auto small = decodeFrame(h.get("/patterns/crease/image?size=64").bytes());
    ASSERT_TRUE(small);
    EXPECT_EQ(small->width, 64);
    EXPECT_EQ(small->height, 64);
}

TEST_F(PatternsHttpTest, CustomPatternUploadUseAndDelete) {
    Http h = http();
    Reply up = h.upload("/patterns?name=dome", domePng(), "image/png");
    ASSERT_EQ(up.status, 201) << up;
    const std::string pid = up.js()["id"];
    EXPECT_EQ(pid.rfind("p_", 0), 0u) << pid;
    EXPECT_EQ(up.js()["name"], "dome");
    EXPECT_EQ(up.js()["width"], 64);
    Reply preview = h.get("/patterns/" + pid + "/image?size=32");
    ASSERT_EQ(preview.status, 200) << preview;
    auto dec = decodeFrame(preview.bytes());
    ASSERT_TRUE(dec);
    EXPECT_GT(dec->rgba[(16 * 32 + 16) * 4], 200); // the dome's top is bright
    bool listed = false;
    for (const json all = h.get("/patterns").js(); const json& p : all["patterns"])
        listed = listed || (p["id"] == pid && !p["builtin"].get<bool>());
    EXPECT_TRUE(listed);

    // Directly by id, driven (the forearm bent 60° about x).
    json doc = smallScene();
    doc["placements"] = {placementOf(pid, "dome")};
    doc["pose"] = {{"joints", {{"forearm.l", {{"axis_angles", {{"x", 60}}}}}}}};
    const std::string sid = createScene(doc);
    ASSERT_FALSE(sid.empty());
    Reply bump = h.get("/scenes/" + sid + "/heightmaps/bump?format=f32");
    ASSERT_EQ(bump.status, 200) << bump;
    ASSERT_EQ(bump.body.size(), 4u * 256 * 256);
    std::vector<float> values(256 * 256);
    std::memcpy(values.data(), bump.body.data(), bump.body.size());
    EXPECT_GT(*std::max_element(values.begin(), values.end()), 0.1f);
    expectError(h.del("/patterns/" + pid), 409, "id");

    // Through the scene's alias map.
    doc["patterns"] = {{"my_dome", pid}};
    doc["placements"] = {placementOf("my_dome", "dome")};
    Reply put = h.put("/scenes/" + sid, doc);
    ASSERT_EQ(put.status, 200) << put;
    EXPECT_EQ(put.js()["scene"]["patterns"]["my_dome"], pid);
    expectError(h.del("/patterns/" + pid), 409, "id");

    // Once no scene names it, it can go.
    json unused = smallScene();
    ASSERT_EQ(h.put("/scenes/" + sid, unused).status, 200);
    EXPECT_EQ(h.del("/patterns/" + pid).status, 204);
    expectError(h.get("/patterns/" + pid + "/image"), 404, "id");
    expectError(h.del("/patterns/" + pid), 404, "id");
    EXPECT_EQ(h.del("/scenes/" + sid).status, 204);
}

} // namespace
