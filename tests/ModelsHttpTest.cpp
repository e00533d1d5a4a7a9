// ModelsHttpTest — the /api/v1/models routes end to end on one server (HttpTestFixture.hpp: a real
// dermis::Service + dermis::Api on 127.0.0.1, a GL context on $DERMIS_TEST_GL, cpp-httplib clients
// over loopback). It checks:
//   * models: built-in details, .glb uploads of the shared models (CesiumMan, KayKit Barbarian,
//     RiggedFigure without UVs), UV layouts as JSON and PNG, deletion (409 while a scene uses it);
//   * morph targets listed by name in a model's details and posed through the scene's
//     pose.morphs (merged like the joints; an unknown name 404 naming it);
//   * parts counted by where their tangents come from (the file, generated on load, none);
//   * the UV diagnosis in a model's details (`uv`, SPEC §8): the default character and CesiumMan
//     usable without overlap, the Barbarian's palette atlas overlapping with its regions named
//     (the hat shares texels with the body; left and right forearm mirrored), RiggedFigure
//     without UVs (every triangle missing);
//   * base-colour textures as PNG (CesiumMan's at its size and downsized; none on the default
//     character or RiggedFigure: 404 no_texture);
//   * a multipart .gltf with its external buffer, and multipart uploads that are refused (missing
//     buffer, a URI outside the folder, a folder in a part name, no .gltf part, not JSON); no
//     answer to a bad upload contains a path of the server (the data folder, /tmp);
//   * tiny files that declare huge models (issue #12: a zero-filled accessor instanced by 16
//     nodes, three 16384² textures): 413 too_large naming the field, the server healthy after.
#include "GltfTestBuilder.hpp"
#include "HttpTestFixture.hpp"
#include "io/gltf_loader.hpp"
#include "common/sha256.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// One server (no token).
class ModelsHttpTest : public SharedServerTest {};

// ================================================================================================
// Models
// ================================================================================================

TEST_F(ModelsHttpTest, MorphTargetsAreListedAndPosedByName) {
    Http h = http();
    gltf::MorphedTriangle t;
    Reply up = h.upload("/models", t.b.glb(), "model/gltf-binary");
    ASSERT_EQ(up.status, 201) << up;
    const std::string model = up.js()["id"];
    const json details = h.get("/models/" + model).js();
    ASSERT_EQ(details["morphs"].size(), 2u) << details.dump();
    EXPECT_EQ(details["morphs"][0], json({{"name", "smile"}, {"rest", 0.25}}));
    EXPECT_EQ(details["morphs"][1], json({{"name", "blink"}, {"rest", 0.0}}));
    EXPECT_EQ(h.get("/models/builtin:default").js()["morphs"], json::array());

    Reply created = h.post("/scenes", {{"format", "dermis.scene/1"}, {"model", model},
                                       {"pose", {{"animation", "bend"}, {"time", 0}}}});
    ASSERT_EQ(created.status, 201) << created;
    const std::string scene = "/scenes/" + created.js()["id"].get<std::string>();
    const std::string frame = scene + "/frame?width=96&height=96&aa=none";
    const auto rest = decodeFrame(h.get(frame).bytes());
    ASSERT_TRUE(rest);
    // Merged member by member like the joints; null removes one.
    ASSERT_EQ(h.patch(scene + "/pose", {{"morphs", {{"smile", 1.0}, {"blink", 1.0}}}}).status, 200);
    ASSERT_EQ(h.patch(scene + "/pose", {{"morphs", {{"blink", nullptr}}}}).status, 200);
    const json pose = h.get(scene).js()["scene"]["pose"];
    EXPECT_EQ(pose["morphs"], json({{"smile", 1.0}})) << pose.dump();
    const auto smiling = decodeFrame(h.get(frame).bytes());
    ASSERT_TRUE(smiling);
    EXPECT_NE(smiling->rgba, rest->rgba) << "the weight moved a vertex";
    // Back to the rest weight: the first frame again.
    ASSERT_EQ(h.patch(scene + "/pose", {{"morphs", {{"smile", 0.25}}}}).status, 200);
    const auto again = decodeFrame(h.get(frame).bytes());
    ASSERT_TRUE(again);
    EXPECT_EQ(again->rgba, rest->rgba);
    expectError(h.patch(scene + "/pose", {{"morphs", {{"frown", 1.0}}}}), 404, "/pose/morphs/frown");
    EXPECT_EQ(h.del(scene).status, 204);
    EXPECT_EQ(h.del("/models/" + model).status, 204);
}

TEST_F(ModelsHttpTest, PartsAreCountedByWhereTheirTangentsComeFrom) {
    Http h = http();
    const std::string fidelity = kTestModels + "/fidelity/";
    const std::pair<std::string, json> cases[] = {
        // A normal map and no TANGENT: generated on load (core/tangents.hpp).
        {"DamagedHelmet/DamagedHelmet.glb", {{"file", 0}, {"generated", 1}, {"none", 0}}},
        {"NormalTangentMirrorTest/NormalTangentMirrorTest.glb", {{"file", 1}, {"generated", 0}, {"none", 0}}},
    };
    for (const auto& [file, tangents] : cases) {
        Reply up = h.upload("/models", readBytes(fidelity + file), "model/gltf-binary");
        ASSERT_TRUE(up.status == 201 || up.status == 200) << file << ": " << up;
        const json details = h.get("/models/" + up.js()["id"].get<std::string>()).js();
        EXPECT_EQ(details["tangents"], tangents) << file;
    }
    // No normal map: no tangents (CesiumMan's and the others' uploads are other tests').
    const json builtin = h.get("/models/builtin:default").js()["tangents"];
    EXPECT_EQ(builtin["file"], 0);
    EXPECT_EQ(builtin["generated"], 0);
    EXPECT_GE(builtin["none"], 1);
}

TEST_F(ModelsHttpTest, BuiltinModelIsListedWithItsDetails) {
    Http h = http();
    Reply list = h.get("/models");
    ASSERT_EQ(list.status, 200) << list;
    bool found = false;
    for (const json all = list.js(); const json& m : all["models"])
        if (m["id"] == "builtin:default") {
            found = true;
            EXPECT_EQ(m["joint_count"], 51) << m;
            EXPECT_EQ(m["has_texture"], false) << m; // GET …/texture answers 404 no_texture
        }
    EXPECT_TRUE(found) << list;

    Reply r = h.get("/models/builtin:default");
    ASSERT_EQ(r.status, 200) << r;
    const json m = r.js();
    EXPECT_EQ(m["id"], "builtin:default");
    EXPECT_TRUE(m["has_uvs"].get<bool>());
    EXPECT_NEAR(m["triangles"].get<double>(), 4300, 100);
    ASSERT_TRUE(m["joints"].is_array());
    EXPECT_EQ(m["joints"].size(), 51u);
    std::set<std::string> names;
    int roots = 0;
    for (const json& j : m["joints"]) {
        ASSERT_TRUE(j["name"].is_string()) << j;
        names.insert(j["name"].get<std::string>());
        ASSERT_TRUE(j["rest_rotation"].is_array() && j["rest_rotation"].size() == 4) << j;
        double n2 = 0;
        for (const json& c : j["rest_rotation"])
            n2 += c.get<double>() * c.get<double>();
        EXPECT_NEAR(n2, 1.0, 1e-3) << j;
        if (j["parent"].is_null())
            ++roots;
        else
            EXPECT_TRUE(j["parent"].is_string()) << j;
    }
    EXPECT_EQ(roots, 1);
    for (const json& j : m["joints"])
        if (j["parent"].is_string()) EXPECT_TRUE(names.count(j["parent"].get<std::string>())) << j;
    EXPECT_TRUE(names.count("forearm.l") && names.count("spine_02") && names.count("root"));
    ASSERT_TRUE(m["clips"].is_array());
    EXPECT_EQ(m["clips"].size(), 7u);
    // Its UV diagnosis: unique UVs, usable for the height maps.
    const json& uv = m["uv"];
    ASSERT_TRUE(uv.is_object()) << m;
    EXPECT_EQ(uv["has_uvs"], true);
    EXPECT_EQ(uv["usable"], true);
    EXPECT_EQ(uv["overlap_fraction"], 0.0);
    EXPECT_NEAR(uv["used_fraction"].get<double>(), 0.47, 0.02);
    EXPECT_EQ(uv["resolution"], 1024);
    EXPECT_TRUE(uv["sharing"].empty());
    EXPECT_EQ(uv["summary"], "");
    EXPECT_EQ(uv["missing"]["triangles"], 0);
    EXPECT_EQ(uv["density"].size(), 49u); // the joints that drive triangles (not root, not index_03.l)
    for (const json& c : m["clips"]) {
        EXPECT_TRUE(c["name"].is_string());
        EXPECT_GT(c["duration"].get<double>(), 0.0) << c;
    }
}

TEST_F(ModelsHttpTest, CesiumManUploadsInspectsAndDeletes) {
    Http h = http();
    // A name with path tricks is only a label.
    Reply up =
        h.upload("/models?name=..%2F..%2Fetc%2Fpasswd", readBytes(kCesiumMan), "model/gltf-binary");
    ASSERT_EQ(up.status, 201) << up;
    const json created = up.js();
    const std::string id = created["id"];
    EXPECT_EQ(id.rfind("m_", 0), 0u) << id;
    EXPECT_EQ(created["joints"], 19);
    // The upload answer carries what the editor needs without a second request.
    EXPECT_EQ(created["joint_count"], 19) << created;
    EXPECT_EQ(created["has_texture"], true) << created;
    EXPECT_EQ(created["name"].get<std::string>().find('/'), std::string::npos) << created;

    Reply got = h.get("/models/" + id);
    ASSERT_EQ(got.status, 200) << got;
    const json m = got.js();
    EXPECT_EQ(m["joints"].size(), 19u);
    EXPECT_EQ(m["joint_count"], 19);
    EXPECT_EQ(m["has_texture"], true);
    EXPECT_TRUE(m["has_uvs"].get<bool>());
    EXPECT_EQ(m["triangles"], 4672);
    EXPECT_GE(m["clips"].size(), 1u);
    EXPECT_EQ(m["uv"]["usable"], true) << m["uv"];
    EXPECT_LT(m["uv"]["overlap_fraction"].get<double>(), 0.005);
    EXPECT_TRUE(m["uv"]["mirrored_pairs"].empty());

    bool listed = false;
    for (const json all = h.get("/models").js(); const json& e : all["models"])
        listed = listed || e["id"] == id;
    EXPECT_TRUE(listed);

    Reply uv = h.get("/models/" + id + "/uv-layout");
    ASSERT_EQ(uv.status, 200) << uv;
    const json layout = uv.js();
    EXPECT_EQ(layout["layout"], "model"); // CesiumMan: its own UVs are usable
    ASSERT_TRUE(layout["edges"].is_array());
    EXPECT_GT(layout["edge_count"].get<std::size_t>(), 1000u);
    EXPECT_EQ(layout["edges"].size(), 4 * layout["edge_count"].get<std::size_t>());
    for (const json& v : layout["edges"])
        ASSERT_TRUE(v.is_number() && std::isfinite(v.get<double>()));

    Reply png = h.get("/models/" + id + "/uv-layout?format=png&size=256");
    ASSERT_EQ(png.status, 200) << png;
    EXPECT_EQ(png.header("Content-Type"), "image/png");
    auto img = decodeFrame(png.bytes());
    ASSERT_TRUE(img) << img.error().message;
    EXPECT_EQ(img->width, 256);
    EXPECT_EQ(img->height, 256);
    std::size_t lit = 0;
    for (std::size_t i = 0; i < img->rgba.size(); i += 4)
        lit += img->rgba[i] == 255;
    EXPECT_GT(lit, 1000u);

    EXPECT_EQ(h.del("/models/" + id).status, 204);
    expectError(h.get("/models/" + id), 404, "id");
    expectError(h.del("/models/" + id), 404, "id");
}

TEST_F(ModelsHttpTest, BaseColourTextureAsPng) {
    Http h = http();
    // The texture as the loader decodes it: what the route must answer.
    auto cesium = loadGltfFile(kCesiumMan);
    ASSERT_TRUE(cesium) << cesium.error().message;
    const int image = cesium->dominantBaseColorImage();
    ASSERT_GE(image, 0);
    const Image8& tex = cesium->images[static_cast<std::size_t>(image)];
    ASSERT_GT(tex.width, 256);

    Reply up = h.upload("/models", readBytes(kCesiumMan), "model/gltf-binary");
    ASSERT_EQ(up.status, 201) << up;
    const std::string id = up.js()["id"];
    Reply full = h.get("/models/" + id + "/texture");
    ASSERT_EQ(full.status, 200) << full;
    EXPECT_EQ(full.header("Content-Type"), "image/png");
    auto img = decodeFrame(full.bytes());
    ASSERT_TRUE(img) << img.error().message;
    EXPECT_EQ(img->width, tex.width);
    EXPECT_EQ(img->height, tex.height);
    EXPECT_EQ(img->rgba, tex.rgba) << "the decoded texture, byte for byte";

    // ?size= fits the longer side into N, keeping the aspect; never enlarges.
    Reply small = h.get("/models/" + id + "/texture?size=64");
    ASSERT_EQ(small.status, 200) << small;
    auto s = decodeFrame(small.bytes());
    ASSERT_TRUE(s);
    EXPECT_EQ(std::max(s->width, s->height), 64);
    EXPECT_EQ(s->width, static_cast<int>(std::lround(64.0 * tex.width / std::max(tex.width, tex.height))));
    auto big = decodeFrame(h.get("/models/" + id + "/texture?size=4096").bytes());
    ASSERT_TRUE(big);
    EXPECT_EQ(big->width, tex.width);

    for (const char* bad : {"size=8", "size=5000", "size=abc", "size=-1"})
        expectError(h.get("/models/" + id + "/texture?" + bad), 422, "size");
    EXPECT_EQ(h.del("/models/" + id).status, 204);
    expectError(h.get("/models/" + id + "/texture"), 404, "id");

    // No base-colour texture: the default character (a base colour factor only), RiggedFigure.
    Reply none = h.get("/models/builtin:default/texture");
    expectError(none, 404, "texture");
    EXPECT_EQ(none.js()["error"]["code"], "no_texture") << none;
    Reply fig = h.upload("/models", readBytes(kRiggedFigure), "model/gltf-binary");
    ASSERT_EQ(fig.status, 201) << fig;
    const std::string figId = fig.js()["id"];
    Reply figTex = h.get("/models/" + figId + "/texture");
    expectError(figTex, 404, "texture");
    EXPECT_EQ(figTex.js()["error"]["code"], "no_texture") << figTex;
    EXPECT_EQ(h.del("/models/" + figId).status, 204);
    expectError(h.get("/models/m_nope/texture"), 404, "id");
}

TEST_F(ModelsHttpTest, GltfWithExternalFilesUploadsAsMultipart) {
    auto post = [&](const httplib::MultipartFormDataItems& items) {
        httplib::Client cli("127.0.0.1", server_->port());
        auto r = cli.Post((std::string(kApi) + "/models?name=tri").c_str(), items);
        Reply out;
        if (r) {
            out.status = r->status;
            out.body = r->body;
        }
        return out;
    };
    const auto [gltf, bin] = triangleGltf("tri.bin");
    Reply ok = post({{"gltf", gltf, "tri.gltf", "model/gltf+json"},
                     {"buffer", bin, "tri.bin", "application/octet-stream"}});
    ASSERT_EQ(ok.status, 201) << ok;
    const std::string id = ok.js()["id"];
    EXPECT_EQ(ok.js()["triangles"], 1);
    Reply got = http().get("/models/" + id);
    ASSERT_EQ(got.status, 200) << got;
    EXPECT_EQ(got.js()["vertices"], 3);
    // A scene on it renders.
    const std::string sid = createScene({{"format", "dermis.scene/1"}, {"model", id},
                                         {"render", {{"size", {64, 64}}}}});
    Reply frame = http().get("/scenes/" + sid + "/frame");
    EXPECT_EQ(frame.status, 200) << frame;
    EXPECT_EQ(http().del("/scenes/" + sid).status, 204);
    EXPECT_EQ(http().del("/models/" + id).status, 204);

    // The buffer is missing; the .gltf points outside its folder; a part name with a folder;
    // no .gltf part at all: 4xx JSON errors, nothing stored.
    const auto [escaping, bin2] = triangleGltf("../tri.bin");
    const std::vector<std::pair<std::string, httplib::MultipartFormDataItems>> bad = {
        {"missing buffer", {{"gltf", gltf, "tri.gltf", ""}}},
        {"escaping uri", {{"gltf", escaping, "tri.gltf", ""}, {"buffer", bin2, "tri.bin", ""}}},
        {"folder in a part name", {{"gltf", gltf, "tri.gltf", ""}, {"buffer", bin, "../tri.bin", ""}}},
        {"no gltf part", {{"buffer", bin, "tri.bin", ""}}},
        {"not json", {{"gltf", "not json", "tri.gltf", ""}, {"buffer", bin, "tri.bin", ""}}},
    };
    const std::size_t models = http().get("/models").js()["models"].size();
    for (const auto& [name, items] : bad) {
        Reply r = post(items);
        EXPECT_GE(r.status, 400) << name << ": " << r;
        EXPECT_LT(r.status, 500) << name << ": " << r;
        EXPECT_TRUE(r.js().contains("error")) << name << ": " << r;
    }
    EXPECT_EQ(http().get("/models").js()["models"].size(), models);
}

// Issue #12.9: error answers to bad uploads name ids, parts and fields, never a path of the server
// (the data folder, where uploads are stored).
TEST_F(ModelsHttpTest, BadUploadErrorsNameNoServerPath) {
    const std::string data = server_->dataDir();
    std::error_code ec;
    const std::string canonical = std::filesystem::canonical(data, ec).string();
    ASSERT_FALSE(data.empty());
    auto post = [&](const std::string& path, const httplib::MultipartFormDataItems& items) {
        httplib::Client cli("127.0.0.1", server_->port());
        auto r = cli.Post((std::string(kApi) + path).c_str(), items);
        Reply out;
        if (r) {
            out.status = r->status;
            out.body = r->body;
        }
        return out;
    };
    auto expectNoPath = [&](const std::string& name, const Reply& r) {
        EXPECT_GE(r.status, 400) << name << ": " << r;
        EXPECT_LT(r.status, 500) << name << ": " << r;
        EXPECT_EQ(r.body.find(data), std::string::npos) << name << ": " << r;
        if (!canonical.empty()) EXPECT_EQ(r.body.find(canonical), std::string::npos) << name << ": " << r;
    };
    const auto [gltf, bin] = triangleGltf("tri.bin");
    json textured = json::parse(gltf);
    textured["images"] = {{{"uri", "skin.png"}}};
    textured["textures"] = {{{"source", 0}}};
    textured["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
    textured["meshes"][0]["primitives"][0]["material"] = 0;
    const std::vector<std::pair<std::string, httplib::MultipartFormDataItems>> bad = {
        {"missing buffer", {{"gltf", gltf, "tri.gltf", ""}}},
        {"bad buffer name", {{"gltf", triangleGltf("no such.bin").first, "tri.gltf", ""}, {"buffer", bin, "tri.bin", ""}}},
        {"absolute buffer uri", {{"gltf", triangleGltf("/etc/x.bin").first, "tri.gltf", ""}}},
        {"escaping buffer uri", {{"gltf", triangleGltf("../../tri.bin").first, "tri.gltf", ""}, {"buffer", bin, "tri.bin", ""}}},
        {"file uri", {{"gltf", triangleGltf("file:///etc/x.bin").first, "tri.gltf", ""}}},
        {"short buffer", {{"gltf", gltf, "tri.gltf", ""}, {"buffer", bin.substr(0, 10), "tri.bin", ""}}},
        {"missing image", {{"gltf", textured.dump(), "tri.gltf", ""}, {"buffer", bin, "tri.bin", ""}}},
        {"corrupt image", {{"gltf", textured.dump(), "tri.gltf", ""}, {"buffer", bin, "tri.bin", ""},
                           {"image", std::string("\x89PNG\r\n\x1a\nbroken"), "skin.png", ""}}},
        {"folder in a part name", {{"gltf", gltf, "tri.gltf", ""}, {"buffer", bin, "../tri.bin", ""}}},
        {"not json", {{"gltf", "not json", "tri.gltf", ""}, {"buffer", bin, "tri.bin", ""}}},
    };
    for (const auto& [name, items] : bad) expectNoPath(name, post("/models?name=tri", items));

    Http h = http();
    const auto png = domePng();
    const std::vector<std::pair<std::string, std::vector<std::uint8_t>>> images = {
        {"truncated png", std::vector<std::uint8_t>(png.begin(), png.begin() + static_cast<long>(png.size() / 2))},
        {"png magic only", std::vector<std::uint8_t>(png.begin(), png.begin() + 8)},
        {"garbage", std::vector<std::uint8_t>(500, 0x5a)},
        {"empty", {}},
    };
    for (const auto& [name, bytes] : images) {
        expectNoPath("pattern " + name, h.upload("/patterns?name=bad", bytes, "image/png"));
        expectNoPath("glb " + name, h.upload("/models?name=bad", bytes, "model/gltf-binary"));
    }
    std::string glb = "glTF";
    glb += std::string(40, '\0');
    expectNoPath("glb header only", h.upload("/models?name=bad", std::vector<std::uint8_t>(glb.begin(), glb.end()),
                                              "model/gltf-binary"));
}

TEST_F(ModelsHttpTest, BarbarianAndRiggedFigureUpload) {
    Http h = http();
    Reply barb = h.upload("/models", readBytes(kBarbarian), "model/gltf-binary");
    ASSERT_EQ(barb.status, 201) << barb;
    const std::string barbId = barb.js()["id"];
    EXPECT_EQ(barb.js()["joint_count"], 41) << barb;
    EXPECT_EQ(barb.js()["has_texture"], true) << barb;
    Reply bm = h.get("/models/" + barbId);
    ASSERT_EQ(bm.status, 200);
    EXPECT_EQ(bm.js()["joints"].size(), 41u);
    EXPECT_GE(bm.js()["clips"].size(), 70u);
    // A palette atlas: most used texels are shared, by regions named after part and joint.
    const json uv = bm.js()["uv"];
    EXPECT_EQ(uv["has_uvs"], true);
    EXPECT_EQ(uv["usable"], false);
    EXPECT_GT(uv["overlap_fraction"].get<double>(), 0.005);
    EXPECT_NE(uv["summary"].get<std::string>().find("shares texels with"), std::string::npos) << uv["summary"];
    bool hatWithBody = false;
    for (const json& r : uv["sharing"])
        if (r["region"] == "Barbarian_Hat (head)") {
            EXPECT_EQ(r["joint"], "head");
            EXPECT_GT(r["shared_texels"].get<int>(), 0);
            for (const json& o : r["shares_with"])
                hatWithBody = hatWithBody || o["region"].get<std::string>().rfind("Barbarian_Body (", 0) == 0;
        }
    EXPECT_TRUE(hatWithBody) << uv["sharing"];
    bool forearms = false;
    for (const json& p : uv["mirrored_pairs"])
        forearms = forearms || p["regions"] == json({"Barbarian_ArmLeft (lowerarm.l)", "Barbarian_ArmRight (lowerarm.r)"});
    EXPECT_TRUE(forearms) << uv["mirrored_pairs"];
    bool density = false;
    for (const json& j : uv["density"])
        density = density || (j["joint"] == "lowerarm.l" && j["texels_per_unit"].get<double>() > 0);
    EXPECT_TRUE(density) << uv["density"];

    // Its UVs are not usable: auto lays the height maps out anew; the model's own stay asked for.
    EXPECT_EQ(h.get("/models/" + barbId + "/uv-layout").js()["layout"], "generated");
    EXPECT_EQ(h.get("/models/" + barbId + "/uv-layout?layout=model").js()["layout"], "model");

    // A scene on an uploaded model renders.
    json doc = {{"format", "dermis.scene/1"},
                {"model", barbId},
                {"heightmap", {{"size", {256, 256}}}},
                {"render", {{"size", {96, 96}}, {"msaa", 1}}}};
    const std::string sid = createScene(doc);
    Reply frame = h.get("/scenes/" + sid + "/frame");
    ASSERT_EQ(frame.status, 200) << frame;
    auto img = decodeFrame(frame.bytes());
    ASSERT_TRUE(img);
    EXPECT_EQ(img->width, 96);
    expectError(h.del("/models/" + barbId), 409, "id"); // in use
    EXPECT_EQ(h.del("/scenes/" + sid).status, 204);
    EXPECT_EQ(h.del("/models/" + barbId).status, 204);

    Reply fig = h.upload("/models", readBytes(kRiggedFigure), "model/gltf-binary");
    ASSERT_EQ(fig.status, 201) << fig;
    const std::string figId = fig.js()["id"];
    EXPECT_FALSE(fig.js()["has_uvs"].get<bool>());
    EXPECT_FALSE(fig.js()["has_texture"].get<bool>());
    EXPECT_EQ(fig.js()["joint_count"], 19);
    const json figUv = h.get("/models/" + figId).js()["uv"];
    EXPECT_EQ(figUv["has_uvs"], false);
    EXPECT_EQ(figUv["usable"], false);
    EXPECT_EQ(figUv["missing"]["triangles"], 256);
    EXPECT_EQ(figUv["missing"]["parts"], 1);
    EXPECT_EQ(figUv["used_fraction"], 0.0);
    // No UVs: the layout in use is the generated one (SPEC §8 uv_layout auto); its own is none.
    Reply gen = h.get("/models/" + figId + "/uv-layout");
    ASSERT_EQ(gen.status, 200) << gen;
    const json genLayout = gen.js(); // kept: the loop below reads into it
    EXPECT_EQ(genLayout["layout"], "generated");
    EXPECT_GT(genLayout["edge_count"].get<std::size_t>(), 256u); // every triangle laid out
    for (const json& v : genLayout["edges"]) ASSERT_TRUE(v.get<double>() >= 0.0 && v.get<double>() <= 1.0);
    Reply genPng = h.get("/models/" + figId + "/uv-layout?format=png&size=128&layout=generated");
    ASSERT_EQ(genPng.status, 200) << genPng;
    EXPECT_EQ(genPng.header("Content-Type"), "image/png");
    expectError(h.get("/models/" + figId + "/uv-layout?layout=model"), 422, "layout");
    expectError(h.get("/models/" + figId + "/uv-layout?format=png&layout=model"), 422, "layout");
    expectError(h.get("/models/" + figId + "/uv-layout?layout=unique"), 422, "layout");
    // Its height maps live in the generated layout: a UV placement there is valid (and renders);
    // the model's own layout has no texel for it.
    json inUv = placementOf("crease", "a");
    inUv["joint"] = "arm_joint_L_2";
    json withPlacement = {{"format", "dermis.scene/1"},
                          {"model", figId},
                          {"heightmap", {{"size", {256, 256}}}},
                          {"render", {{"size", {64, 64}}, {"msaa", 1}}},
                          {"placements", {inUv}}};
    const std::string genScene = createScene(withPlacement);
    EXPECT_EQ(h.get("/scenes/" + genScene + "/frame").status, 200);
    EXPECT_EQ(h.del("/scenes/" + genScene).status, 204);
    withPlacement["uv_layout"] = "model";
    expectError(h.post("/scenes", withPlacement), 422, "/uv_layout");
    // Without placements it is a valid scene.
    const std::string figScene = createScene(
        {{"format", "dermis.scene/1"}, {"model", figId}, {"heightmap", {{"size", {256, 256}}}}});
    EXPECT_EQ(h.del("/scenes/" + figScene).status, 204);
    EXPECT_EQ(h.del("/models/" + figId).status, 204);
}

TEST_F(ModelsHttpTest, TinyFilesThatDeclareHugeModelsAre413) {
    Http h = http();
    const std::size_t models = h.get("/models").js()["models"].size();
    gltf::SkinnedTriangle textured;
    const std::vector<std::uint8_t> huge = gltf::pngHeader(16384, 16384);
    gltf::withBaseColorImages(textured, {huge, huge, huge});
    const struct {
        const char* name;
        std::vector<std::uint8_t> glb;
        std::string field;
    } cases[] = {
        {"instanced zero-filled mesh", gltf::instancedZeroMesh(),
         "/meshes/0/primitives/0/attributes/POSITION"},
        {"three 16384² textures", textured.b.glb(), "/images/0"},
    };
    for (const auto& c : cases) {
        const auto t0 = std::chrono::steady_clock::now();
        Reply r = h.upload("/models?name=huge", c.glb, "model/gltf-binary");
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        expectError(r, 413, c.field);
        EXPECT_EQ(r.js()["error"]["code"], "too_large") << c.name << ": " << r;
        std::printf("%s (%zu bytes): %d in %.3f s\n", c.name, c.glb.size(), r.status, s);
        EXPECT_EQ(h.get("/health").status, 200) << c.name;
    }
    EXPECT_EQ(h.get("/models").js()["models"].size(), models); // nothing stored
}

} // namespace

// Issue #14: uploads are content-addressed. The same .glb twice answers 200 with the first id
// ("m_" + the first 16 hex digits of the bytes' SHA-256) and stores no copy; a multipart .gltf
// with its files likewise; other bytes get another id; after a delete the bytes upload anew (201).
TEST_F(ModelsHttpTest, SameBytesUploadTwiceGiveTheSameId) {
    Http h = http();
    const auto glb = readBytes(kRiggedFigure);
    const std::size_t before = h.get("/models").js()["models"].size();
    Reply first = h.upload("/models?name=fig", glb, "model/gltf-binary");
    ASSERT_EQ(first.status, 201) << first;
    const std::string id = first.js()["id"];
    EXPECT_EQ(id, "m_" + toHex(sha256(glb)).substr(0, 16));
    Reply again = h.upload("/models?name=other", glb, "model/gltf-binary");
    ASSERT_EQ(again.status, 200) << again;
    EXPECT_EQ(again.js()["id"], id);
    EXPECT_EQ(again.js()["name"], "fig") << "the stored model, unchanged";
    EXPECT_EQ(h.get("/models").js()["models"].size(), before + 1) << "no copy";
    Reply cesium = h.upload("/models", readBytes(kCesiumMan), "model/gltf-binary");
    ASSERT_EQ(cesium.status, 201) << cesium;
    EXPECT_NE(cesium.js()["id"], id);

    auto post = [&](const httplib::MultipartFormDataItems& items) {
        httplib::Client cli("127.0.0.1", server_->port());
        auto r = cli.Post((std::string(kApi) + "/models?name=tri").c_str(), items);
        return r ? std::make_pair(r->status, json::parse(r->body, nullptr, false)) : std::make_pair(0, json());
    };
    const auto [gltf, bin] = triangleGltf("tri.bin");
    auto [s1, j1] = post({{"gltf", gltf, "tri.gltf", ""}, {"buffer", bin, "tri.bin", ""}});
    auto [s2, j2] = post({{"gltf", gltf, "tri.gltf", ""}, {"buffer", bin, "tri.bin", ""}});
    EXPECT_EQ(s1, 201) << j1;
    EXPECT_EQ(s2, 200) << j2;
    EXPECT_EQ(j1["id"], j2["id"]);
    EXPECT_EQ(j1["id"].get<std::string>().size(), 18u);

    // Deleted, the same bytes are a new upload again (same id: the id is the content's).
    EXPECT_EQ(h.del("/models/" + id).status, 204);
    Reply after = h.upload("/models", glb, "model/gltf-binary");
    EXPECT_EQ(after.status, 201) << after;
    EXPECT_EQ(after.js()["id"], id);
    for (const std::string m : {id, cesium.js()["id"].get<std::string>(), j1["id"].get<std::string>()})
        EXPECT_EQ(h.del("/models/" + m).status, 204) << m;
}
