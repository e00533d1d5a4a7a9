// ScenesHttpTest — the /api/v1/scenes routes end to end on one server (HttpTestFixture.hpp: a real
// dermis::Service + dermis::Api on 127.0.0.1, a GL context on $DERMIS_TEST_GL, cpp-httplib clients
// over loopback). It checks:
//   * scenes: create (default pattern set), get, list, replace, placement add/patch/reorder/delete,
//     pose put/patch (merge, null removal), revisions, frames (PNG/JPEG, size, backend header,
//     changing with the pose), height maps (png16/exr/f32, normal), delete.
#include "HttpTestFixture.hpp"
#include "io/webp_encode.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// One server (no token).
class ScenesHttpTest : public SharedServerTest {};

// ================================================================================================
// Scenes: documents, edits, renders
// ================================================================================================

TEST_F(ScenesHttpTest, SceneLifecycleWithEditsAndRenders) {
    Http h = http();
    Reply created = h.post("/scenes", {{"default_patterns", true}});
    ASSERT_EQ(created.status, 201) << created;
    const std::string id = created.js()["id"];
    EXPECT_EQ(id.rfind("s_", 0), 0u) << id;
    EXPECT_EQ(created.header("Location"), kApi + "/scenes/" + id);
    EXPECT_EQ(created.js()["revision"], 1);
    EXPECT_EQ(created.js()["scene"]["placements"].size(), 18u);
    EXPECT_EQ(created.js()["scene"]["model"], "builtin:default");

    Reply got = h.get("/scenes/" + id);
    ASSERT_EQ(got.status, 200) << got;
    EXPECT_EQ(got.js()["scene"], created.js()["scene"]);
    bool listed = false;
    for (const json all = h.get("/scenes").js(); const json& s : all["scenes"])
        listed = listed || (s["id"] == id && s["placements"] == 18);
    EXPECT_TRUE(listed);

    std::uint64_t rev = 1;
    auto expectRevision = [&](const Reply& r, int status) {
        ASSERT_EQ(r.status, status) << r;
        EXPECT_EQ(r.js()["revision"], ++rev) << r;
        EXPECT_EQ(h.get("/scenes/" + id).js()["revision"], rev);
    };

    // Replace.
    Reply put = h.put("/scenes/" + id, smallScene());
    expectRevision(put, 200);
    ASSERT_EQ(put.js()["scene"]["placements"].size(), 1u);

    // Add a placement without an id: one is generated.
    json added = placementOf("crease");
    added["joint"] = "forearm.r";
    Reply add = h.post("/scenes/" + id + "/placements", added);
    expectRevision(add, 201);
    const json pl = add.js()["scene"]["placements"];
    ASSERT_EQ(pl.size(), 2u);
    const std::string newId = pl[1]["id"];
    EXPECT_FALSE(newId.empty());
    EXPECT_NE(newId, "elbow");

    // Partial update: only the centre moves.
    Reply patched = h.patch("/scenes/" + id + "/placements/" + newId, {{"center", {0.6, 0.55}}});
    expectRevision(patched, 200);
    const json p1 = patched.js()["scene"]["placements"][1];
    EXPECT_EQ(p1["id"], newId);
    EXPECT_NEAR(p1["center"][0].get<double>(), 0.6, 1e-12);
    EXPECT_NEAR(p1["center"][1].get<double>(), 0.55, 1e-12);
    EXPECT_EQ(p1["joint"], "forearm.r");
    EXPECT_EQ(p1["pattern"], "crease");
    EXPECT_NEAR(p1["scale"][0].get<double>(), 0.2, 1e-12);

    // Reorder.
    Reply reordered = h.put("/scenes/" + id + "/placements", json::array({newId, "elbow"}));
    expectRevision(reordered, 200);
    EXPECT_EQ(reordered.js()["scene"]["placements"][0]["id"], newId);
    EXPECT_EQ(reordered.js()["scene"]["placements"][1]["id"], "elbow");

    // Remove.
    Reply removed = h.del("/scenes/" + id + "/placements/" + newId);
    expectRevision(removed, 200);
    ASSERT_EQ(removed.js()["scene"]["placements"].size(), 1u);
    EXPECT_EQ(removed.js()["scene"]["placements"][0]["id"], "elbow");

    // Pose: replace, then merge (time replaced, joints merged, null removes one).
    Reply pose = h.put("/scenes/" + id + "/pose",
                       json::parse(R"({"animation": "elbow_curl", "time": 0.25, "joints": {
                           "spine_02": {"axis_angles": {"x": 10}},
                           "neck_01": {"axis_angles": {"y": 20}}}})"));
    expectRevision(pose, 200);
    EXPECT_EQ(pose.js()["scene"]["pose"]["time"], 0.25);
    Reply merged =
        h.patch("/scenes/" + id + "/pose", json::parse(R"({"time": 0.5, "joints": {"neck_01": null,
                               "head": {"axis_angles": {"x": 5}}}})"));
    expectRevision(merged, 200);
    const json mp = merged.js()["scene"]["pose"];
    EXPECT_EQ(mp["time"], 0.5);
    EXPECT_EQ(mp["animation"], "elbow_curl");
    EXPECT_TRUE(mp["joints"].contains("spine_02")) << mp;
    EXPECT_TRUE(mp["joints"].contains("head")) << mp;
    EXPECT_FALSE(mp["joints"].contains("neck_01")) << mp;

    // Frames: size from the query, format, backend header.
    const std::string backendName = h.get("/info").js()["backend"];
    Reply png = h.get("/scenes/" + id + "/frame?width=128&height=96");
    ASSERT_EQ(png.status, 200) << png;
    EXPECT_EQ(png.header("Content-Type"), "image/png");
    EXPECT_EQ(png.header("X-Dermis-Backend"), backendName);
    auto a = decodeFrame(png.bytes());
    ASSERT_TRUE(a) << a.error().message;
    EXPECT_EQ(a->width, 128);
    EXPECT_EQ(a->height, 96);
    Reply jpeg =
        h.get("/scenes/" + id + "/frame?format=jpeg&width=120&height=80&msaa=2&yaw=30&pitch=5");
    ASSERT_EQ(jpeg.status, 200) << jpeg;
    EXPECT_EQ(jpeg.header("Content-Type"), "image/jpeg");
    EXPECT_TRUE(jpeg.hasHeader("X-Dermis-Backend"));
    auto j = decodeFrame(jpeg.bytes());
    ASSERT_TRUE(j) << j.error().message;
    EXPECT_EQ(j->width, 120);
    EXPECT_EQ(j->height, 80);
    // Lossless WebP: its own content type and magic bytes, the same pixels as the PNG frame.
    Reply webp = h.get("/scenes/" + id + "/frame?format=webp&width=128&height=96");
    ASSERT_EQ(webp.status, 200) << webp;
    EXPECT_EQ(webp.header("Content-Type"), "image/webp");
    const std::vector<std::uint8_t> webpBytes = webp.bytes();
    ASSERT_GE(webpBytes.size(), 12u);
    EXPECT_EQ(std::string(webpBytes.begin(), webpBytes.begin() + 4), "RIFF");
    EXPECT_EQ(std::string(webpBytes.begin() + 8, webpBytes.begin() + 12), "WEBP");
    auto w = decodeWebp(webpBytes);
    ASSERT_TRUE(w) << w.error().message;
    EXPECT_EQ(w->width, 128);
    EXPECT_EQ(w->height, 96);
    EXPECT_EQ(w->rgba, a->rgba); // both lossless and opaque
    // Unknown formats are still refused, naming the parameter.
    for (const char* f : {"gif", "WEBP", "webp-lossy", ""}) {
        Reply bad = h.get("/scenes/" + id + "/frame?width=32&height=32&format=" + std::string(f));
        EXPECT_EQ(bad.status, 422) << f << bad;
        EXPECT_EQ(bad.js()["error"]["field"], "format") << f << bad;
    }

    // Two pose times give different frames (the elbow curls); the same time the same frame.
    ASSERT_EQ(h.patch("/scenes/" + id + "/pose", {{"time", 0.0}}).status, 200);
    ++rev;
    auto f0 = decodeFrame(h.get("/scenes/" + id + "/frame").bytes());
    auto f0again = decodeFrame(h.get("/scenes/" + id + "/frame").bytes());
    ASSERT_EQ(h.patch("/scenes/" + id + "/pose", {{"time", 1.0}}).status, 200);
    ++rev;
    auto f1 = decodeFrame(h.get("/scenes/" + id + "/frame").bytes());
    ASSERT_TRUE(f0 && f0again && f1);
    EXPECT_EQ(f0->width, 128); // render.size of the document
    EXPECT_GT(pixelsDiffering(*f0, *f1), 20u);
    EXPECT_EQ(pixelsDiffering(*f0, *f0again), 0u);
    // The query's time overrides the pose's without an edit.
    auto q0 = decodeFrame(h.get("/scenes/" + id + "/frame?time=0").bytes());
    ASSERT_TRUE(q0);
    EXPECT_EQ(pixelsDiffering(*f0, *q0), 0u);
    EXPECT_EQ(h.get("/scenes/" + id).js()["revision"], rev);

    // Height maps.
    for (const char* map : {"bump", "displacement"}) {
        SCOPED_TRACE(map);
        const std::string base = "/scenes/" + id + "/heightmaps/" + map;
        Reply p16 = h.get(base + "?format=png16");
        ASSERT_EQ(p16.status, 200) << p16;
        EXPECT_TRUE(isPng(p16.body));
        EXPECT_EQ(pngBitDepth(p16.body), 16);
        Reply dflt = h.get(base);
        ASSERT_EQ(dflt.status, 200) << dflt;
        EXPECT_TRUE(isPng(dflt.body));
        Reply exr = h.get(base + "?format=exr");
        ASSERT_EQ(exr.status, 200) << exr;
        EXPECT_TRUE(isExr(exr.body));
        Reply f32 = h.get(base + "?format=f32");
        ASSERT_EQ(f32.status, 200) << f32;
        EXPECT_EQ(f32.body.size(), 4u * 256 * 256);
        EXPECT_EQ(f32.header("Content-Type"), "application/octet-stream");
    }
    Reply normal = h.get("/scenes/" + id + "/heightmaps/normal");
    ASSERT_EQ(normal.status, 200) << normal;
    auto n = decodeFrame(normal.bytes());
    ASSERT_TRUE(n) << n.error().message;
    EXPECT_EQ(n->width, 256);
    EXPECT_EQ(n->height, 256);
    Reply nexr = h.get("/scenes/" + id + "/heightmaps/normal?format=exr");
    ASSERT_EQ(nexr.status, 200) << nexr;
    EXPECT_TRUE(isExr(nexr.body));

    // Delete.
    EXPECT_EQ(h.del("/scenes/" + id).status, 204);
    expectError(h.get("/scenes/" + id), 404, "id");
    expectError(h.get("/scenes/" + id + "/frame"), 404, "id");
    expectError(h.del("/scenes/" + id), 404, "id");
}

TEST_F(ScenesHttpTest, DisabledAndLabelledPlacements) {
    Http h = http();
    const std::string id = createScene(smallScene());
    const std::string s = "/scenes/" + id;
    Reply on = h.get(s + "/heightmaps/bump?format=f32");
    ASSERT_EQ(on.status, 200) << on;
    Reply patched = h.patch(s + "/placements/elbow", {{"enabled", false}, {"label", "left elbow crease"}});
    ASSERT_EQ(patched.status, 200) << patched;
    EXPECT_EQ(patched.js()["scene"]["placements"][0]["enabled"], false);
    EXPECT_EQ(patched.js()["scene"]["placements"][0]["label"], "left elbow crease");
    Reply off = h.get(s + "/heightmaps/bump?format=f32");
    ASSERT_EQ(off.status, 200) << off;
    ASSERT_EQ(off.body.size(), on.body.size());
    EXPECT_NE(on.body, off.body);
    EXPECT_EQ(off.body, std::string(off.body.size(), '\0')) << "a disabled placement contributes nothing";
    expectError(h.patch(s + "/placements/elbow", {{"enabled", "no"}}), 422, "/placements/0/enabled");
    expectError(h.patch(s + "/placements/elbow", {{"label", std::string(121, 'x')}}), 422,
                "/placements/0/label");
    EXPECT_EQ(h.get(s).js()["revision"], 2);
    EXPECT_EQ(h.del(s).status, 204);
}

} // namespace
