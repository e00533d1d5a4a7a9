// RenderCliGLTest — the GPU commands of dermis-server end to end, on the backend named by
// $DERMIS_TEST_GL (ctest runs it for osmesa and egl-surfaceless): `info` prints JSON,
// `bake --gpu` writes maps equal to the CPU bake away from footprint edges, `bake --normals`
// writes a normal map, `render` writes PNG/JPEG/EXR frames, animation ranges and height maps,
// `--view` chooses what a frame shows, and bad scenes, models and options exit non-zero with a
// message.
#include "BuildPaths.hpp"
#include "TestFiles.hpp"
#include "io/frame_io.hpp"
#include "io/image_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <map>
#include <sys/wait.h>

using namespace dermis;
using namespace dermis::test;
using nlohmann::json;

namespace {

const std::string kSource = dermis::build::sourceDir();
const std::string kTestModels = dermis::build::testModelsDir();
const std::string kDefaultScene = kSource + "/models/default.scene.json";

std::string backend() {
    const char* env = std::getenv("DERMIS_TEST_GL");
    return env && *env ? env : "auto";
}


std::string gl() { return " --gl " + backend(); }

TEST(RenderCliGLTest, InfoPrintsTheBackendAsJson) {
    TempDir dir;
    CliRun r = runServer(dir, "info" + gl());
    ASSERT_EQ(r.code, 0) << r.err;
    json j = json::parse(r.out);
    if (backend() != "auto") EXPECT_EQ(j["backend"], backend());
    EXPECT_FALSE(j["gl_renderer"].get<std::string>().empty());
    EXPECT_FALSE(j["gl_vendor"].get<std::string>().empty());
    EXPECT_NE(j["gl_version"].get<std::string>().find("4."), std::string::npos);
    EXPECT_TRUE(j["tried"].is_array());
    const bool software = j["gl_renderer"].get<std::string>().find("llvmpipe") != std::string::npos;
    EXPECT_EQ(j["aa_auto"], software ? "post" : "msaa4");
}

TEST(RenderCliGLTest, AaChoosesTheAntiAliasingAndTimingsSaysWhereTheTimeWent) {
    TempDir dir;
    std::map<std::string, std::vector<std::uint8_t>> frames;
    for (const char* aa : {"post", "none", "msaa"}) {
        const std::string out = dir / (std::string(aa) + ".png");
        CliRun r = runServer(dir, "render --scene " + kDefaultScene + " --out " + out + " --size 128x128 --aa " + aa +
                                      " --timings" + gl());
        ASSERT_EQ(r.code, 0) << aa << ": " << r.err;
        frames[aa] = readBytes(out);
        const auto line = r.err.find("{\"timings\"");
        ASSERT_NE(line, std::string::npos) << r.err;
        const json t = json::parse(r.err.substr(line))["timings"];
        EXPECT_EQ(t["first_frame"]["aa"], std::string(aa) == "msaa" ? "msaa4" : aa) << t.dump();
        EXPECT_GT(t["context_ms"].get<double>(), 0.0) << t.dump();
        EXPECT_GT(t["first_frame"]["skin_ms"].get<double>(), 0.0) << t.dump();
        EXPECT_GE(t["total_ms"].get<double>(), t["first_frame"]["total_ms"].get<double>()) << t.dump();
        EXPECT_EQ(t["frames"], 1);
    }
    EXPECT_NE(frames["post"], frames["none"]);
    EXPECT_NE(frames["msaa"], frames["none"]);
    CliRun r = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / "x.png") + " --aa fxaa" + gl());
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("--aa"), std::string::npos) << r.err;
}

TEST(RenderCliGLTest, EglDeviceEitherStartsOrSaysWhy) {
    // CI has no GPU: the device platform then offers only Mesa's software device, which an
    // explicit request accepts. Whatever the machine, the answer is a backend or a clear error.
    TempDir dir;
    CliRun r = runServer(dir, "info --gl egl-device");
    if (r.code == 0) {
        EXPECT_EQ(json::parse(r.out)["backend"], "egl-device");
    } else {
        EXPECT_EQ(r.code, 1);
        EXPECT_NE(r.err.find("egl-device"), std::string::npos) << r.err;
    }
}

TEST(RenderCliGLTest, GpuBakeEqualsTheCpuBake) {
    TempDir dir;
    CliRun cpu = runServer(dir, "bake --scene " + kDefaultScene + " --out " + (dir / "cpu"));
    ASSERT_EQ(cpu.code, 0) << cpu.err;
    CliRun gpu = runServer(dir, "bake --gpu --normals --scene " + kDefaultScene + " --out " +
                                    (dir / "gpu") + gl());
    ASSERT_EQ(gpu.code, 0) << gpu.err;
    EXPECT_NE(gpu.out.find("GPU"), std::string::npos) << gpu.out;
    for (const char* name : {"bump.exr", "displacement.exr"}) {
        auto a = readHeightImage(dir / "cpu" + "/" + name);
        auto b = readHeightImage(dir / "gpu" + "/" + name);
        ASSERT_TRUE(a && b) << name;
        ASSERT_EQ(a->width, b->width);
        ASSERT_EQ(a->height, b->height);
        // Footprint edges may differ by a texel; everywhere else within 2e-3. Count the texels
        // that differ by more: only a thin outline of each footprint may.
        std::size_t over = 0, nonZero = 0;
        for (std::size_t i = 0; i < a->data.size(); ++i) {
            if (std::abs(a->data[i] - b->data[i]) > 2e-3f) ++over;
            if (a->data[i] != 0.0f) ++nonZero;
        }
        EXPECT_GT(nonZero, 10000u) << name;
        EXPECT_LT(over, nonZero / 50) << name << ": " << over << " of " << nonZero;
    }
    auto normal = decodeFrame(readBytes(dir / "gpu" + "/normal.png"));
    ASSERT_TRUE(normal) << normal.error().message;
    EXPECT_EQ(normal->width, 1024);
    // Flat areas are (0.5, 0.5, 1) → (128, 128, 255); deformed areas tilt.
    EXPECT_NEAR(normal->rgba[0], 128, 1);
    EXPECT_EQ(normal->rgba[2], 255);
    std::size_t tilted = 0;
    for (std::size_t p = 0; p < normal->rgba.size(); p += 4)
        if (std::abs(int(normal->rgba[p]) - 128) > 8) ++tilted;
    EXPECT_GT(tilted, 1000u);
}

TEST(RenderCliGLTest, RendersOneFrameInEachFormat) {
    TempDir dir;
    for (const char* name : {"frame.png", "frame.jpg", "frame.exr"}) {
        CliRun r = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / name) +
                                      " --size 160x120 --time 1.0" + gl());
        ASSERT_EQ(r.code, 0) << name << ": " << r.err;
        EXPECT_NE(r.out.find("rendered 1 frame of 160x120"), std::string::npos) << r.out;
    }
    auto png = decodeFrame(readBytes(dir / "frame.png"));
    ASSERT_TRUE(png) << png.error().message;
    EXPECT_EQ(png->width, 160);
    EXPECT_EQ(png->height, 120);
    auto jpg = decodeFrame(readBytes(dir / "frame.jpg"));
    ASSERT_TRUE(jpg) << jpg.error().message;
    EXPECT_EQ(jpg->width, 160);
    auto exr = readBytes(dir / "frame.exr");
    ASSERT_GT(exr.size(), 4u);
    EXPECT_EQ(exr[0], 0x76); // OpenEXR magic 76 2f 31 01
    EXPECT_EQ(exr[1], 0x2f);
}

TEST(RenderCliGLTest, ViewChoosesWhatTheFrameShows) {
    TempDir dir;
    std::map<std::string, std::vector<std::uint8_t>> frames;
    for (const char* view : {"shaded", "bump", "normal"}) {
        const std::string out = dir / (std::string(view) + ".png");
        CliRun r = runServer(dir, "render --scene " + kDefaultScene + " --out " + out +
                                      " --size 96x96 --view " + view + gl());
        ASSERT_EQ(r.code, 0) << view << ": " << r.err;
        frames[view] = readBytes(out);
        ASSERT_TRUE(decodeFrame(frames[view])) << view;
    }
    EXPECT_NE(frames["shaded"], frames["bump"]);
    EXPECT_NE(frames["bump"], frames["normal"]);
    CliRun r = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / "x.png") +
                                  " --view nope" + gl());
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("--view"), std::string::npos) << r.err;
}

TEST(RenderCliGLTest, RendersAnAnimationRangeWithHeightMaps) {
    TempDir dir;
    CliRun r = runServer(dir, "render --scene " + kDefaultScene + " --out " +
                                  (dir / "anim/frame_%04d.png") +
                                  " --frames 0.25:1.25:0.5 --size 96x96 --heightmaps" + gl());
    ASSERT_EQ(r.code, 0) << r.err;
    std::vector<std::vector<std::uint8_t>> frames;
    for (int k = 0; k < 3; ++k) {
        char name[64];
        std::snprintf(name, sizeof name, "anim/frame_%04d", k);
        auto bytes = readBytes(dir / (std::string(name) + ".png"));
        ASSERT_FALSE(bytes.empty()) << name;
        frames.push_back(bytes);
        auto bump = readHeightImage(dir / (std::string(name) + ".bump.exr"));
        auto disp = readHeightImage(dir / (std::string(name) + ".displacement.exr"));
        ASSERT_TRUE(bump && disp) << name;
        EXPECT_EQ(bump->width, 1024);
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "anim/frame_0003.png"));
    // Three poses of the squat (the clip holds it from 1 s: frames there differ by a wrinkle's
    // shade, which a 96² pbr frame need not show).
    EXPECT_NE(frames[0], frames[1]);
    EXPECT_NE(frames[1], frames[2]);
}

TEST(RenderCliGLTest, RangeFramesAreTheOneShotFrames) {
    // A range renders its frames one after another on one renderer and encodes them on a writer
    // thread while the next renders (render_cmd.cpp); each file must be byte-equal to the one-shot
    // render of its time: nothing of one frame leaks into the next, and the post-process edge
    // pass runs on each. 320² so that the edge pass splits the frame between threads as at full size.
    TempDir dir;
    CliRun r = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / "range/f_%04d.png") +
                                  " --frames 0.25:0.75:0.5 --size 320x320 --aa post" + gl());
    ASSERT_EQ(r.code, 0) << r.err;
    for (int k = 0; k < 2; ++k) {
        const std::string time = k == 0 ? "0.25" : "0.75";
        const std::string one = "one_" + std::to_string(k) + ".png";
        CliRun o = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / one) + " --time " +
                                      time + " --size 320x320 --aa post" + gl());
        ASSERT_EQ(o.code, 0) << o.err;
        char name[32];
        std::snprintf(name, sizeof name, "range/f_%04d.png", k);
        const auto ranged = readBytes(dir / name);
        ASSERT_FALSE(ranged.empty()) << name;
        EXPECT_TRUE(ranged == readBytes(dir / one)) << name << " differs from render --time " << time;
    }
    // And the edge pass ran: the same range without it gives other bytes.
    CliRun n = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / "none/f_%04d.png") +
                                  " --frames 0.25:0.75:0.5 --size 320x320 --aa none" + gl());
    ASSERT_EQ(n.code, 0) << n.err;
    EXPECT_FALSE(readBytes(dir / "none/f_0000.png") == readBytes(dir / "range/f_0000.png"));
}

TEST(RenderCliGLTest, RendersTheSharedModels) {
    TempDir dir;
    // The three test characters (skinned, posed half a second into their first clip) and the
    // Khronos material models of tests/models/fidelity (rigid meshes on plain nodes: a node
    // rotation, several materials and textures, alpha-textured cards; issue #26 shades them).
    for (const char* model : {"CesiumMan/CesiumMan.glb", "KayKitBarbarian/Barbarian.glb",
                              "RiggedFigure/RiggedFigure.glb", "fidelity/DamagedHelmet/DamagedHelmet.glb",
                              "fidelity/NormalTangentMirrorTest/NormalTangentMirrorTest.glb",
                              "fidelity/AlphaBlendModeTest/AlphaBlendModeTest.glb"}) {
        json scene = {{"format", "dermis.scene/1"}, {"model", kTestModels + "/" + model}};
        if (std::string(model).find("fidelity/") != 0) scene["pose"] = {{"time", 0.5}};
        writeText(dir / "s.json", scene.dump());
        CliRun r = runServer(dir, "render --scene " + (dir / "s.json") + " --out " +
                                      (dir / "m.png") + " --size 128x128" + gl());
        ASSERT_EQ(r.code, 0) << model << ": " << r.err;
        auto img = decodeFrame(readBytes(dir / "m.png"));
        ASSERT_TRUE(img) << model;
        std::size_t fg = 0;
        for (std::size_t p = 0; p < img->rgba.size(); p += 4)
            if (std::abs(int(img->rgba[p]) - int(img->rgba[0])) > 8) ++fg;
        EXPECT_GT(fg, 128u * 128u / 50) << model << " is missing from its frame";
    }
}

TEST(RenderCliGLTest, BadInputExitsNonZeroWithAMessage) {
    TempDir dir;
    writeText(dir / "bad.json", R"({"format":"dermis.scene/1","placements":[{"pattern":"crease",
        "joint":"upperarm_l","theta_min":10,"theta_max":10}]})");
    CliRun r = runServer(dir, "render --scene " + (dir / "bad.json") + " --out " + (dir / "x.png") + gl());
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("/placements/0/theta_max"), std::string::npos) << r.err;

    writeText(dir / "broken.glb", "glTF but not really");
    writeText(dir / "m.json", R"({"format":"dermis.scene/1","model":"broken.glb"})");
    r = runServer(dir, "render --scene " + (dir / "m.json") + " --out " + (dir / "x.png") + gl());
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("error"), std::string::npos) << r.err;

    r = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / "x.bmp") + gl());
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;

    r = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / "x.png") +
                           " --size 0x100" + gl());
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;

    r = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / "x.png") +
                           " --frames 2:1:0.5" + gl());
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("--frames"), std::string::npos) << r.err;

    r = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / "same.png") +
                           " --frames 0:1:0.5" + gl());
    EXPECT_EQ(r.code, 1) << "a range needs a %04d field";

    r = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / "x.png") +
                           " --gl vulkan");
    EXPECT_EQ(r.code, 2);
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
}

} // namespace
