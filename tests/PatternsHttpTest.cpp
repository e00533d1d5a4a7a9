// PatternsHttpTest — the /api/v1/patterns routes end to end on one server (HttpTestFixture.hpp: a
// real dermis::Service + dermis::Api on 127.0.0.1, a GL context on $DERMIS_TEST_GL, cpp-httplib
// clients over loopback). It checks:
//   * patterns: the built-in manifest and previews, a custom PNG upload used by id and through a
//     scene's alias map, 409 while in use, 204 once unused (an alias no placement names is
//     dropped); previews of tall patterns keep the aspect ratio.
#include "BuildPaths.hpp"
#include "HttpTestFixture.hpp"
#include "common/sha256.hpp"

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

// Issue #12.6: previews fit the longer side into `size` and keep the aspect ratio, for tall and
// wide patterns alike (a 1×4096 one at size 256 once asked for 256×1048576 pixels).
TEST_F(PatternsHttpTest, TallAndWidePatternPreviewsKeepTheAspect) {
    Http h = http();
    for (const auto& [w, ht] : {std::pair{1, 4096}, std::pair{4096, 1}, std::pair{30, 120}}) {
        Reply up = h.upload("/patterns?name=thin", domePng(w, ht), "image/png");
        ASSERT_EQ(up.status, 201) << up;
        const std::string pid = up.js()["id"];
        for (int size : {1, 5, 256, 2048}) {
            Reply img = h.get("/patterns/" + pid + "/image?size=" + std::to_string(size));
            ASSERT_EQ(img.status, 200) << w << "x" << ht << " size " << size << ": " << img;
            auto dec = decodeFrame(img.bytes());
            ASSERT_TRUE(dec) << dec.error().message;
            const int longer = std::max(w, ht), shorter = std::min(w, ht);
            const int expectShort = std::max(1, static_cast<int>(std::lround(double(shorter) * size / longer)));
            EXPECT_EQ(w >= ht ? dec->width : dec->height, size) << w << "x" << ht << " size " << size;
            EXPECT_EQ(w >= ht ? dec->height : dec->width, expectShort) << w << "x" << ht << " size " << size;
        }
        expectError(h.get("/patterns/" + pid + "/image?size=2049"), 422, "size");
        expectError(h.get("/patterns/" + pid + "/image?size=0"), 422, "size");
        EXPECT_EQ(h.del("/patterns/" + pid).status, 204);
    }
}

// Issue #12.5: placing an uploaded pattern by id adds the alias {p: p}; once the last placement
// using it goes, the alias goes too, and the pattern can be deleted.
TEST_F(PatternsHttpTest, StaleAliasDoesNotBlockDeletion) {
    Http h = http();
    Reply up = h.upload("/patterns?name=dome", domePng(), "image/png");
    ASSERT_EQ(up.status, 201) << up;
    const std::string pid = up.js()["id"];
    json doc = smallScene();
    doc["placements"] = {placementOf(pid, "dome")};
    const std::string sid = createScene(doc);
    ASSERT_FALSE(sid.empty());
    Reply got = h.get("/scenes/" + sid);
    ASSERT_EQ(got.status, 200) << got;
    json placed = got.js()["scene"];
    EXPECT_EQ(placed["patterns"][pid], pid);
    expectError(h.del("/patterns/" + pid), 409, "id");

    // The editor's way: the document it got back, less the placement (the alias left in).
    placed["placements"] = json::array();
    Reply put = h.put("/scenes/" + sid, placed);
    ASSERT_EQ(put.status, 200) << put;
    EXPECT_FALSE(put.js()["scene"].contains("patterns") && put.js()["scene"]["patterns"].contains(pid))
        << put.js()["scene"].dump();
    EXPECT_EQ(h.del("/patterns/" + pid).status, 204);
    // The scene still validates without the pattern.
    EXPECT_EQ(h.put("/scenes/" + sid, put.js()["scene"]).status, 200);
    EXPECT_EQ(h.del("/scenes/" + sid).status, 204);
}

} // namespace

// Issue #14: pattern uploads are content-addressed: the same image bytes twice answer 200 with the
// first id ("p_" + 16 hex digits of their SHA-256), one entry listed; other bytes another id.
TEST_F(PatternsHttpTest, SameBytesUploadTwiceGiveTheSameId) {
    Http h = http();
    const auto png = domePng();
    const std::size_t before = h.get("/patterns").js()["patterns"].size();
    Reply first = h.upload("/patterns?name=dome", png, "image/png");
    ASSERT_EQ(first.status, 201) << first;
    const std::string id = first.js()["id"];
    EXPECT_EQ(id, "p_" + toHex(sha256(png)).substr(0, 16));
    Reply again = h.upload("/patterns?name=dome2", png, "image/png");
    ASSERT_EQ(again.status, 200) << again;
    EXPECT_EQ(again.js()["id"], id);
    EXPECT_EQ(again.js()["name"], "dome");
    EXPECT_EQ(h.get("/patterns").js()["patterns"].size(), before + 1);
    Reply third = h.upload(
        "/patterns", readBytes(std::string(dermis::build::sourceDir()) + "/patterns/crease.png"),
        "image/png");
    ASSERT_EQ(third.status, 201) << third;
    EXPECT_NE(third.js()["id"], id);
    EXPECT_EQ(h.del("/patterns/" + id).status, 204);
    EXPECT_EQ(h.del("/patterns/" + third.js()["id"].get<std::string>()).status, 204);
}
