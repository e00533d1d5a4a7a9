// BakeCliTest — `dermis-server bake` end to end on a character from tests/models: the EXR
// maps equal the in-process CPU reference, are non-zero exactly inside the footprints, and bad
// scenes exit non-zero with the offending field on stderr. Needs the built dermis-server.
#include "BuildPaths.hpp"
#include "TestFiles.hpp"
#include "core/bake.hpp"
#include "io/image_io.hpp"
#include "io/scene_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <sys/wait.h>

using namespace dermis;
using namespace dermis::test;
using nlohmann::json;

namespace {

const std::string kCesium =
    std::string(dermis::build::testModelsDir()) + "/CesiumMan/CesiumMan.glb";
const std::string kRigged =
    std::string(dermis::build::testModelsDir()) + "/RiggedFigure/RiggedFigure.glb";
const char* kJoint = "Skeleton_torso_joint_2";


/// A 32×32 dome pattern: positive inside a disc, 0 at the border.
void writeDome(const std::string& path) {
    std::vector<std::uint16_t> px(32 * 32);
    for (int j = 0; j < 32; ++j)
        for (int i = 0; i < 32; ++i) {
            const double x = (i + 0.5) / 16 - 1, y = (j + 0.5) / 16 - 1;
            const double r2 = x * x + y * y;
            px[j * 32 + i] = static_cast<std::uint16_t>(32768 + (r2 < 1 ? 30000 * (1 - r2) : 0));
        }
    writeImage(path, 32, 32, 1, px, OIIO::TypeDesc::UINT16);
}

json baseScene(const std::string& model) {
    return json{
        {"format", "dermis.scene/1"},
        {"model", model},
        {"heightmap", {{"size", {64, 48}}}},
        {"patterns", {{"dome", "dome.png"}}},
        {"placements",
         {{{"id", "a"}, {"pattern", "dome"}, {"center", {0.25, 0.25}}, {"scale", {0.25, 0.25}},
           {"rotation", 30}, {"joint", kJoint}, {"axis", "x"}, {"theta_min", 0},
           {"theta_max", 90}, {"model", "scale"}, {"target", "bump"}},
          {{"id", "b"}, {"pattern", "dome"}, {"center", {0.75, 0.6}}, {"scale", {0.2, 0.3}},
           {"joint", kJoint}, {"axis", "x"}, {"theta_min", 0}, {"theta_max", 30},
           {"target", "displacement"}}}},
        {"pose", {{"joints", {{kJoint, {{"axis_angles", {{"x", 45}}}}}}}}}};
}

} // namespace

class BakeCliTest : public ::testing::Test {
protected:
    void SetUp() override {
        ASSERT_TRUE(std::filesystem::exists(kCesium))
            << "shared models missing: " << kCesium << " (CI has shared/ beside the clone)";
        writeDome(dir / "dome.png");
    }
    void writeScene(const json& doc) { writeText(dir / "scene.json", doc.dump(2)); }
    TempDir dir;
};

TEST_F(BakeCliTest, WritesTheCpuReferenceMapsAsExr) {
    writeScene(baseScene(kCesium));
    const CliRun r = runServer(dir, "bake --scene " + (dir / "scene.json") + " --out " + (dir / "maps"));
    ASSERT_EQ(r.code, 0) << r.err;
    auto bump = readHeightImage(dir / "maps/bump.exr");
    auto disp = readHeightImage(dir / "maps/displacement.exr");
    ASSERT_TRUE(bump.ok()) << bump.error().message;
    ASSERT_TRUE(disp.ok()) << disp.error().message;
    EXPECT_EQ(bump->width, 64);
    EXPECT_EQ(bump->height, 48);

    auto loaded = loadSceneFile(dir / "scene.json");
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    auto ref = bakeScene(loaded->scene, loaded->model, loaded->images);
    ASSERT_TRUE(ref.ok()) << ref.error().message;
    EXPECT_EQ(bump->data, ref->bump.data);
    EXPECT_EQ(disp->data, ref->displacement.data);

    // The dome at t = 0.5 (45° of 0..90): peak ≈ 30000/32767 · log2(1.5); full dome on b (t = 1).
    float bumpMax = 0, dispMax = 0;
    for (float v : bump->data) bumpMax = std::max(bumpMax, v);
    for (float v : disp->data) dispMax = std::max(dispMax, v);
    EXPECT_NEAR(bumpMax, 30000.0 / 32767 * std::log2(1.5), 0.05);
    EXPECT_NEAR(dispMax, 30000.0 / 32767, 0.05);

    // Non-zero only inside the footprints.
    for (int j = 0; j < 48; ++j)
        for (int i = 0; i < 64; ++i) {
            const glm::dvec2 uv((i + 0.5) / 64, (j + 0.5) / 48);
            Footprint fa{{0.25, 0.25}, {0.25, 0.25}, 30}, fb{{0.75, 0.6}, {0.2, 0.3}, 0};
            auto inside = [&](const Footprint& f) {
                const glm::dvec2 s = f.toPattern(uv);
                return s.x >= 0 && s.x <= 1 && s.y >= 0 && s.y <= 1;
            };
            if (!inside(fa)) EXPECT_EQ(bump->at(i, j), 0.0f) << i << "," << j;
            if (!inside(fb)) EXPECT_EQ(disp->at(i, j), 0.0f) << i << "," << j;
        }
    EXPECT_GT(bump->at(16, 12), 0.0f); // centre of a
}

TEST_F(BakeCliTest, TimeOptionAndRestPose) {
    json doc = baseScene(kCesium);
    doc["pose"] = json::object(); // animated pose, joint not overridden
    writeScene(doc);
    const CliRun r =
        runServer(dir, "bake --scene " + (dir / "scene.json") + " --out " + (dir / "t") + " --time 0.5");
    ASSERT_EQ(r.code, 0) << r.err;
    auto loaded = loadSceneFile(dir / "scene.json");
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    SceneBakeOptions opt;
    opt.time = 0.5;
    auto ref = bakeScene(loaded->scene, loaded->model, loaded->images, opt);
    ASSERT_TRUE(ref.ok());
    auto bump = readHeightImage(dir / "t/bump.exr");
    ASSERT_TRUE(bump.ok());
    EXPECT_EQ(bump->data, ref->bump.data);
}

TEST_F(BakeCliTest, BadScenesExitNonZeroNamingTheField) {
    struct Case {
        std::string name;
        json doc;
        std::string expect;
    };
    std::vector<Case> cases;
    json d = baseScene(kCesium);
    d["placements"][0]["theta_max"] = 0;
    cases.push_back({"theta", d, "/placements/0/theta_max"});
    d = baseScene(kCesium);
    d["placements"][1]["joint"] = "no_such_joint";
    cases.push_back({"joint", d, "/placements/1/joint"});
    d = baseScene(kCesium);
    d["patterns"]["dome"] = "missing.png";
    cases.push_back({"pattern file", d, "/placements/0/pattern"});
    d = baseScene(kRigged);
    d["pose"] = json::object();
    d["placements"][0]["joint"] = "torso_joint_2";
    d["placements"][1]["joint"] = "torso_joint_2";
    d["uv_layout"] = "model"; // auto would generate a layout (NoUvsBakeInTheGeneratedLayout)
    cases.push_back({"no uvs", d, "TEXCOORD_0"});
    d = baseScene(dir / "nope.glb");
    cases.push_back({"model", d, "/model"});
    for (const Case& c : cases) {
        writeScene(c.doc);
        const CliRun r = runServer(dir, "bake --scene " + (dir / "scene.json") + " --out " + (dir / "x"));
        EXPECT_EQ(r.code, 1) << c.name;
        EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.name << ": " << r.err;
        EXPECT_NE(r.err.find("error"), std::string::npos) << c.name;
    }
    writeText(dir / "scene.json", "{ \"format\": \"dermis.scene/1\", ");
    CliRun r = runServer(dir, "bake --scene " + (dir / "scene.json") + " --out " + (dir / "x"));
    EXPECT_EQ(r.code, 1);
    r = runServer(dir, "bake --out " + (dir / "x"));
    EXPECT_EQ(r.code, 2);
    r = runServer(dir, "bake --scene " + (dir / "absent.json") + " --out " + (dir / "x"));
    EXPECT_EQ(r.code, 2);
    EXPECT_FALSE(r.err.empty());
}

// SPEC §8: a model without UVs bakes in the generated layout under uv_layout "auto" (the default),
// exactly as the server renders it; the maps carry the placements.
TEST_F(BakeCliTest, NoUvsBakeInTheGeneratedLayout) {
    json d = baseScene(kRigged);
    d["placements"][0]["joint"] = "torso_joint_2";
    d["placements"][1]["joint"] = "torso_joint_2";
    d["pose"] = {{"joints", {{"torso_joint_2", {{"axis_angles", {{"x", 45}}}}}}}};
    writeScene(d);
    const CliRun r = runServer(dir, "bake --scene " + (dir / "scene.json") + " --out " + (dir / "g"));
    ASSERT_EQ(r.code, 0) << r.err;
    auto bump = readHeightImage(dir / "g/bump.exr");
    ASSERT_TRUE(bump.ok()) << bump.error().message;
    float peak = 0.0f;
    for (float v : bump->data) peak = std::max(peak, v);
    EXPECT_GT(peak, 0.0f) << "the placements left no mark in the generated layout";
}
