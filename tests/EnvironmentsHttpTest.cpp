// EnvironmentsHttpTest — the /api/v1/environments routes and `render.environment` end to end on
// one server (HttpTestFixture.hpp: a real dermis::Service + dermis::Api on 127.0.0.1, a GL
// context on $DERMIS_TEST_GL). It checks:
//   * the list starts with the built-in studio;
//   * a Radiance .hdr upload (content-addressed: 201, then 200 with the same id) lights a pbr
//     frame of a scene that names it (a red sky turns the character red), 409 while a scene
//     names it, 204 once none does; a scene naming an unknown one is refused naming the field;
//   * uploads that are no environment: 415 (not .hdr/.exr, a broken .hdr, a wrong Content-Type),
//     413 (a side over the image limit), nothing left in the store;
//   * uploads survive a restart of the service;
//   * a scene's `render.key_light` lights its frames, a frame's `key_light=on|off` overrides it,
//     and a PUT with it null removes it.
#include "BuildPaths.hpp"
#include "HttpTestFixture.hpp"

#include <filesystem>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

class EnvironmentsHttpTest : public SharedServerTest {};

std::vector<std::uint8_t> bytesOfText(const std::string& s) { return {s.begin(), s.end()}; }

/// A sky of one radiance everywhere.
std::vector<std::uint8_t> uniformSky(float r, float g, float b) {
    const float c[3] = {r, g, b};
    return bytesOfText(radianceHdr(64, 32, c, c));
}

/// Σ channel `a` / Σ channel `b` over the frame's pixels that are not the background (its
/// top-left pixel).
double channelRatio(const Image8& img, int a, int b) {
    double sa = 0.0, sb = 0.0;
    for (std::size_t p = 0; p + 3 < img.rgba.size(); p += 4) {
        if (img.rgba[p] == img.rgba[0] && img.rgba[p + 1] == img.rgba[1] && img.rgba[p + 2] == img.rgba[2]) continue;
        sa += img.rgba[p + a];
        sb += img.rgba[p + b];
    }
    return sa / std::max(sb, 1.0);
}

/// The frame of scene `sid` with `query`, decoded (empty when the answer is not 200 or no image).
Image8 frameOf(const Http& h, const std::string& sid, const std::string& query = "") {
    Reply r = h.get("/scenes/" + sid + "/frame" + query);
    EXPECT_EQ(r.status, 200) << r;
    auto img = decodeFrame(r.bytes());
    return img ? *img : Image8{};
}

/// Σ red / Σ green over the character.
double redness(const Image8& img) { return channelRatio(img, 0, 1); }

std::size_t filesIn(const std::string& folder) {
    std::error_code ec;
    std::size_t n = 0;
    for (const auto& e : std::filesystem::directory_iterator(folder, ec)) {
        (void)e;
        ++n;
    }
    return n;
}

} // namespace

TEST_F(EnvironmentsHttpTest, TheListStartsWithTheStudio) {
    Reply list = http().get("/environments");
    ASSERT_EQ(list.status, 200) << list;
    const json all = list.js();
    ASSERT_FALSE(all["environments"].empty());
    EXPECT_EQ(all["environments"][0]["id"], "builtin:studio");
    EXPECT_EQ(all["environments"][0]["builtin"], true);
    expectError(http().del("/environments/builtin:studio"), 409, "id");
    expectError(http().del("/environments/e_0000000000000000"), 404, "id");
}

TEST_F(EnvironmentsHttpTest, AnUploadedSkyLightsTheScenesThatNameIt) {
    Http h = http();
    const std::vector<std::uint8_t> red = uniformSky(1.5f, 0.0f, 0.0f);
    Reply up = h.upload("/environments?name=red%20sky", red, "image/vnd.radiance");
    ASSERT_EQ(up.status, 201) << up;
    const std::string eid = up.js()["id"];
    EXPECT_EQ(eid.rfind("e_", 0), 0u) << eid;
    EXPECT_EQ(up.js()["name"], "red sky");
    EXPECT_EQ(up.js()["width"], 64);
    EXPECT_EQ(up.js()["height"], 32);
    Reply again = h.upload("/environments", red, "application/octet-stream");
    EXPECT_EQ(again.status, 200) << again;
    EXPECT_EQ(again.js()["id"], eid);
    bool listed = false;
    for (const json all = h.get("/environments").js(); const json& e : all["environments"])
        listed = listed || e["id"] == eid;
    EXPECT_TRUE(listed);

    // The same pbr scene under the studio and under the red sky.
    json doc = smallScene();
    doc["render"]["shading"] = "pbr";
    const std::string studio = createScene(doc);
    doc["render"]["environment"] = eid;
    const std::string lit = createScene(doc);
    ASSERT_FALSE(studio.empty() || lit.empty());
    EXPECT_EQ(h.get("/scenes/" + lit).js()["scene"]["render"]["environment"], eid);
    auto frame = [&](const std::string& sid, const std::string& query = "") { return frameOf(h, sid, query); };
    const Image8 studioFrame = frame(studio), redFrame = frame(lit);
    EXPECT_GT(redness(redFrame), 1.5 * redness(studioFrame))
        << "red sky " << redness(redFrame) << ", studio " << redness(studioFrame);
    // Legacy frames of that scene do not use it (one key light): the studio scene's legacy frame.
    EXPECT_EQ(frame(lit, "?shading=legacy").rgba, frame(studio, "?shading=legacy").rgba);

    // In use: 409 naming the id; once no scene names it, gone.
    expectError(h.del("/environments/" + eid), 409, "id");
    ASSERT_EQ(h.del("/scenes/" + lit).status, 204);
    EXPECT_EQ(h.del("/environments/" + eid).status, 204);
    for (const json all = h.get("/environments").js(); const json& e : all["environments"])
        EXPECT_NE(e["id"], eid);
    expectError(h.post("/scenes", doc), 404, "/render/environment");
}

TEST_F(EnvironmentsHttpTest, ASceneKeyLightLightsItsFramesAndAPutRemovesIt) {
    // render.key_light over HTTP: a blue key light from the right turns a pbr frame of the
    // scene's character blue against the same scene without it, a bad light is refused naming its
    // field, and a PUT with `"key_light": null` gives back the plain frame.
    Http h = http();
    json doc = smallScene();
    doc["render"]["shading"] = "pbr";
    const std::string plain = createScene(doc);
    doc["render"]["key_light"] = {{"direction", {1, 0.5, 0.5}}, {"intensity", 6}, {"color", {0, 0, 1}}};
    const std::string lit = createScene(doc);
    ASSERT_FALSE(plain.empty() || lit.empty());
    EXPECT_EQ(h.get("/scenes/" + lit).js()["scene"]["render"]["key_light"]["shadow"], true);
    auto frame = [&](const std::string& sid, const std::string& query = "") { return frameOf(h, sid, query); };
    const Image8 plainFrame = frame(plain), litFrame = frame(lit);
    // Σ blue / Σ red over the character (skin is red-heavy; tone mapping's desaturation of what
    // the light brightens raises blue too).
    auto blueness = [](const Image8& img) { return channelRatio(img, 2, 0); };
    EXPECT_GT(blueness(litFrame), 1.2 * blueness(plainFrame))
        << "key light " << blueness(litFrame) << ", none " << blueness(plainFrame);
    // The frame's key_light: off takes the scene's light away, on keeps it or adds the default.
    EXPECT_EQ(frame(lit, "?key_light=off").rgba, plainFrame.rgba);
    EXPECT_EQ(frame(lit, "?key_light=on").rgba, litFrame.rgba);
    const Image8 defaultLight = frame(plain, "?key_light=on");
    EXPECT_NE(defaultLight.rgba, plainFrame.rgba) << "the default key light on a scene without one";
    EXPECT_NE(defaultLight.rgba, litFrame.rgba);
    expectError(h.get("/scenes/" + plain + "/frame?key_light=maybe"), 422, "key_light");
    json bad = doc;
    bad["render"]["key_light"]["intensity"] = -1;
    expectError(h.post("/scenes", bad), 422, "/render/key_light/intensity");
    json off = h.get("/scenes/" + lit).js()["scene"];
    off["render"]["key_light"] = nullptr;
    Reply put = h.put("/scenes/" + lit, off);
    ASSERT_EQ(put.status, 200) << put;
    EXPECT_FALSE(h.get("/scenes/" + lit).js()["scene"]["render"].contains("key_light"));
    EXPECT_EQ(frame(lit).rgba, plainFrame.rgba);
}

TEST_F(EnvironmentsHttpTest, ScenesNameOnlyEnvironmentsThatExist) {
    Http h = http();
    json doc = smallScene();
    doc["render"]["environment"] = "e_0123456789abcdef";
    expectError(h.post("/scenes", doc), 404, "/render/environment");
    doc["render"]["environment"] = "builtin:sunset";
    expectError(h.post("/scenes", doc), 422, "/render/environment");
    doc["render"]["environment"] = "builtin:studio";
    EXPECT_FALSE(createScene(doc).empty());
}

TEST_F(EnvironmentsHttpTest, UploadsThatAreNoEnvironmentAreRefused) {
    Http h = http();
    const std::string folder = server_->dataDir() + "/environments";
    const std::size_t before = filesIn(folder);
    expectError(h.upload("/environments", bytesOfText("hello"), "image/vnd.radiance"), 415, "body");
    expectError(h.upload("/environments", domePng(), "image/png"), 415, "body"); // a PNG is no radiance
    expectError(h.upload("/environments", uniformSky(1, 1, 1), "text/plain"), 415, "body");
    // A Radiance header over truncated data.
    expectError(h.upload("/environments", bytesOfText("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 32 +X 64\n\x01\x02"),
                         "image/vnd.radiance"),
                415, "body");
    // A side over the server's image limit (4096).
    const float c[3] = {1, 1, 1};
    Reply wide = h.upload("/environments", bytesOfText(radianceHdr(5000, 2, c, c)), "image/vnd.radiance");
    EXPECT_EQ(wide.status, 413) << wide;
    EXPECT_EQ(filesIn(folder), before) << "nothing of a refused upload stays in the store";
}

TEST(EnvironmentsServiceTest, UploadsSurviveARestart) {
    TempDir dir;
    std::string id;
    {
        auto svc = Service::open(dir.str(), testBackend(), mainLimits());
        ASSERT_TRUE(svc) << svc.error().message;
        auto up = (*svc)->addEnvironment(uniformSky(0.5f, 0.6f, 0.7f), "dusk");
        ASSERT_TRUE(up) << up.error().message;
        id = (*up)["id"];
    }
    auto svc = Service::open(dir.str(), testBackend(), mainLimits());
    ASSERT_TRUE(svc) << svc.error().message;
    const json list = (*svc)->listEnvironments();
    ASSERT_EQ(list["environments"].size(), 2u) << list.dump();
    EXPECT_EQ(list["environments"][1]["id"], id);
    EXPECT_EQ(list["environments"][1]["name"], "dusk");
    EXPECT_EQ(list["environments"][1]["width"], 64);
    // And a scene may name it.
    json doc = smallScene();
    doc["render"]["environment"] = id;
    EXPECT_TRUE((*svc)->createScene(doc, {})) << "a scene names the restored environment";
}

TEST(EnvironmentsUploadLimitHttpTest, AnEnvironmentUploadHasTheUploadLimitNotTheJsonOne) {
    // JSON bodies capped at 1 MiB, uploads at kMaxUpload (8 MiB): an environment is an upload.
    ApiOptions opt;
    opt.maxJsonBytes = 1u << 20;
    std::string error;
    auto server = LiveServer::start(mainLimits(), "", error, opt);
    ASSERT_TRUE(server && error.empty()) << error;
    Http h(server->port());
    std::vector<std::uint8_t> bytes(2u << 20, 0x7f); // 2 MiB: over the JSON limit, under the upload limit; no image
    expectError(h.upload("/environments", bytes, "image/vnd.radiance"), 415, "body"); // read whole, then refused as no environment
    bytes.resize(kMaxUpload + 1024, 0x7f);
    EXPECT_EQ(h.upload("/environments", bytes, "image/vnd.radiance").status, 413);
    // Scene documents keep the JSON limit.
    EXPECT_EQ(h.post("/scenes", json{{"model", "builtin:default"}, {"pad", std::string(2u << 20, 'x')}}).status, 413);
}
