// The pattern manifest (`dermis.patterns/1`, patterns/manifest.json): parsing with the kind's
// defaults, serialisation round trips, and one test per kind of bad input, each checking the exact
// JSON pointer that the error names. Pure: no files, no GL. (Scene documents: SceneTest.)
#include "core/scene.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

using dermis::PatternManifest;
using nlohmann::json;

namespace {

const char* kManifestText = R"({
  "format": "dermis.patterns/1",
  "patterns": [
    {"id": "crease", "file": "crease.png", "kind": "wrinkle", "joint": "elbow", "axis": "x",
     "theta_min": 0, "theta_max": 120, "description": "inner-elbow crease"},
    {"id": "biceps", "file": "bulges/biceps.png", "kind": "bulge", "joint": "elbow",
     "axis": "z", "theta_min": 10, "theta_max": 100, "description": "round bulge"},
    {"id": "clavicle", "file": "clavicle.png", "kind": "bone", "joint": "shoulder",
     "axis": "y", "theta_min": -30, "theta_max": 60, "description": "clavicle ridge"},
    {"id": "waist_twist", "file": "waist.png", "kind": "wrinkle", "model": "bias",
     "target": "displacement", "joint": "spine", "axis": "y", "theta_min": 45, "theta_max": -45,
     "description": ""}
  ]
})";

/// `{"format":"dermis.scene/1", <body>}`.
std::string doc(const std::string& body) {
    return std::string(R"({"format":"dermis.scene/1")") + (body.empty() ? "" : ",") + body + "}";
}

dermis::Result<PatternManifest> parseManifest(const std::string& text) {
    return dermis::parsePatternManifest(json::parse(text));
}

/// The manifest with the first entry's member `key` replaced by `value` (JSON text).
std::string manifestWith(const std::string& key, const std::string& value) {
    json j = json::parse(kManifestText);
    j["patterns"][0][key] = json::parse(value);
    return j.dump();
}

} // namespace

TEST(PatternManifestTest, ParsesWithKindDefaults) {
    auto m = parseManifest(kManifestText);
    ASSERT_TRUE(m.ok()) << m.error().message;
    ASSERT_EQ(m->patterns.size(), 4u);
    const dermis::PatternInfo* crease = m->find("crease");
    ASSERT_NE(crease, nullptr);
    EXPECT_EQ(crease->file, "crease.png");
    EXPECT_EQ(crease->kind, dermis::PatternKind::Wrinkle);
    EXPECT_EQ(crease->model, dermis::DeformModel::Scale);
    EXPECT_EQ(crease->target, dermis::Target::Bump);
    EXPECT_EQ(crease->joint, "elbow");
    EXPECT_EQ(crease->thetaMax, 120.0);
    EXPECT_EQ(crease->description, "inner-elbow crease");

    const dermis::PatternInfo* biceps = m->find("biceps");
    ASSERT_NE(biceps, nullptr);
    EXPECT_EQ(biceps->model, dermis::DeformModel::Scale);
    EXPECT_EQ(biceps->target, dermis::Target::Displacement);
    EXPECT_EQ(biceps->file, "bulges/biceps.png");

    const dermis::PatternInfo* bone = m->find("clavicle");
    ASSERT_NE(bone, nullptr);
    EXPECT_EQ(bone->model, dermis::DeformModel::Bias);
    EXPECT_EQ(bone->target, dermis::Target::Bump);
    EXPECT_EQ(bone->axis, "y");

    const dermis::PatternInfo* twist = m->find("waist_twist");
    ASSERT_NE(twist, nullptr);
    EXPECT_EQ(twist->model, dermis::DeformModel::Bias); // explicit beats the kind
    EXPECT_EQ(twist->target, dermis::Target::Displacement);

    EXPECT_EQ(m->find("nope"), nullptr);
}

TEST(PatternManifestTest, MinimalEntryGetsDefaults) {
    auto m = parseManifest(
        R"({"format":"dermis.patterns/1","patterns":[{"id":"a","file":"a.png","kind":"bone"}]})");
    ASSERT_TRUE(m.ok()) << m.error().message;
    const auto& p = m->patterns[0];
    EXPECT_EQ(p.model, dermis::DeformModel::Bias);
    EXPECT_EQ(p.target, dermis::Target::Bump);
    EXPECT_EQ(p.axis, "x");
    EXPECT_EQ(p.thetaMin, 0.0);
    EXPECT_EQ(p.thetaMax, 90.0);
    EXPECT_EQ(p.joint, "");
}

TEST(PatternManifestTest, RoundTripIsStable) {
    auto m = parseManifest(kManifestText);
    ASSERT_TRUE(m.ok());
    const std::string first = dermis::toJson(*m).dump();
    auto again = dermis::parsePatternManifest(json::parse(first));
    ASSERT_TRUE(again.ok()) << again.error().message;
    EXPECT_EQ(first, dermis::toJson(*again).dump());
}

TEST(PatternManifestTest, ScenesUseTheParsedManifest) {
    auto m = parseManifest(kManifestText);
    ASSERT_TRUE(m.ok());
    auto s =
        dermis::parseSceneText(doc(R"("placements":[{"pattern":"waist_twist","joint":"j"}])"), *m);
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_EQ(s->placements[0].model, dermis::DeformModel::Bias);
    EXPECT_EQ(s->placements[0].target, dermis::Target::Displacement);
    EXPECT_EQ(s->placements[0].thetaMin, 45.0);
    EXPECT_EQ(s->placements[0].thetaMax, -45.0);
    // With an empty manifest there are no built-in ids.
    auto none = dermis::parseSceneText(doc(R"("placements":[{"pattern":"crease","joint":"j"}])"),
                                       PatternManifest{});
    ASSERT_FALSE(none.ok());
    EXPECT_EQ(none.error().field, "/placements/0/pattern");
}

struct BadManifest {
    const char* name;
    std::string text;
    std::string pointer;
};

class PatternManifestBadInput : public testing::TestWithParam<BadManifest> {};

TEST_P(PatternManifestBadInput, NamesTheField) {
    const BadManifest& c = GetParam();
    auto r = parseManifest(c.text);
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_EQ(r.error().field, c.pointer) << r.error().message;
}

const BadManifest kBadManifests[] = {
    {"RootArray", "[]", ""},
    {"FormatMissing", R"({"patterns":[]})", "/format"},
    {"FormatWrong", R"({"format":"dermis.scene/1","patterns":[]})", "/format"},
    {"PatternsMissing", R"({"format":"dermis.patterns/1"})", "/patterns"},
    {"PatternsObject", R"({"format":"dermis.patterns/1","patterns":{}})", "/patterns"},
    {"EntryNotObject", R"({"format":"dermis.patterns/1","patterns":["crease"]})", "/patterns/0"},
    {"DuplicateId",
     [] {
         json j = json::parse(kManifestText);
         j["patterns"][2]["id"] = "crease";
         return j.dump();
     }(),
     "/patterns/2/id"},
    {"IdUpperCase", manifestWith("id", R"("Crease")"), "/patterns/0/id"},
    {"IdDash", manifestWith("id", R"("in-elbow")"), "/patterns/0/id"},
    {"IdMissing",
     [] {
         json j = json::parse(kManifestText);
         j["patterns"][0].erase("id");
         return j.dump();
     }(),
     "/patterns/0/id"},
    {"KindUnknown", manifestWith("kind", R"("scar")"), "/patterns/0/kind"},
    {"KindMissing",
     [] {
         json j = json::parse(kManifestText);
         j["patterns"][1].erase("kind");
         return j.dump();
     }(),
     "/patterns/1/kind"},
    {"ModelUnknown", manifestWith("model", R"("offset")"), "/patterns/0/model"},
    {"TargetUnknown", manifestWith("target", R"("normal")"), "/patterns/0/target"},
    {"AxisVector", manifestWith("axis", "[1,0,0]"), "/patterns/0/axis"},
    {"ThetaEqual", manifestWith("theta_max", "0"), "/patterns/0/theta_max"},
    {"ThetaString", manifestWith("theta_min", R"("0")"), "/patterns/0/theta_min"},
    {"FileMissing",
     [] {
         json j = json::parse(kManifestText);
         j["patterns"][0].erase("file");
         return j.dump();
     }(),
     "/patterns/0/file"},
    {"FileEmpty", manifestWith("file", R"("")"), "/patterns/0/file"},
    {"FileParent", manifestWith("file", R"("../secret.png")"), "/patterns/0/file"},
    {"FileInnerParent", manifestWith("file", R"("a/../../b.png")"), "/patterns/0/file"},
    {"FileAbsolute", manifestWith("file", R"("/etc/passwd")"), "/patterns/0/file"},
    {"FileBackslash", manifestWith("file", R"("..\\x.png")"), "/patterns/0/file"},
    {"FileDrive", manifestWith("file", R"("C:x.png")"), "/patterns/0/file"},
    {"FileDoubleSlash", manifestWith("file", R"("a//b.png")"), "/patterns/0/file"},
    {"FileDot", manifestWith("file", R"("./a.png")"), "/patterns/0/file"},
    {"FileNumber", manifestWith("file", "3"), "/patterns/0/file"},
    {"DescriptionNumber", manifestWith("description", "3"), "/patterns/0/description"},
};

INSTANTIATE_TEST_SUITE_P(Table, PatternManifestBadInput, testing::ValuesIn(kBadManifests),
                         [](const testing::TestParamInfo<BadManifest>& info) {
                             return std::string(info.param.name);
                         });
