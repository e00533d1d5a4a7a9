// Scene documents for SceneTest (SceneTest.cpp, SceneBadInputs.cpp): a small pattern library,
// the SPEC §2b example and builders of documents around one member. Pure: no files, no GL.
#pragma once

#include "core/scene.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

namespace scenetest {


/// A small hand-built library: one pattern of each kind, with suggested axis and theta range.
inline dermis::PatternManifest testManifest() {
    dermis::PatternManifest m;
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
inline const char* const kSpecExample = R"({
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

inline dermis::Result<dermis::Scene> parse(const std::string& text) {
    return dermis::parseSceneText(text, testManifest());
}

inline dermis::Scene parseOk(const std::string& text) {
    auto r = parse(text);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message) << "\n" << text;
    return r.ok() ? *r : dermis::Scene{};
}

/// parse → serialise → parse → serialise must be byte-identical; returns the first dump.
inline std::string expectStableRoundTrip(const std::string& text) {
    const dermis::PatternManifest m = testManifest();
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
inline std::string doc(const std::string& body) {
    return std::string(R"({"format":"dermis.scene/1")") + (body.empty() ? "" : ",") + body + "}";
}

/// One placement with the required fields plus `extra`.
inline std::string placement(const std::string& extra) {
    return doc(R"("placements":[{"pattern":"crease","joint":"elbow")" +
               (extra.empty() ? std::string() : "," + extra) + "}]");
}

/// A surface placement (SPEC §8) with anchor and size, plus `extra` (members given twice: the
/// later one wins, as nlohmann reads objects).
inline std::string surface(const std::string& extra) {
    return placement(std::string(R"("projection":"surface",)") +
                     R"("anchor":{"position":[0.1,1.2,0.05],"normal":[0,0,1],"tangent":[1,0,0]},)" +
                     R"("size":[0.08,0.05])" + (extra.empty() ? std::string() : "," + extra));
}

/// A pose with one joint "spine" whose value is `value`.
inline std::string spine(const std::string& value) {
    return doc(R"("pose":{"joints":{"spine":)" + value + "}}");
}

} // namespace scenetest
