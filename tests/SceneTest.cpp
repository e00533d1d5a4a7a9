// Scene documents (`dermis.scene/1`, SPEC §2b): parsing, defaults and serialisation round trips;
// bad inputs, each checking the exact JSON pointer that the error names, are in
// SceneBadInputs.cpp (the same executable). Pure: no files, no GL. (The pattern manifest:
// PatternManifestTest.)
#include "core/key_light.hpp"
#include "core/scene.hpp"
#include "BuildPaths.hpp"
#include "SceneTestDocs.hpp"

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

using namespace scenetest;


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
