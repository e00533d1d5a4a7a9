// Scene documents (`dermis.scene/1`, SPEC §2b) that the parser refuses: one case per kind of bad
// input, each checking the exact JSON pointer that the error names, and a check that every member
// of the published schema has one. Part of SceneTest (SceneTest.cpp). Pure: no files but the
// schema, no GL.
#include "core/scene.hpp"
#include "BuildPaths.hpp"
#include "SceneTestDocs.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>


using dermis::ErrorCode;
using dermis::PatternManifest;
using dermis::Scene;
using nlohmann::json;

using namespace scenetest;

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
