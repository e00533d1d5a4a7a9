// InspectHttpTest — probe and activation over real HTTP (HttpTestFixture.hpp): the probe's
// bump value equals the served f32 map at that texel, contributions name the placement;
// activation of the scene's clip lists every placement; bad parameters are clear 4xx errors;
// frame views (view=shaded|bump|displacement|normal) on frames and frame diffs.
#include "HttpTestFixture.hpp"

#include <cmath>
#include <cstring>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

class InspectHttpTest : public SharedServerTest {};

TEST_F(InspectHttpTest, ProbeAndActivation) {
    Http h = http();
    const std::string id = createScene(smallScene());
    const std::string s = "/scenes/" + id;
    const json placement = smallScene()["placements"][0];
    const double u = placement["center"][0], v = placement["center"][1];

    Reply probe = h.get(s + "/probe?u=" + std::to_string(u) + "&v=" + std::to_string(v));
    ASSERT_EQ(probe.status, 200) << probe;
    const json p = probe.js();
    ASSERT_EQ(p["contributions"].size(), 1u) << p;
    EXPECT_EQ(p["contributions"][0]["placement"], "elbow");
    EXPECT_EQ(p["contributions"][0]["pattern"], "crease");
    EXPECT_EQ(p["contributions"][0]["target"], "bump");
    EXPECT_EQ(p["map_size"], json({256, 256}));
    // The served map holds the same value at that texel (GPU, within its tolerance).
    Reply map = h.get(s + "/heightmaps/bump?format=f32");
    ASSERT_EQ(map.status, 200);
    const int x = p["texel"][0], y = p["texel"][1];
    float served = 0;
    std::memcpy(&served, map.body.data() + (static_cast<std::size_t>(y) * 256 + x) * 4, 4);
    EXPECT_NEAR(served, p["bump"].get<double>(), 2e-3);
    EXPECT_NE(p["bump"].get<double>(), 0.0) << "the elbow crease is active at time 0.5 of elbow_curl";

    Reply act = h.get(s + "/activation?clip=elbow_curl&fps=10");
    ASSERT_EQ(act.status, 200) << act;
    const json a = act.js();
    ASSERT_TRUE(a["placements"].contains("elbow")) << a;
    EXPECT_EQ(a["placements"]["elbow"].size(), a["times"].size());
    EXPECT_TRUE(a["flags"].is_array());

    expectError(h.get(s + "/probe?u=1.5&v=0.5"), 422, "u");
    expectError(h.get(s + "/probe?u=0.5&v=-0.1"), 422, "v");
    expectError(h.get(s + "/probe?u=0.5"), 422, "v");
    expectError(h.get(s + "/probe?u=abc&v=0.5"), 422, "u");
    expectError(h.get(s + "/probe?u=0.5&v=0.5&time=-1"), 422, "time");
    expectError(h.get(s + "/activation?clip=no_such_clip"), 404, "clip");
    expectError(h.get(s + "/activation"), 422, "clip");
    expectError(h.get(s + "/activation?clip=elbow_curl&fps=0"), 422, "fps");
    expectError(h.get(s + "/activation?clip=elbow_curl&fps=1000"), 422, "fps");
    expectError(h.get("/scenes/s_0000000000000000/probe?u=0.5&v=0.5"), 404, "id");
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(InspectHttpTest, LintFindsOverlapsAndUnusedUploads) {
    Http h = http();
    // The shipped default scene has no warnings (unused uploads of other tests are info only).
    Reply defaults = h.post("/scenes", {{"default_patterns", true}});
    ASSERT_EQ(defaults.status, 201) << defaults;
    const std::string ds = "/scenes/" + defaults.js()["id"].get<std::string>();
    Reply defaultLint = h.get(ds + "/lint");
    ASSERT_EQ(defaultLint.status, 200) << defaultLint;
    for (const json findings = defaultLint.js(); const json& f : findings)
        EXPECT_NE(f["severity"], "warning") << f;
    ASSERT_EQ(h.del(ds).status, 204);

    const std::string id = createScene(smallScene());
    const std::string s = "/scenes/" + id;
    Reply clean = h.get(s + "/lint");
    ASSERT_EQ(clean.status, 200) << clean;
    ASSERT_TRUE(clean.js().is_array());
    // smallScene() puts its "elbow" crease at (0.3, 0.4): the chest in the default atlas, where
    // forearm.l has no weight. Lint says so.
    bool noInfluence = false;
    for (const json& f : clean.js())
        noInfluence = noInfluence || (f["code"] == "no_influence" && f["placement"] == "elbow");
    EXPECT_TRUE(noInfluence) << clean;

    json twin = smallScene()["placements"][0];
    twin["id"] = "twin";
    twin["center"][0] = twin["center"][0].get<double>() + 0.01;
    ASSERT_EQ(h.post(s + "/placements", twin).status, 201);
    Reply up = h.upload("/patterns?name=lonely", domePng(), "image/png");
    ASSERT_EQ(up.status, 201) << up;
    const std::string pid = up.js()["id"];
    Reply lint = h.get(s + "/lint");
    ASSERT_EQ(lint.status, 200) << lint;
    bool overlap = false, unused = false;
    for (const json& f : lint.js()) {
        EXPECT_TRUE(f["severity"] == "warning" || f["severity"] == "info") << f;
        overlap = overlap || (f["code"] == "overlap" && f["placement"] == "elbow");
        unused = unused || (f["code"] == "unused_upload" && f["placement"].is_null() &&
                            f["message"].get<std::string>().find(pid) != std::string::npos);
    }
    EXPECT_TRUE(overlap) << lint;
    EXPECT_TRUE(unused) << lint;
    expectError(h.get("/scenes/s_0000000000000000/lint"), 404, "id");
    ASSERT_EQ(h.del("/patterns/" + pid).status, 204);
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(InspectHttpTest, PickHitsTheCharacterAndMissesTheBackground) {
    Http h = http();
    const std::string id = createScene(smallScene());
    const std::string s = "/scenes/" + id;
    Reply bg = h.get(s + "/pick?x=1&y=1&width=128&height=128");
    ASSERT_EQ(bg.status, 200) << bg;
    EXPECT_EQ(bg.js()["hit"], false);
    Reply body = h.get(s + "/pick?x=64&y=50&width=128&height=128");
    ASSERT_EQ(body.status, 200) << body;
    const json p = body.js();
    ASSERT_EQ(p["hit"], true) << p;
    EXPECT_EQ(p["uv"].size(), 2u);
    EXPECT_EQ(p["position"].size(), 3u);
    ASSERT_FALSE(p["joints"].empty());
    EXPECT_LE(p["joints"].size(), 4u);
    double sum = 0;
    for (const json& j : p["joints"]) sum += j["weight"].get<double>();
    EXPECT_LE(sum, 1.0001);
    EXPECT_FALSE(p["suggested"]["joint"].get<std::string>().empty());
    EXPECT_NE(p["suggested"]["theta_min"], p["suggested"]["theta_max"]);

    expectError(h.get(s + "/pick?x=128&y=5&width=128&height=128"), 422, "x");
    expectError(h.get(s + "/pick?x=5&y=-1&width=128&height=128"), 422, "y");
    expectError(h.get(s + "/pick?x=5&y=5&width=0&height=128"), 422, "width");
    expectError(h.get(s + "/pick?y=5"), 422, "x");
    expectError(h.get(s + "/pick?x=5&y=5&pitch=200"), 422, "pitch");
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(InspectHttpTest, MirrorAddsTheTwinOnTheOtherSide) {
    Http h = http();
    Reply created = h.post("/scenes", {{"default_patterns", true}});
    ASSERT_EQ(created.status, 201) << created;
    const std::string s = "/scenes/" + created.js()["id"].get<std::string>();
    json right;
    const json doc = created.js(); // js() parses a fresh value: keep it alive while iterating
    for (const json& p : doc["scene"]["placements"])
        if (p["id"] == "elbow_r") right = p;
    ASSERT_TRUE(right.is_object());
    ASSERT_EQ(h.del(s + "/placements/elbow_r").status, 200);

    ASSERT_EQ(h.patch(s + "/placements/elbow_l", {{"label", "left elbow (L)"}}).status, 200); // r3
    // Based on r2, from before that label: a conflict on the placement mirrored.
    httplib::Headers stale{{"If-Match", "\"r2\""}};
    expectError(h.call("POST", s + "/placements/elbow_l/mirror", "", "", stale), 412, "If-Match");
    Reply m = h.call("POST", s + "/placements/elbow_l/mirror", "", "", {{"X-Dermis-Client", "ana"}});
    ASSERT_EQ(m.status, 201) << m;
    EXPECT_EQ(m.header("ETag"), "\"r4\"");
    json twin;
    const json mirrored = m.js();
    for (const json& p : mirrored["scene"]["placements"])
        if (p["id"] == "elbow_r") twin = p;
    ASSERT_TRUE(twin.is_object()) << m;
    EXPECT_EQ(twin["joint"], "forearm.r");
    EXPECT_EQ(twin["pattern"], "crease");
    EXPECT_EQ(twin["label"], "right elbow (R)");
    const double du = (twin["center"][0].get<double>() - right["center"][0].get<double>()) * 1024;
    const double dv = (twin["center"][1].get<double>() - right["center"][1].get<double>()) * 1024;
    EXPECT_LE(std::hypot(du, dv), 2.0) << twin;
    // Mirroring again stacks no second twin: 409 naming the one there (and the twin's own twin
    // is the source).
    Reply again = h.call("POST", s + "/placements/elbow_l/mirror", "", "", {});
    expectError(again, 409, "placement");
    EXPECT_NE(again.js()["error"]["message"].get<std::string>().find("\"elbow_r\""), std::string::npos) << again;
    Reply back = h.call("POST", s + "/placements/elbow_r/mirror", "", "", {});
    expectError(back, 409, "placement");
    EXPECT_NE(back.js()["error"]["message"].get<std::string>().find("\"elbow_l\""), std::string::npos) << back;
    EXPECT_EQ(h.get(s).header("ETag"), "\"r4\"");
    EXPECT_EQ(h.get(s + "/revisions?limit=1").js()["revisions"][0]["op"], "mirror placement elbow_l");
    // Moved away from where the twin would be, the old one is no twin: a new one, its id unique.
    ASSERT_EQ(h.patch(s + "/placements/elbow_r", {{"center", {0.9, 0.9}}}).status, 200);
    Reply third = h.call("POST", s + "/placements/elbow_l/mirror", "", "", {});
    ASSERT_EQ(third.status, 201) << third;
    EXPECT_EQ(third.js()["scene"]["placements"].back()["id"], "elbow_r_2");

    // A footprint centre on no UV chart cannot be mirrored; an unknown placement is 404.
    ASSERT_EQ(h.patch(s + "/placements/stomach", {{"center", {0.995, 0.995}}, {"scale", {0.005, 0.005}}}).status, 200);
    int stomachAt = -1; // the field names the placement's member in the document
    const json ps = h.get(s).js()["scene"]["placements"];
    for (std::size_t k = 0; k < ps.size(); ++k)
        if (ps[k]["id"] == "stomach") stomachAt = static_cast<int>(k);
    ASSERT_GE(stomachAt, 0);
    expectError(h.call("POST", s + "/placements/stomach/mirror", "", "", {}), 422,
                "/placements/" + std::to_string(stomachAt) + "/center");
    expectError(h.call("POST", s + "/placements/nope/mirror", "", "", {}), 404, "pid");
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(InspectHttpTest, CompareFramesAndDiffs) {
    Http h = http();
    Reply created = h.post("/scenes", {{"default_patterns", true}});
    ASSERT_EQ(created.status, 201) << created;
    const std::string s = "/scenes/" + created.js()["id"].get<std::string>();
    const std::string size = "width=128&height=128&msaa=1";
    Reply normal = h.get(s + "/frame?" + size);
    Reply off = h.get(s + "/frame?patterns=off&" + size);
    Reply solo = h.get(s + "/frame?only=elbow_l,knee_l&" + size);
    ASSERT_EQ(normal.status, 200) << normal;
    ASSERT_EQ(off.status, 200) << off;
    ASSERT_EQ(solo.status, 200) << solo;
    EXPECT_NE(normal.body, off.body) << "the default patterns change the frame";

    // patterns=off equals the document with every placement disabled; only= with the others
    // disabled; revision=1 the frame as it was (renders are deterministic).
    json disabled = created.js()["scene"];
    for (json& p : disabled["placements"]) p["enabled"] = false;
    ASSERT_EQ(h.put(s, disabled).status, 200);
    EXPECT_EQ(h.get(s + "/frame?" + size).body, off.body);
    json soloDoc = created.js()["scene"];
    for (json& p : soloDoc["placements"]) p["enabled"] = p["id"] == "elbow_l" || p["id"] == "knee_l";
    ASSERT_EQ(h.put(s, soloDoc).status, 200);
    EXPECT_EQ(h.get(s + "/frame?" + size).body, solo.body);
    Reply atOne = h.get(s + "/frame?revision=1&" + size);
    ASSERT_EQ(atOne.status, 200) << atOne;
    EXPECT_EQ(atOne.body, normal.body);

    // Diffs: against the patterns off and against a revision; none against itself.
    Reply diff = h.get(s + "/frame-diff?against=off&revision=1&" + size);
    ASSERT_EQ(diff.status, 200) << diff;
    EXPECT_TRUE(isPng(diff.body));
    const long changed = std::stol(diff.header("X-Dermis-Changed-Pixels"));
    EXPECT_GT(changed, 20);
    EXPECT_LT(changed, 128 * 128);
    auto heat = decodeFrame(diff.bytes());
    ASSERT_TRUE(heat);
    std::size_t lit = 0;
    for (std::size_t k = 0; k < heat->rgba.size(); k += 4) lit += heat->rgba[k] > 0;
    EXPECT_EQ(static_cast<long>(lit), changed);
    Reply same = h.get(s + "/frame-diff?against=1&revision=1&" + size);
    ASSERT_EQ(same.status, 200) << same;
    EXPECT_EQ(same.header("X-Dermis-Changed-Pixels"), "0");
    Reply vsOne = h.get(s + "/frame-diff?against=1&" + size);
    ASSERT_EQ(vsOne.status, 200);
    EXPECT_GT(std::stol(vsOne.header("X-Dermis-Changed-Pixels")), 0);

    expectError(h.get(s + "/frame?patterns=maybe"), 422, "patterns");
    expectError(h.get(s + "/frame?only=nope"), 422, "only");
    expectError(h.get(s + "/frame?only=,"), 422, "only");
    expectError(h.get(s + "/frame?revision=99"), 404, "revision");
    expectError(h.get(s + "/frame?revision=0"), 422, "revision");
    expectError(h.get(s + "/frame-diff?" + size), 422, "against");
    expectError(h.get(s + "/frame-diff?against=abc"), 422, "against");
    expectError(h.get(s + "/frame-diff?against=77"), 404, "against"); // the revision compared against
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(InspectHttpTest, FrameViews) {
    Http h = http();
    Reply created = h.post("/scenes", {{"default_patterns", true}});
    ASSERT_EQ(created.status, 201) << created;
    const std::string s = "/scenes/" + created.js()["id"].get<std::string>();
    const std::string size = "width=96&height=96&msaa=1";
    Reply shaded = h.get(s + "/frame?" + size);
    ASSERT_EQ(shaded.status, 200) << shaded;
    EXPECT_EQ(h.get(s + "/frame?view=shaded&" + size).body, shaded.body) << "shaded is the default";
    std::set<std::string> bodies = {shaded.body};
    for (const char* view : {"bump", "displacement", "normal"}) {
        Reply r = h.get(s + "/frame?view=" + view + "&" + size);
        ASSERT_EQ(r.status, 200) << view << ": " << r;
        EXPECT_EQ(r.header("Content-Type"), "image/png");
        auto img = decodeFrame(r.bytes());
        ASSERT_TRUE(img) << view;
        EXPECT_EQ(img->width, 96);
        bodies.insert(r.body);
    }
    EXPECT_EQ(bodies.size(), 4u) << "four different pictures";
    // frame-diff takes the view for both frames: the bump view against no patterns lights the
    // pixels where the patterns are.
    Reply diff = h.get(s + "/frame-diff?against=off&view=bump&" + size);
    ASSERT_EQ(diff.status, 200) << diff;
    EXPECT_GT(std::stol(diff.header("X-Dermis-Changed-Pixels")), 0);
    expectError(h.get(s + "/frame?view=nope"), 422, "view");
    expectError(h.get(s + "/frame?view=Bump"), 422, "view");
    expectError(h.get(s + "/frame-diff?against=off&view="), 422, "view");
    ASSERT_EQ(h.del(s).status, 204);
}

} // namespace

TEST_F(InspectHttpTest, PreviewRendersAnEditWithoutStoringIt) {
    Http h = http();
    Reply created = h.post("/scenes", {{"default_patterns", true}});
    ASSERT_EQ(created.status, 201) << created;
    const std::string s = "/scenes/" + created.js()["id"].get<std::string>();
    const std::string size = "width=128&height=128&msaa=1";
    // {"elbow_l":{"center":[0.3,0.5],"h":2}}, percent-encoded.
    const std::string moveElbow = "%7B%22elbow_l%22%3A%7B%22center%22%3A%5B0.3%2C0.5%5D%2C%22h%22%3A2%7D%7D";
    Reply before = h.get(s + "/frame?" + size);
    Reply preview = h.get(s + "/frame?preview=" + moveElbow + "&" + size);
    ASSERT_EQ(preview.status, 200) << preview;
    EXPECT_TRUE(preview.body != before.body) << "the previewed elbow changes the frame";
    // Nothing was stored: same revision, same document.
    Reply doc = h.get(s);
    EXPECT_EQ(doc.js()["revision"], 1);
    EXPECT_EQ(doc.js()["scene"], created.js()["scene"]);
    // The preview equals the frame of the edited document, byte for byte; with revision= too.
    Reply atOne = h.get(s + "/frame?revision=1&preview=" + moveElbow + "&" + size);
    ASSERT_EQ(atOne.status, 200) << atOne;
    EXPECT_TRUE(atOne.body == preview.body);
    ASSERT_EQ(h.patch(s + "/placements/elbow_l", {{"center", {0.3, 0.5}}, {"h", 2}}).status, 200);
    EXPECT_TRUE(h.get(s + "/frame?" + size).body == preview.body) << "the preview equals the edit's frame";
    // A preview of the old revision still applies to that revision's document.
    Reply oldPreview = h.get(s + "/frame?revision=1&preview=%7B%22elbow_l%22%3A%7B%22h%22%3A2%7D%7D&" + size);
    ASSERT_EQ(oldPreview.status, 200) << oldPreview;
    EXPECT_TRUE(oldPreview.body != before.body) << "h = 2 on revision 1's elbow";
    EXPECT_TRUE(oldPreview.body != preview.body) << "revision 1's elbow is where it was";

    expectError(h.get(s + "/frame?preview=%7B%22nope%22%3A%7B%7D%7D"), 422, "preview");   // unknown id
    expectError(h.get(s + "/frame?preview=%5B%5D"), 422, "preview");                       // not an object
    expectError(h.get(s + "/frame?preview=%7B"), 422, "preview");                           // not JSON
    expectError(h.get(s + "/frame?preview=%7B%22elbow_l%22%3A3%7D"), 422, "preview");       // patch not an object
    expectError(h.get(s + "/frame?preview=%7B%22elbow_l%22%3A%7B%22h%22%3A-1%7D%7D"), 422, "preview"); // invalid
    expectError(h.get(s + "/frame?preview=%7B%22elbow_l%22%3A%7B%22id%22%3A%22x%22%7D%7D"), 422, "preview");
    EXPECT_EQ(h.get(s).js()["revision"], 2);
    ASSERT_EQ(h.del(s).status, 204);
}
