// Scene documents (`dermis.scene/1`, SPEC §2b): parsing, defaults, serialisation round trips,
// and one test per kind of bad input, each checking the exact JSON pointer that the error names.
// Pure: no files, no GL. (The pattern manifest: PatternManifestTest.)
#include "core/key_light.hpp"
#include "core/scene.hpp"
#include "BuildPaths.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

using dermis::ErrorCode;
using dermis::PatternManifest;
using dermis::Scene;
using nlohmann::json;

namespace {

/// A small hand-built library: one pattern of each kind, with suggested axis and theta range.
PatternManifest testManifest() {
    PatternManifest m;
    dermis::PatternInfo crease;
    crease.id = "crease";
    crease.file = "crease.png";
    crease.kind = dermis::PatternKind::Wrinkle;
    crease.model = dermis::DeformModel::Scale;
    crease.target = dermis::Target::Bump;
    crease.joint = "elbow";
    crease.axis = "x";
    crease.thetaMin = 0;
    crease.thetaMax = 120;
    m.patterns.push_back(crease);

    dermis::PatternInfo biceps;
    biceps.id = "biceps";
    biceps.file = "biceps.png";
    biceps.kind = dermis::PatternKind::Bulge;
    biceps.model = dermis::DeformModel::Scale;
    biceps.target = dermis::Target::Displacement;
    biceps.joint = "elbow";
    biceps.axis = "z";
    biceps.thetaMin = 10;
    biceps.thetaMax = 100;
    m.patterns.push_back(biceps);

    dermis::PatternInfo clavicle;
    clavicle.id = "clavicle";
    clavicle.file = "clavicle.png";
    clavicle.kind = dermis::PatternKind::Bone;
    clavicle.model = dermis::DeformModel::Bias;
    clavicle.target = dermis::Target::Bump;
    clavicle.joint = "shoulder";
    clavicle.axis = "y";
    clavicle.thetaMin = -30;
    clavicle.thetaMax = 60;
    m.patterns.push_back(clavicle);
    return m;
}

/// The example of SPEC §2b, verbatim.
const char* kSpecExample = R"({
  "format": "dermis.scene/1",
  "model": "builtin:default" ,
  "heightmap": { "size": [1024, 1024], "base": "optional/static_height.exr" },
  "patterns": { "my_ridge": "custom/ridge.png" },
  "placements": [
    { "id": "elbow_l", "pattern": "crease", "center": [0.31, 0.42], "scale": [0.08, 0.05],
      "rotation": 30, "joint": "forearm.l", "axis": "x", "theta_min": 0, "theta_max": 120,
      "h": 1.0, "model": "scale", "target": "bump", "response": "log2" }
  ],
  "pose": { "animation": "Walk", "time": 0.5,
            "joints": { "forearm.l": { "rotation": [0, 0, 0.383, 0.924] },
                        "spine":     { "axis_angles": { "x": 20, "y": -10 } } } },
  "render": { "size": [1024, 1024], "camera": { "yaw": 0, "pitch": 10, "distance": "auto" },
              "displacement_scale": "auto", "bump_strength": 1.0 }
})";

dermis::Result<Scene> parse(const std::string& text) {
    return dermis::parseSceneText(text, testManifest());
}

Scene parseOk(const std::string& text) {
    auto r = parse(text);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message) << "\n" << text;
    return r.ok() ? *r : Scene{};
}

/// parse → serialise → parse → serialise must be byte-identical; returns the first dump.
std::string expectStableRoundTrip(const std::string& text) {
    const PatternManifest m = testManifest();
    auto a = dermis::parseSceneText(text, m);
    EXPECT_TRUE(a.ok()) << (a.ok() ? "" : a.error().message);
    if (!a) return {};
    const std::string first = dermis::toJson(*a).dump();
    auto b = dermis::parseSceneText(first, m);
    EXPECT_TRUE(b.ok()) << (b.ok() ? "" : b.error().message) << "\n" << first;
    if (!b) return first;
    EXPECT_EQ(first, dermis::toJson(*b).dump());
    // Pretty-printed text reads back the same too.
    auto c = dermis::parseSceneText(dermis::toJson(*b).dump(2), m);
    EXPECT_TRUE(c.ok());
    if (c) EXPECT_EQ(first, dermis::toJson(*c).dump());
    return first;
}

/// `{"format":"dermis.scene/1", <body>}`.
std::string doc(const std::string& body) {
    return std::string(R"({"format":"dermis.scene/1")") + (body.empty() ? "" : ",") + body + "}";
}

/// One placement with the required fields plus `extra`.
std::string placement(const std::string& extra) {
    return doc(R"("placements":[{"pattern":"crease","joint":"elbow")" +
               (extra.empty() ? std::string() : "," + extra) + "}]");
}

/// A surface placement (SPEC §8) with anchor and size, plus `extra` (members given twice: the
/// later one wins, as nlohmann reads objects).
std::string surface(const std::string& extra) {
    return placement(std::string(R"("projection":"surface",)") +
                     R"("anchor":{"position":[0.1,1.2,0.05],"normal":[0,0,1],"tangent":[1,0,0]},)" +
                     R"("size":[0.08,0.05])" + (extra.empty() ? std::string() : "," + extra));
}

/// A pose with one joint "spine" whose value is `value`.
std::string spine(const std::string& value) {
    return doc(R"("pose":{"joints":{"spine":)" + value + "}}");
}

} // namespace

// --- valid documents ---------------------------------------------------------------------------

TEST(SceneTest, SpecExampleParses) {
    Scene s = parseOk(kSpecExample);
    EXPECT_EQ(s.model, "builtin:default");
    EXPECT_EQ(s.heightmapSize, (std::array<int, 2>{1024, 1024}));
    ASSERT_TRUE(s.heightmapBase.has_value());
    EXPECT_EQ(*s.heightmapBase, "optional/static_height.exr");
    ASSERT_EQ(s.patterns.size(), 1u);
    EXPECT_EQ(s.patterns.at("my_ridge"), "custom/ridge.png");

    ASSERT_EQ(s.placements.size(), 1u);
    const dermis::Placement& p = s.placements[0];
    EXPECT_EQ(p.id, "elbow_l");
    EXPECT_EQ(p.pattern, "crease");
    EXPECT_DOUBLE_EQ(p.center[0], 0.31);
    EXPECT_DOUBLE_EQ(p.center[1], 0.42);
    EXPECT_DOUBLE_EQ(p.scale[0], 0.08);
    EXPECT_DOUBLE_EQ(p.scale[1], 0.05);
    EXPECT_DOUBLE_EQ(p.rotation, 30.0);
    EXPECT_EQ(p.joint, "forearm.l");
    EXPECT_EQ(p.axisName, "x");
    EXPECT_EQ(p.axis, (std::array<double, 3>{1, 0, 0}));
    EXPECT_DOUBLE_EQ(p.thetaMin, 0.0);
    EXPECT_DOUBLE_EQ(p.thetaMax, 120.0);
    EXPECT_DOUBLE_EQ(p.h, 1.0);
    EXPECT_EQ(p.model, dermis::DeformModel::Scale);
    EXPECT_EQ(p.target, dermis::Target::Bump);
    EXPECT_EQ(p.response, dermis::Response::Log2);

    ASSERT_TRUE(s.pose.animation.has_value());
    EXPECT_EQ(*s.pose.animation, "Walk");
    EXPECT_DOUBLE_EQ(s.pose.time, 0.5);
    ASSERT_EQ(s.pose.joints.size(), 2u);
    const dermis::JointPose& fore = s.pose.joints.at("forearm.l");
    ASSERT_TRUE(fore.rotation.has_value());
    EXPECT_FALSE(fore.axisAngles.has_value());
    const auto& q = *fore.rotation;
    EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-12);
    EXPECT_NEAR(q[2] / q[3], 0.383 / 0.924, 1e-12); // direction kept, length normalised
    const dermis::JointPose& sp = s.pose.joints.at("spine");
    ASSERT_TRUE(sp.axisAngles.has_value());
    EXPECT_FALSE(sp.rotation.has_value());
    EXPECT_EQ(*sp.axisAngles, (std::array<double, 3>{20, -10, 0}));

    EXPECT_EQ(s.render.size, (std::array<int, 2>{1024, 1024}));
    EXPECT_DOUBLE_EQ(s.render.camera.yaw, 0.0);
    EXPECT_DOUBLE_EQ(s.render.camera.pitch, 10.0);
    EXPECT_FALSE(s.render.camera.distance.has_value());
    EXPECT_FALSE(s.render.displacementScale.has_value());
    EXPECT_DOUBLE_EQ(s.render.bumpStrength, 1.0);
    EXPECT_EQ(s.render.msaa, 4);
    EXPECT_EQ(s.render.displacement, dermis::DisplacementMode::Vertex);
}

TEST(SceneTest, MinimalDocumentGetsDefaults) {
    Scene s = parseOk(doc(""));
    EXPECT_EQ(s.model, "builtin:default");
    EXPECT_EQ(s.heightmapSize, (std::array<int, 2>{1024, 1024}));
    EXPECT_FALSE(s.heightmapBase.has_value());
    EXPECT_TRUE(s.patterns.empty());
    EXPECT_TRUE(s.placements.empty());
    EXPECT_FALSE(s.pose.animation.has_value());
    EXPECT_EQ(s.pose.time, 0.0);
    EXPECT_TRUE(s.pose.joints.empty());
    EXPECT_EQ(s.render.size, (std::array<int, 2>{1024, 1024}));
    EXPECT_EQ(s.render.camera.yaw, 0.0);
    EXPECT_EQ(s.render.camera.pitch, 10.0);
    EXPECT_FALSE(s.render.camera.distance.has_value());
    EXPECT_FALSE(s.render.displacementScale.has_value());
    EXPECT_EQ(s.render.bumpStrength, 1.0);
    EXPECT_EQ(s.render.msaa, 4);
}

TEST(SceneTest, PlacementDefaultsFollowThePatternKind) {
    Scene s = parseOk(doc(R"("patterns":{"mine":"mine.png"},"placements":[
        {"pattern":"crease","joint":"a"},
        {"pattern":"biceps","joint":"b"},
        {"pattern":"clavicle","joint":"c"},
        {"pattern":"mine","joint":"d"}])"));
    ASSERT_EQ(s.placements.size(), 4u);
    const auto& wrinkle = s.placements[0];
    EXPECT_EQ(wrinkle.model, dermis::DeformModel::Scale);
    EXPECT_EQ(wrinkle.target, dermis::Target::Bump);
    const auto& bulge = s.placements[1];
    EXPECT_EQ(bulge.model, dermis::DeformModel::Scale);
    EXPECT_EQ(bulge.target, dermis::Target::Displacement);
    const auto& bone = s.placements[2];
    EXPECT_EQ(bone.model, dermis::DeformModel::Bias);
    EXPECT_EQ(bone.target, dermis::Target::Bump);
    const auto& custom = s.placements[3];
    EXPECT_EQ(custom.model, dermis::DeformModel::Scale);
    EXPECT_EQ(custom.target, dermis::Target::Bump);

    // The manifest's suggested axis and theta range apply to built-in patterns ...
    EXPECT_EQ(bulge.axisName, "z");
    EXPECT_EQ(bulge.axis, (std::array<double, 3>{0, 0, 1}));
    EXPECT_EQ(bulge.thetaMin, 10.0);
    EXPECT_EQ(bulge.thetaMax, 100.0);
    EXPECT_EQ(bone.axisName, "y");
    EXPECT_EQ(bone.thetaMin, -30.0);
    EXPECT_EQ(bone.thetaMax, 60.0);
    // ... custom patterns get the struct defaults.
    EXPECT_EQ(custom.axisName, "x");
    EXPECT_EQ(custom.thetaMin, 0.0);
    EXPECT_EQ(custom.thetaMax, 90.0);

    // Everything else per placement.
    for (const auto& p : s.placements) {
        EXPECT_EQ(p.center, (std::array<double, 2>{0.5, 0.5}));
        EXPECT_EQ(p.scale, (std::array<double, 2>{0.1, 0.1}));
        EXPECT_EQ(p.rotation, 0.0);
        EXPECT_EQ(p.h, 1.0);
        EXPECT_EQ(p.response, dermis::Response::Log2);
    }
    EXPECT_EQ(s.placements[0].id, "p0");
    EXPECT_EQ(s.placements[3].id, "p3");
}

TEST(SceneTest, ExplicitModelAndTargetOverrideTheKind) {
    Scene s = parseOk(doc(R"("placements":[
        {"pattern":"clavicle","joint":"a","model":"scale","target":"displacement",
         "response":"smoothstep"},
        {"pattern":"biceps","joint":"b","model":"bias","target":"bump","response":"ln"},
        {"pattern":"crease","joint":"c","response":"linear"}])"));
    ASSERT_EQ(s.placements.size(), 3u);
    EXPECT_EQ(s.placements[0].model, dermis::DeformModel::Scale);
    EXPECT_EQ(s.placements[0].target, dermis::Target::Displacement);
    EXPECT_EQ(s.placements[0].response, dermis::Response::Smoothstep);
    EXPECT_EQ(s.placements[1].model, dermis::DeformModel::Bias);
    EXPECT_EQ(s.placements[1].target, dermis::Target::Bump);
    EXPECT_EQ(s.placements[1].response, dermis::Response::Ln);
    EXPECT_EQ(s.placements[2].response, dermis::Response::Linear);
}

TEST(SceneTest, GeneratedIdsAvoidExplicitOnes) {
    Scene s = parseOk(doc(R"("placements":[
        {"pattern":"crease","joint":"a"},
        {"id":"p0","pattern":"crease","joint":"a"},
        {"pattern":"crease","joint":"a"}])"));
    ASSERT_EQ(s.placements.size(), 3u);
    EXPECT_EQ(s.placements[1].id, "p0");
    EXPECT_NE(s.placements[0].id, "p0");
    EXPECT_EQ(s.placements[0].id.rfind("p0", 0), 0u);
    EXPECT_EQ(s.placements[2].id, "p2");
    expectStableRoundTrip(doc(R"("placements":[{"pattern":"crease","joint":"a"},
                                 {"id":"p0","pattern":"crease","joint":"a"}])"));
}

TEST(SceneTest, AxisVectorIsNormalised) {
    Scene s = parseOk(placement(R"("axis":[0, 3, -4])"));
    ASSERT_EQ(s.placements.size(), 1u);
    const auto& p = s.placements[0];
    EXPECT_EQ(p.axisName, "");
    EXPECT_NEAR(p.axis[0], 0.0, 1e-15);
    EXPECT_NEAR(p.axis[1], 0.6, 1e-15);
    EXPECT_NEAR(p.axis[2], -0.8, 1e-15);

    // Tiny and huge vectors neither underflow nor overflow.
    Scene tiny = parseOk(placement(R"("axis":[1e-300, 0, 1e-300])"));
    EXPECT_NEAR(tiny.placements[0].axis[0], std::sqrt(0.5), 1e-15);
    Scene huge = parseOk(placement(R"("axis":[1e300, 1e300, 0])"));
    EXPECT_NEAR(huge.placements[0].axis[1], std::sqrt(0.5), 1e-15);

    // Named axes.
    EXPECT_EQ(parseOk(placement(R"("axis":"y")")).placements[0].axis,
              (std::array<double, 3>{0, 1, 0}));
    EXPECT_EQ(parseOk(placement(R"("axis":"z")")).placements[0].axisName, "z");
}

TEST(SceneTest, QuaternionIsNormalised) {
    Scene s = parseOk(spine(R"({"rotation":[0, 0, 2, 0]})"));
    EXPECT_EQ(*s.pose.joints.at("spine").rotation, (std::array<double, 4>{0, 0, 1, 0}));
}

TEST(SceneTest, RoundTripIsStable) {
    expectStableRoundTrip(kSpecExample);
    expectStableRoundTrip(doc(""));
    expectStableRoundTrip(doc(R"("patterns":{"mine":"a/b.png","z.1-x":"c.exr"},"placements":[
        {"pattern":"crease","joint":"a","axis":[0.1, 0.2, 0.3],"rotation":-12.345},
        {"pattern":"mine","joint":"b","axis":[1, 1, 1],"h":0.3333333333333333,
         "theta_min":90,"theta_max":-45.5},
        {"pattern":"biceps","joint":"c","center":[1e-7, 0.9999999],"scale":[16, 1e-9]}],
        "pose":{"time":3.25,"joints":{"a/b~c":{"rotation":[0.1, 0.2, 0.3, 0.4]},
                                      "q":{"rotation":[0.5, 0.5, 0.5, 0.5]},
                                      "e":{"axis_angles":{}}},"morphs":{"smile":0.75,"a/b":-10}},
        "render":{"size":[640, 480],"camera":{"yaw":-725.5,"pitch":-90,"distance":3.5},
                  "displacement_scale":0,"bump_strength":0,"msaa":1})"));
}

TEST(SceneTest, RoundTripOfNormalisedVectorsIsStable) {
    // Normalisation must be idempotent bit for bit, or re-saving a scene would drift.
    std::mt19937_64 rng(12345);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    std::uniform_int_distribution<int> exponent(-200, 200);
    for (int i = 0; i < 300; ++i) {
        auto component = [&] { return uni(rng) * std::pow(10.0, exponent(rng) % 8); };
        json axis = json::array({component(), component(), component()});
        json quat = json::array({component(), component(), component(), component()});
        expectStableRoundTrip(placement(R"("axis":)" + axis.dump()) + "");
        expectStableRoundTrip(spine(R"({"rotation":)" + quat.dump() + "}"));
    }
}

TEST(SceneTest, EnabledAndLabelRoundTrip) {
    const Scene defaults = parseOk(placement(""));
    EXPECT_TRUE(defaults.placements[0].enabled);
    EXPECT_EQ(defaults.placements[0].label, "");
    const std::string label = "inner elbow \u2014 left"; // UTF-8, 120 bytes allowed
    const Scene s = parseOk(placement(R"("enabled":false,"label":")" + label + R"(")"));
    EXPECT_FALSE(s.placements[0].enabled);
    EXPECT_EQ(s.placements[0].label, "inner elbow \xE2\x80\x94 left");
    const json j = dermis::toJson(s);
    EXPECT_EQ(j["placements"][0]["enabled"], false);
    EXPECT_EQ(j["placements"][0]["label"], "inner elbow \xE2\x80\x94 left");
    expectStableRoundTrip(placement(R"("enabled":false,"label":")" + std::string(120, 'y') + R"(")"));
}

TEST(SceneTest, EveryShadingRoundTrips) {
    for (const char* name : {"legacy", "pbr", "skin"}) {
        const auto shading = dermis::shadingFromString(name);
        ASSERT_TRUE(shading) << name;
        EXPECT_EQ(dermis::toString(*shading), name);
    }
    EXPECT_FALSE(dermis::shadingFromString("Skin")) << "names are case-sensitive";
    const Scene s = parseOk(doc(R"("render":{"shading":"skin"})"));
    EXPECT_EQ(s.render.shading, dermis::Shading::Skin);
    EXPECT_EQ(dermis::toJson(s)["render"]["shading"], "skin");
    expectStableRoundTrip(doc(R"("render":{"shading":"skin"})"));
    // pbr is the default (since 2026-11-30): not written; legacy, the old default, is.
    const Scene plain = parseOk(doc(""));
    EXPECT_EQ(plain.render.shading, dermis::Shading::Pbr);
    EXPECT_FALSE(dermis::toJson(plain)["render"].contains("shading"));
    const Scene legacy = parseOk(doc(R"("render":{"shading":"legacy"})"));
    EXPECT_EQ(dermis::toJson(legacy)["render"]["shading"], "legacy");
    expectStableRoundTrip(doc(R"("render":{"shading":"legacy"})"));
}

TEST(SceneTest, EnvironmentIsWrittenOnlyWhenNamed) {
    const Scene plain = parseOk(doc(""));
    EXPECT_EQ(plain.render.environment, "");
    EXPECT_FALSE(dermis::toJson(plain)["render"].contains("environment")) << "older documents keep their text";
    const Scene named = parseOk(doc(R"("render":{"environment":"e_0123456789abcdef"})"));
    EXPECT_EQ(named.render.environment, "e_0123456789abcdef");
    EXPECT_EQ(dermis::toJson(named)["render"]["environment"], "e_0123456789abcdef");
    expectStableRoundTrip(doc(R"("render":{"environment":"sky/studio.hdr"})"));
    expectStableRoundTrip(doc(R"("render":{"environment":"builtin:studio"})"));
}

TEST(SceneTest, KeyLightIsWrittenOnlyWhenSetAndRoundTrips) {
    const Scene plain = parseOk(doc(""));
    EXPECT_FALSE(plain.render.keyLight);
    EXPECT_FALSE(dermis::toJson(plain)["render"].contains("key_light")) << "older documents keep their text";
    // An empty object is the default light, members fill in over it.
    const Scene defaults = parseOk(doc(R"("render":{"key_light":{}})"));
    ASSERT_TRUE(defaults.render.keyLight);
    EXPECT_EQ(*defaults.render.keyLight, dermis::KeyLight{});
    const Scene set = parseOk(doc(R"("render":{"key_light":{"direction":[1,2,3],"intensity":7.5,"color":[1,0.5,0.25],"shadow":false}})"));
    ASSERT_TRUE(set.render.keyLight);
    const dermis::KeyLight& k = *set.render.keyLight;
    EXPECT_EQ(k.direction, (std::array<double, 3>{1, 2, 3}));
    EXPECT_EQ(k.intensity, 7.5);
    EXPECT_EQ(k.color, (std::array<double, 3>{1, 0.5, 0.25}));
    EXPECT_FALSE(k.shadow);
    const auto written = dermis::toJson(set)["render"]["key_light"];
    EXPECT_EQ(written["direction"], nlohmann::json::array({1, 2, 3}));
    EXPECT_EQ(written["shadow"], false);
    expectStableRoundTrip(doc(R"("render":{"key_light":{"direction":[-0.5,1,0.6],"intensity":3,"color":[1,1,1],"shadow":true}})"));
    // null removes it (what a PUT of a document without the light does too).
    EXPECT_FALSE(parseOk(doc(R"("render":{"key_light":null})")).render.keyLight);
    // The unit direction and the shadow camera (core/key_light.hpp).
    const glm::vec3 l = dermis::keyLightDirection(k);
    EXPECT_NEAR(glm::length(l), 1.0f, 1e-6f);
    EXPECT_NEAR(l.z / l.x, 3.0f, 1e-5f);
}

TEST(SceneTest, TheShadowCameraSeesTheWholeCharacterFromTheLight) {
    const glm::vec3 lo(-0.4f, 0.0f, -0.2f), hi(0.6f, 1.8f, 0.3f);
    for (const glm::vec3 dir : {glm::vec3(0, 1, 0), glm::vec3(0, -1, 0), glm::vec3(1, 0.3f, 0.2f),
                                glm::vec3(-0.5f, 1, 0.6f)}) {
        const glm::vec3 l = glm::normalize(dir);
        const dermis::ShadowCamera sc = dermis::shadowCamera(lo, hi, 0.05, l, 2048);
        EXPECT_NEAR(sc.radius, 0.5f * glm::length(hi - lo) + 0.05f, 1e-5f);
        EXPECT_NEAR(sc.texelWorld, 2.0f * sc.radius / 2048.0f, 1e-7f);
        // Every corner of the bounds, pushed out by the displacement scale, lies in the clip volume.
        for (int c = 0; c < 8; ++c) {
            const glm::vec3 p((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
            const glm::vec4 q = sc.viewProj * glm::vec4(p, 1.0f);
            for (int k = 0; k < 3; ++k) EXPECT_LE(std::abs(q[k] / q.w), 1.0f) << c;
        }
        // Nearer the light is smaller depth: the centre moved towards the light.
        const glm::vec3 centre = 0.5f * (lo + hi);
        const float z0 = (sc.viewProj * glm::vec4(centre, 1.0f)).z;
        const float z1 = (sc.viewProj * glm::vec4(centre + 0.1f * l, 1.0f)).z;
        EXPECT_LT(z1, z0);
        // A step across the light does not change depth.
        const glm::vec3 across = glm::normalize(glm::cross(l, std::abs(l.y) > 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0)));
        EXPECT_NEAR((sc.viewProj * glm::vec4(centre + 0.3f * across, 1.0f)).z, z0, 1e-5f);
    }
}

TEST(SceneTest, UvLayoutDefaultsToAutoAndRoundTrips) {
    EXPECT_EQ(parseOk(doc("")).uvLayout, dermis::UvLayoutMode::Auto);
    EXPECT_EQ(dermis::toJson(parseOk(doc("")))["uv_layout"], "auto");
    for (const char* mode : {"auto", "model", "generated"}) {
        const Scene s = parseOk(doc(std::string(R"("uv_layout":")") + mode + "\""));
        EXPECT_EQ(dermis::toString(s.uvLayout), mode);
        EXPECT_EQ(dermis::toJson(s)["uv_layout"], mode);
        expectStableRoundTrip(doc(std::string(R"("uv_layout":")") + mode + "\""));
    }
}

TEST(SceneTest, SurfacePlacementParsesAndEchoesItsMembers) {
    const Scene s = parseOk(surface(R"("rotation":30)"));
    const dermis::Placement& p = s.placements[0];
    EXPECT_EQ(p.projection, dermis::Projection::Surface);
    EXPECT_EQ(p.anchor.position, (std::array<double, 3>{0.1, 1.2, 0.05}));
    EXPECT_EQ(p.anchor.normal, (std::array<double, 3>{0, 0, 1}));
    EXPECT_EQ(p.anchor.tangent, (std::array<double, 3>{1, 0, 0}));
    EXPECT_EQ(p.size, (std::array<double, 2>{0.08, 0.05}));
    EXPECT_FALSE(p.depth.has_value());
    EXPECT_DOUBLE_EQ(p.depthOrDefault(), 0.04); // max(w, h) / 2
    const json j = dermis::toJson(s)["placements"][0];
    EXPECT_EQ(j["projection"], "surface");
    EXPECT_EQ(j["anchor"]["position"], json::array({0.1, 1.2, 0.05}));
    EXPECT_EQ(j["anchor"]["normal"], json::array({0.0, 0.0, 1.0}));
    EXPECT_EQ(j["anchor"]["tangent"], json::array({1.0, 0.0, 0.0}));
    EXPECT_EQ(j["size"], json::array({0.08, 0.05}));
    EXPECT_EQ(j["depth"], "auto");
    EXPECT_EQ(j["rotation"], 30.0);
    expectStableRoundTrip(surface(R"("rotation":30)"));

    const Scene d = parseOk(surface(R"("depth":0.02)"));
    EXPECT_DOUBLE_EQ(d.placements[0].depthOrDefault(), 0.02);
    EXPECT_EQ(dermis::toJson(d)["placements"][0]["depth"], 0.02);
    EXPECT_FALSE(parseOk(surface(R"("depth":"auto")")).placements[0].depth.has_value());
}

TEST(SceneTest, UvPlacementsEchoProjectionButNoSurfaceMembers) {
    const json j = dermis::toJson(parseOk(placement("")))["placements"][0];
    EXPECT_EQ(j["projection"], "uv");
    for (const char* key : {"anchor", "size", "depth"}) EXPECT_FALSE(j.contains(key)) << key;
    // Surface members on a UV placement are checked (above) but not kept: switching back to
    // "uv" drops them from the canonical document.
    const Scene s = parseOk(surface(R"("projection":"uv")"));
    EXPECT_EQ(s.placements[0].projection, dermis::Projection::Uv);
    EXPECT_FALSE(dermis::toJson(s)["placements"][0].contains("anchor"));
}

TEST(SceneTest, AnchorIsNormalisedAndTheTangentMadeOrthogonal) {
    const Scene s = parseOk(surface(
        R"("anchor":{"position":[1,2,3],"normal":[0,0,2],"tangent":[3,0,4]})"));
    const dermis::SurfaceAnchor& a = s.placements[0].anchor;
    EXPECT_EQ(a.normal, (std::array<double, 3>{0, 0, 1}));
    EXPECT_NEAR(a.tangent[0], 1.0, 1e-15);
    EXPECT_NEAR(a.tangent[1], 0.0, 1e-15);
    EXPECT_NEAR(a.tangent[2], 0.0, 1e-15);
    // Oblique vectors: unit, orthogonal, and stable through parse → serialise → parse.
    const std::string oblique =
        surface(R"("anchor":{"position":[1,2,3],"normal":[0.3,-0.7,0.2],"tangent":[0.9,0.4,0.5]})");
    const Scene o = parseOk(oblique);
    const auto& n = o.placements[0].anchor.normal;
    const auto& t = o.placements[0].anchor.tangent;
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-14);
    EXPECT_NEAR(t[0] * t[0] + t[1] * t[1] + t[2] * t[2], 1.0, 1e-14);
    EXPECT_NEAR(n[0] * t[0] + n[1] * t[1] + n[2] * t[2], 0.0, 1e-14);
    expectStableRoundTrip(oblique);
}

TEST(SceneTest, SerialisationWritesEveryField) {
    json j = dermis::toJson(parseOk(placement("")));
    EXPECT_EQ(j["format"], "dermis.scene/1");
    EXPECT_EQ(j["model"], "builtin:default");
    EXPECT_EQ(j["heightmap"]["size"], json::array({1024, 1024}));
    EXPECT_FALSE(j["heightmap"].contains("base"));
    EXPECT_TRUE(j["patterns"].is_object());
    const json& p = j["placements"][0];
    for (const char* key : {"id", "pattern", "center", "scale", "rotation", "joint", "axis",
                            "theta_min", "theta_max", "h", "model", "target", "response",
                            "enabled", "label", "projection"})
        EXPECT_TRUE(p.contains(key)) << key;
    EXPECT_EQ(j["uv_layout"], "auto");
    EXPECT_EQ(p["axis"], "x");
    EXPECT_EQ(p["response"], "log2");
    EXPECT_FALSE(j["pose"].contains("animation")); // absent = the model's first clip
    EXPECT_EQ(j["pose"]["time"], 0.0);
    EXPECT_TRUE(j["pose"]["joints"].is_object());
    EXPECT_EQ(j["render"]["camera"]["distance"], "auto");
    EXPECT_EQ(j["render"]["displacement_scale"], "auto");
    EXPECT_EQ(j["render"]["msaa"], 4);
    EXPECT_EQ(j["render"]["displacement"], "vertex");

    json v = dermis::toJson(parseOk(placement(R"("axis":[0, 0, 5])")));
    EXPECT_EQ(v["placements"][0]["axis"], json::array({0.0, 0.0, 1.0}));
    json a = dermis::toJson(parseOk(spine(R"({"axis_angles":{"y":15}})")));
    EXPECT_EQ(a["pose"]["joints"]["spine"]["axis_angles"],
              json({{"x", 0.0}, {"y", 15.0}, {"z", 0.0}}));
}

TEST(SceneTest, AcceptsEdgeValues) {
    // Integral floats are integers; sizes at both limits; reversed theta range; h = 0.
    Scene s = parseOk(doc(R"("heightmap":{"size":[4096.0, 1]},"render":{"size":[8192, 1],
        "camera":{"pitch":90},"msaa":2,"displacement":"tessellated"},"placements":[{"pattern":"crease","joint":"j",
        "theta_min":120,"theta_max":0,"h":0}])"));
    EXPECT_EQ(s.heightmapSize, (std::array<int, 2>{4096, 1}));
    EXPECT_EQ(s.render.size, (std::array<int, 2>{8192, 1}));
    EXPECT_EQ(s.render.msaa, 2);
    EXPECT_EQ(s.render.displacement, dermis::DisplacementMode::Tessellated);
    EXPECT_EQ(s.placements[0].thetaMin, 120.0);
    EXPECT_EQ(s.placements[0].h, 0.0);
    // Every bound is inclusive (scene.hpp kMax…).
    Scene b = parseOk(doc(R"("placements":[{"pattern":"crease","joint":"j","h":100,"scale":[16, 16],
        "center":[-16, 16],"rotation":-3600,"theta_min":-360,"theta_max":360}],
        "pose":{"time":86400,"joints":{"j":{"axis_angles":{"x":360,"y":-360}}}},
        "render":{"camera":{"yaw":3600,"distance":10000},"displacement_scale":1000,"bump_strength":100})"));
    EXPECT_EQ(b.placements[0].h, dermis::kMaxPlacementHeight);
    EXPECT_EQ(b.placements[0].thetaMax, dermis::kMaxAngle);
    EXPECT_EQ(b.render.bumpStrength, dermis::kMaxBumpStrength);
    // Unknown fields are ignored at every level.
    parseOk(doc(R"("future":1,"render":{"hdr":true},"placements":[{"pattern":"crease",
        "joint":"j","note":"x"}],"pose":{"joints":{"j":{"rotation":[0,0,0,1],"w":1}}})"));
    // A UTF-8 BOM and surrounding whitespace are fine.
    parseOk("\xEF\xBB\xBF  " + doc("") + "\n");
}

TEST(SceneTest, ParseSceneFromJsonValue) {
    json j = json::parse(kSpecExample);
    auto a = dermis::parseScene(j, testManifest());
    ASSERT_TRUE(a.ok()) << a.error().message;
    EXPECT_EQ(dermis::toJson(*a).dump(), dermis::toJson(parseOk(kSpecExample)).dump());
}

// --- invalid documents: each names its offending field ---------------------------------------

struct BadCase {
    const char* name;
    std::string text;
    std::string pointer;
    ErrorCode code = ErrorCode::InvalidArgument;
};

class SceneBadInput : public testing::TestWithParam<BadCase> {};

TEST_P(SceneBadInput, NamesTheField) {
    const BadCase& c = GetParam();
    auto r = parse(c.text);
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_EQ(r.error().field, c.pointer) << r.error().message;
    EXPECT_EQ(r.error().code, c.code) << r.error().message;
    EXPECT_FALSE(r.error().message.empty());
    if (!c.pointer.empty())
        EXPECT_NE(r.error().message.find(c.pointer), std::string::npos) << r.error().message;
}

const BadCase kBadCases[] = {
    // Malformed JSON and the root.
    {"Empty", "", "", ErrorCode::Parse},
    {"Truncated", R"({"format": "dermis.scene/1",)", "", ErrorCode::Parse},
    {"TrailingComma", R"({"format": "dermis.scene/1",})", "", ErrorCode::Parse},
    {"TrailingGarbage", doc("") + "x", "", ErrorCode::Parse},
    {"NaNLiteral", doc(R"("render":{"bump_strength":NaN})"), "", ErrorCode::Parse},
    {"Comment", "// c\n" + doc(""), "", ErrorCode::Parse},
    {"RootArray", "[1, 2]", ""},
    {"RootNull", "null", ""},
    {"RootString", R"("dermis.scene/1")", ""},
    // format.
    {"FormatMissing", "{}", "/format"},
    {"FormatOtherVersion", R"({"format":"dermis.scene/2"})", "/format", ErrorCode::Unsupported},
    {"FormatWrong", R"({"format":"scene"})", "/format"},
    {"FormatNumber", R"({"format":1})", "/format"},
    // model.
    {"ModelEmpty", doc(R"("model":"")"), "/model"},
    {"ModelNumber", doc(R"("model":5)"), "/model"},
    {"ModelBuiltinTraversal", doc(R"("model":"builtin:../../etc/passwd")"), "/model"},
    {"ModelBuiltinEmpty", doc(R"("model":"builtin:")"), "/model"},
    // heightmap.
    {"HeightmapArray", doc(R"("heightmap":[])"), "/heightmap"},
    {"HeightmapZeroSize", doc(R"("heightmap":{"size":[0, 1024]})"), "/heightmap/size/0"},
    {"HeightmapNegativeSize", doc(R"("heightmap":{"size":[1024, -1]})"), "/heightmap/size/1"},
    {"HeightmapHugeSize", doc(R"("heightmap":{"size":[8192, 8192]})"), "/heightmap/size/0"},
    {"HeightmapVeryHugeSize", doc(R"("heightmap":{"size":[16, 1e300]})"), "/heightmap/size/1"},
    {"HeightmapFractionalSize", doc(R"("heightmap":{"size":[10.5, 10]})"), "/heightmap/size/0"},
    {"HeightmapOneElement", doc(R"("heightmap":{"size":[1024]})"), "/heightmap/size"},
    {"HeightmapSizeString", doc(R"("heightmap":{"size":"1024"})"), "/heightmap/size"},
    {"HeightmapSizeBool", doc(R"("heightmap":{"size":[true, 1]})"), "/heightmap/size/0"},
    {"HeightmapBaseEmpty", doc(R"("heightmap":{"base":""})"), "/heightmap/base"},
    {"HeightmapBaseNull", doc(R"("heightmap":{"base":null})"), "/heightmap/base"},
    // patterns.
    {"PatternsArray", doc(R"("patterns":["a.png"])"), "/patterns"},
    {"PatternIdWithSlash", doc(R"("patterns":{"a/b":"x.png"})"), "/patterns/a~1b"},
    {"PatternIdDotDot", doc(R"("patterns":{"..":"x.png"})"), "/patterns/.."},
    {"PatternIdBuiltin", doc(R"("patterns":{"crease":"x.png"})"), "/patterns/crease"},
    {"PatternPathNumber", doc(R"("patterns":{"mine":3})"), "/patterns/mine"},
    {"PatternPathEmpty", doc(R"("patterns":{"mine":""})"), "/patterns/mine"},
    // placements.
    {"PlacementsObject", doc(R"("placements":{})"), "/placements"},
    {"PlacementNotObject", doc(R"("placements":[1])"), "/placements/0"},
    {"PatternMissing", doc(R"("placements":[{"joint":"a"}])"), "/placements/0/pattern"},
    {"PatternUnknown", doc(R"("placements":[{"pattern":"nope","joint":"a"}])"),
     "/placements/0/pattern", ErrorCode::NotFound},
    {"PatternNull", doc(R"("placements":[{"pattern":null,"joint":"a"}])"), "/placements/0/pattern"},
    {"JointMissing", doc(R"("placements":[{"pattern":"crease"}])"), "/placements/0/joint"},
    {"JointEmpty", doc(R"("placements":[{"pattern":"crease","joint":""}])"), "/placements/0/joint"},
    {"CenterOneElement", placement(R"("center":[0.5])"), "/placements/0/center"},
    {"CenterString", placement(R"("center":["a", 0.5])"), "/placements/0/center/0"},
    {"CenterOverflow", placement(R"("center":[0.5, 1e999])"), "/placements/0/center/1"},
    {"ScaleZero", placement(R"("scale":[0, 0.1])"), "/placements/0/scale/0"},
    {"ScaleNegative", placement(R"("scale":[0.1, -1])"), "/placements/0/scale/1"},
    {"ScaleHuge", placement(R"("scale":[100, 0.1])"), "/placements/0/scale/0"},
    {"RotationString", placement(R"("rotation":"30")"), "/placements/0/rotation"},
    {"RotationNull", placement(R"("rotation":null)"), "/placements/0/rotation"},
    {"ThetaEqual", placement(R"("theta_min":45,"theta_max":45)"), "/placements/0/theta_max"},
    {"ThetaEqualToDefault", placement(R"("theta_max":0)"), "/placements/0/theta_max"},
    {"ThetaMinString", placement(R"("theta_min":"0")"), "/placements/0/theta_min"},
    {"ThetaMaxOverflow", placement(R"("theta_max":-1e400)"), "/placements/0/theta_max"},
    {"HNegative", placement(R"("h":-1)"), "/placements/0/h"},
    {"HOverflow", placement(R"("h":1e400)"), "/placements/0/h"},
    {"HBool", placement(R"("h":true)"), "/placements/0/h"},
    {"EnabledString", placement(R"("enabled":"false")"), "/placements/0/enabled"},
    {"EnabledNumber", placement(R"("enabled":0)"), "/placements/0/enabled"},
    {"LabelNumber", placement(R"("label":7)"), "/placements/0/label"},
    {"LabelTooLong", placement(R"("label":")" + std::string(121, 'x') + R"(")"), "/placements/0/label"},
    {"ModelUnknown", placement(R"("model":"linear")"), "/placements/0/model"},
    {"TargetUnknown", placement(R"("target":"normal")"), "/placements/0/target"},
    {"ResponseUnknown", placement(R"("response":"log10")"), "/placements/0/response"},
    {"ResponseNumber", placement(R"("response":2)"), "/placements/0/response"},
    {"AxisName", placement(R"("axis":"w")"), "/placements/0/axis"},
    {"AxisUpperCase", placement(R"("axis":"X")"), "/placements/0/axis"},
    {"AxisZero", placement(R"("axis":[0, 0, 0])"), "/placements/0/axis"},
    {"AxisTwoElements", placement(R"("axis":[1, 0])"), "/placements/0/axis"},
    {"AxisStringElement", placement(R"("axis":[1, "0", 0])"), "/placements/0/axis/1"},
    {"AxisBool", placement(R"("axis":true)"), "/placements/0/axis"},
    {"IdDuplicate", doc(R"("placements":[{"id":"a","pattern":"crease","joint":"j"},
        {"id":"a","pattern":"crease","joint":"j"}])"),
     "/placements/1/id"},
    {"IdNumber", placement(R"("id":7)"), "/placements/0/id"},
    {"IdSlash", placement(R"("id":"a/b")"), "/placements/0/id"},
    {"IdEmpty", placement(R"("id":"")"), "/placements/0/id"},
    {"SecondPlacement", doc(R"("placements":[{"pattern":"crease","joint":"j"},
        {"pattern":"crease","joint":"j","h":-2}])"),
     "/placements/1/h"},
    {"SecondPlacementOverflow", doc(R"("placements":[{"pattern":"crease","joint":"j"},
        {"pattern":"crease","joint":"j","scale":[0.1, 2e308]}])"),
     "/placements/1/scale/1"},
    // pose.
    {"PoseArray", doc(R"("pose":[])"), "/pose"},
    {"PoseTimeNegative", doc(R"("pose":{"time":-1})"), "/pose/time"},
    {"PoseTimeString", doc(R"("pose":{"time":"0"})"), "/pose/time"},
    {"PoseAnimationEmpty", doc(R"("pose":{"animation":""})"), "/pose/animation"},
    {"PoseAnimationNumber", doc(R"("pose":{"animation":3})"), "/pose/animation"},
    {"PoseJointsArray", doc(R"("pose":{"joints":[]})"), "/pose/joints"},
    {"JointBoth", spine(R"({"rotation":[0,0,0,1],"axis_angles":{"x":1}})"), "/pose/joints/spine"},
    {"JointNeither", spine("{}"), "/pose/joints/spine"},
    {"JointNumber", spine("5"), "/pose/joints/spine"},
    {"JointZeroQuaternion", spine(R"({"rotation":[0,0,0,0]})"), "/pose/joints/spine/rotation"},
    {"JointThreeElementQuaternion", spine(R"({"rotation":[0,0,1]})"),
     "/pose/joints/spine/rotation"},
    {"JointQuaternionString", spine(R"({"rotation":[0,0,"1",0]})"),
     "/pose/joints/spine/rotation/2"},
    {"JointQuaternionOverflow", spine(R"({"rotation":[0,0,1e309,1]})"),
     "/pose/joints/spine/rotation/2"},
    {"JointAxisAnglesString", spine(R"({"axis_angles":{"x":"20"}})"),
     "/pose/joints/spine/axis_angles/x"},
    {"JointAxisAnglesArray", spine(R"({"axis_angles":[20]})"), "/pose/joints/spine/axis_angles"},
    {"JointNameEscaped", doc(R"("pose":{"joints":{"a/b~c":{"rotation":[0,0,0,0]}}})"),
     "/pose/joints/a~1b~0c/rotation"},
    {"JointNameEmpty", doc(R"("pose":{"joints":{"":{"rotation":[0,0,0,1]}}})"), "/pose/joints/"},
    {"PoseMorphsArray", doc(R"("pose":{"morphs":[]})"), "/pose/morphs"},
    {"PoseMorphString", doc(R"("pose":{"morphs":{"smile":"1"}})"), "/pose/morphs/smile"},
    {"PoseMorphTooLarge", doc(R"("pose":{"morphs":{"smile":11}})"), "/pose/morphs/smile"},
    {"PoseMorphNameEmpty", doc(R"("pose":{"morphs":{"":1}})"), "/pose/morphs/"},
    // render.
    {"RenderNumber", doc(R"("render":1)"), "/render"},
    {"RenderSizeZero", doc(R"("render":{"size":[0, 1]})"), "/render/size/0"},
    {"RenderSizeHuge", doc(R"("render":{"size":[9000, 10]})"), "/render/size/0"},
    {"RenderSizeNull", doc(R"("render":{"size":null})"), "/render/size"},
    {"CameraString", doc(R"("render":{"camera":"front"})"), "/render/camera"},
    {"CameraYawNull", doc(R"("render":{"camera":{"yaw":null}})"), "/render/camera/yaw"},
    {"CameraPitchOutOfRange", doc(R"("render":{"camera":{"pitch":95}})"), "/render/camera/pitch"},
    {"CameraDistanceZero", doc(R"("render":{"camera":{"distance":0}})"), "/render/camera/distance"},
    {"CameraDistanceWord", doc(R"("render":{"camera":{"distance":"far"}})"),
     "/render/camera/distance"},
    {"CameraDistanceOverflow", doc(R"("render":{"camera":{"distance":1e999}})"),
     "/render/camera/distance"},
    {"DisplacementScaleNegative", doc(R"("render":{"displacement_scale":-1})"),
     "/render/displacement_scale"},
    {"DisplacementScaleWord", doc(R"("render":{"displacement_scale":"big"})"),
     "/render/displacement_scale"},
    {"DisplacementScaleBool", doc(R"("render":{"displacement_scale":false})"),
     "/render/displacement_scale"},
    {"BumpStrengthNegative", doc(R"("render":{"bump_strength":-0.5})"), "/render/bump_strength"},
    {"BumpStrengthOverflow", doc(R"("render":{"bump_strength":1e999})"), "/render/bump_strength"},
    {"MsaaThree", doc(R"("render":{"msaa":3})"), "/render/msaa"},
    {"MsaaEight", doc(R"("render":{"msaa":8})"), "/render/msaa"},
    {"MsaaZero", doc(R"("render":{"msaa":0})"), "/render/msaa"},
    {"AaUnknownMode", doc(R"("render":{"aa":"smaa"})"), "/render/aa"},
    {"AaNotAString", doc(R"("render":{"aa":4})"), "/render/aa"},
    {"MsaaString", doc(R"("render":{"msaa":"4"})"), "/render/msaa"},
    {"DisplacementUnknown", doc(R"("render":{"displacement":"geometry"})"), "/render/displacement"},
    {"DisplacementNumber", doc(R"("render":{"displacement":1})"), "/render/displacement"},
    {"MsaaFraction", doc(R"("render":{"msaa":2.5})"), "/render/msaa"},
    {"ShadingUnknown", doc(R"("render":{"shading":"toon"})"), "/render/shading"},
    {"ShadingNotAString", doc(R"("render":{"shading":true})"), "/render/shading"},
    {"ExposureNegative", doc(R"("render":{"exposure":-1})"), "/render/exposure"},
    {"ExposureTooLarge", doc(R"("render":{"exposure":65})"), "/render/exposure"},
    {"ToneMappingUnknown", doc(R"("render":{"tone_mapping":"filmic"})"), "/render/tone_mapping"},
    {"EnvironmentNotAString", doc(R"("render":{"environment":7})"), "/render/environment"},
    {"EnvironmentEmpty", doc(R"("render":{"environment":""})"), "/render/environment"},
    {"EnvironmentUnknownBuiltin", doc(R"("render":{"environment":"builtin:sunset"})"), "/render/environment"},
    {"EnvironmentRotationTooLarge", doc(R"("render":{"environment_rotation":3601})"),
     "/render/environment_rotation"},
    {"EnvironmentRotationString", doc(R"("render":{"environment_rotation":"90"})"),
     "/render/environment_rotation"},
    {"KeyLightNotAnObject", doc(R"("render":{"key_light":true})"), "/render/key_light"},
    {"KeyLightDirectionZero", doc(R"("render":{"key_light":{"direction":[0,0,0]}})"), "/render/key_light/direction"},
    {"KeyLightDirectionShort", doc(R"("render":{"key_light":{"direction":[0,1]}})"), "/render/key_light/direction"},
    {"KeyLightDirectionHuge", doc(R"("render":{"key_light":{"direction":[0,1e9,0]}})"), "/render/key_light/direction"},
    {"KeyLightIntensityNegative", doc(R"("render":{"key_light":{"intensity":-1}})"), "/render/key_light/intensity"},
    {"KeyLightIntensityTooLarge", doc(R"("render":{"key_light":{"intensity":101}})"), "/render/key_light/intensity"},
    {"KeyLightColorAboveOne", doc(R"("render":{"key_light":{"color":[1,1.5,1]}})"), "/render/key_light/color"},
    {"KeyLightColorString", doc(R"("render":{"key_light":{"color":"white"}})"), "/render/key_light/color"},
    {"KeyLightShadowNumber", doc(R"("render":{"key_light":{"shadow":1}})"), "/render/key_light/shadow"},
    // Bounds of every number (issue #12.7; scene.hpp kMax…).
    {"HeightHuge", placement(R"("h":1e39)"), "/placements/0/h"},
    {"HeightAboveMax", placement(R"("h":100.5)"), "/placements/0/h"},
    {"HeightNegative", placement(R"("h":-1)"), "/placements/0/h"},
    {"ScaleAboveMax", placement(R"("scale":[0.1, 17])"), "/placements/0/scale/1"},
    {"CenterHuge", placement(R"("center":[1e300, 0.5])"), "/placements/0/center/0"},
    {"CenterBelowMin", placement(R"("center":[0.5, -16.5])"), "/placements/0/center/1"},
    {"RotationHuge", placement(R"("rotation":1e30)"), "/placements/0/rotation"},
    {"RotationAboveMax", placement(R"("rotation":3601)"), "/placements/0/rotation"},
    {"ThetaMinBelowMin", placement(R"("theta_min":-361)"), "/placements/0/theta_min"},
    {"ThetaMaxHuge", placement(R"("theta_max":1e20)"), "/placements/0/theta_max"},
    {"PoseTimeHuge", doc(R"("pose":{"time":1e12})"), "/pose/time"},
    {"AxisAngleHuge", doc(R"("pose":{"joints":{"j":{"axis_angles":{"y":1e9}}}})"),
     "/pose/joints/j/axis_angles/y"},
    {"CameraYawHuge", doc(R"("render":{"camera":{"yaw":1e300}})"), "/render/camera/yaw"},
    {"CameraDistanceHuge", doc(R"("render":{"camera":{"distance":1e300}})"),
     "/render/camera/distance"},
    {"DisplacementScaleHuge", doc(R"("render":{"displacement_scale":1e39})"),
     "/render/displacement_scale"},
    {"BumpStrengthHuge", doc(R"("render":{"bump_strength":100.5})"), "/render/bump_strength"},
    // uv_layout and surface placements (SPEC §8).
    {"UvLayoutUnknown", doc(R"("uv_layout":"atlas")"), "/uv_layout"},
    {"UvLayoutNumber", doc(R"("uv_layout":1)"), "/uv_layout"},
    {"ProjectionUnknown", placement(R"("projection":"planar")"), "/placements/0/projection"},
    {"SurfaceWithoutAnchor", placement(R"("projection":"surface","size":[0.1,0.1])"),
     "/placements/0/anchor"},
    {"SurfaceWithoutSize", surface(R"("size":null)"), "/placements/0/size"},
    {"AnchorArray", placement(R"("projection":"surface","anchor":[0,0,0],"size":[1,1])"),
     "/placements/0/anchor"},
    {"AnchorWithoutNormal",
     placement(R"("projection":"surface","anchor":{"position":[0,0,0],"tangent":[1,0,0]},"size":[1,1])"),
     "/placements/0/anchor/normal"},
    {"AnchorPositionHuge", surface(R"("anchor":{"position":[0,2e6,0],"normal":[0,0,1],"tangent":[1,0,0]})"),
     "/placements/0/anchor/position/1"},
    {"AnchorPositionString", surface(R"("anchor":{"position":[0,"1",0],"normal":[0,0,1],"tangent":[1,0,0]})"),
     "/placements/0/anchor/position/1"},
    {"AnchorNormalZero", surface(R"("anchor":{"position":[0,0,0],"normal":[0,0,0],"tangent":[1,0,0]})"),
     "/placements/0/anchor/normal"},
    {"AnchorTangentParallel", surface(R"("anchor":{"position":[0,0,0],"normal":[0,0,1],"tangent":[0,0,-3]})"),
     "/placements/0/anchor/tangent"},
    {"AnchorTangentTwoElements", surface(R"("anchor":{"position":[0,0,0],"normal":[0,0,1],"tangent":[1,0]})"),
     "/placements/0/anchor/tangent"},
    {"SurfaceSizeZero", surface(R"("size":[0, 0.1])"), "/placements/0/size/0"},
    {"SurfaceSizeHuge", surface(R"("size":[0.1, 1e5])"), "/placements/0/size/1"},
    {"SurfaceDepthNegative", surface(R"("depth":-1)"), "/placements/0/depth"},
    {"SurfaceDepthWord", surface(R"("depth":"deep")"), "/placements/0/depth"},
    {"SurfaceDepthHuge", surface(R"("depth":1e300)"), "/placements/0/depth"},
    {"SizeCheckedOnUvPlacements", placement(R"("size":[-1, 1])"), "/placements/0/size/0"},
};

INSTANTIATE_TEST_SUITE_P(Table, SceneBadInput, testing::ValuesIn(kBadCases),
                         [](const testing::TestParamInfo<BadCase>& info) {
                             return std::string(info.param.name);
                         });

// The table covers the document as the published schema describes it: every member of the scene,
// of a placement, of render and of the pose has at least one bad case that the parser refuses
// naming that member (a member added to the schema without one fails here).
TEST(SceneTest, BadCasesCoverEverySchemaMember) {
    std::ifstream in(std::string(dermis::build::sourceDir()) + "/server/http/schemas/scene.json");
    ASSERT_TRUE(in) << "server/http/schemas/scene.json";
    const nlohmann::json schema = nlohmann::json::parse(in);
    std::vector<std::string> prefixes;
    for (const auto& [key, _] : schema.at("properties").items()) prefixes.push_back("/" + key);
    for (const auto& [key, _] : schema.at("definitions").at("placement").at("properties").items())
        prefixes.push_back("/placements/0/" + key);
    for (const char* member : {"render", "pose", "heightmap"}) {
        const nlohmann::json members = schema.at("properties").at(member).value("properties", nlohmann::json::object());
        for (const auto& [key, _] : members.items()) prefixes.push_back(std::string("/") + member + "/" + key);
    }
    ASSERT_GT(prefixes.size(), 30u) << "the schema's members were not found";
    std::vector<std::string> uncovered;
    for (const std::string& prefix : prefixes) {
        const bool covered = std::any_of(std::begin(kBadCases), std::end(kBadCases), [&](const BadCase& c) {
            return c.pointer == prefix || c.pointer.rfind(prefix + "/", 0) == 0;
        });
        if (!covered) uncovered.push_back(prefix);
    }
    EXPECT_TRUE(uncovered.empty()) << "no bad case names " << testing::PrintToString(uncovered);
}

TEST(SceneTest, FirstErrorInDocumentOrderWins) {
    // Both the heightmap and the render settings are wrong: the earlier section is reported.
    auto r = parse(doc(R"("heightmap":{"size":[0,0]},"render":{"msaa":3})"));
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().field, "/heightmap/size/0");
}

TEST(SceneTest, NonFiniteValuesBuiltInCodeAreRejected) {
    // Documents built in code (not parsed from text) can hold NaN and inf.
    const PatternManifest m = testManifest();
    json j = json::parse(kSpecExample);
    j["render"]["bump_strength"] = std::numeric_limits<double>::quiet_NaN();
    auto a = dermis::parseScene(j, m);
    ASSERT_FALSE(a.ok());
    EXPECT_EQ(a.error().field, "/render/bump_strength");

    j = json::parse(kSpecExample);
    j["placements"][0]["center"][1] = std::numeric_limits<double>::infinity();
    auto b = dermis::parseScene(j, m);
    ASSERT_FALSE(b.ok());
    EXPECT_EQ(b.error().field, "/placements/0/center/1");

    j = json::parse(kSpecExample);
    j["heightmap"]["size"][0] = -std::numeric_limits<double>::infinity();
    auto c = dermis::parseScene(j, m);
    ASSERT_FALSE(c.ok());
    EXPECT_EQ(c.error().field, "/heightmap/size/0");

    // Invalid UTF-8 in a string would make serialisation throw: refuse it at the field.
    j = json::parse(kSpecExample);
    j["placements"][0]["joint"] = std::string("arm\xff");
    auto d = dermis::parseScene(j, m);
    ASSERT_FALSE(d.ok());
    EXPECT_EQ(d.error().field, "/placements/0/joint");
}

TEST(SceneTest, DeeplyNestedInputDoesNotCrash) {
    std::string deep(100000, '[');
    auto r = parse(doc(R"("future":)" + deep));
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::Parse);
    std::string closed = deep + std::string(100000, ']');
    auto s = parse(doc(R"("future":)" + closed)); // unknown field: ignored
    EXPECT_TRUE(s.ok());
}

TEST(SceneTest, JsonPointerEscape) {
    EXPECT_EQ(dermis::jsonPointerEscape("a/b~c"), "a~1b~0c");
    EXPECT_EQ(dermis::jsonPointerEscape("~/"), "~0~1");
    EXPECT_EQ(dermis::jsonPointerEscape("plain.name"), "plain.name");
}

