// ColdStartCliGLTest — what the cold-start work (issue #13) must not change, end to end on the
// backend named by $DERMIS_TEST_GL: a pipelined `render --frames` writes exactly the bytes of
// single-frame renders at the same times; PNG and JPEG work without the OpenImageIO module
// (patterns, textures and frames go through libpng / libjpeg-turbo); EXR without the module is a
// clear error naming it; `--help` needs neither GL nor the module.
#include "BuildPaths.hpp"
#include "TestFiles.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sys/wait.h>

using namespace dermis::test;

namespace {

const std::string kSource = dermis::build::sourceDir();
const std::string kDefaultScene = kSource + "/models/default.scene.json";
const std::string kCesium = kSource + "/examples/cesiumman.scene.json";

std::string readText(const std::string& path) {
    const auto b = readBytes(path);
    return std::string(b.begin(), b.end());
}

std::string gl() {
    const char* env = std::getenv("DERMIS_TEST_GL");
    return std::string(" --gl ") + (env && *env ? env : "auto");
}

} // namespace

TEST(ColdStartCliGLTest, PipelinedFramesEqualSingleFrameRendersByteForByte) {
    TempDir dir;
    CliRun r = runServer(dir, "render --scene " + kDefaultScene + " --out " + (dir / "f_%04d.png") +
                                  " --frames 0:0.3:0.1 --size 256x192" + gl());
    ASSERT_EQ(r.code, 0) << r.err;
    for (int k = 0; k < 4; ++k) {
        const std::string one = dir / ("one_" + std::to_string(k) + ".png");
        CliRun s = runServer(dir, "render --scene " + kDefaultScene + " --out " + one + " --time " +
                                      std::to_string(0.1 * k) + " --size 256x192" + gl());
        ASSERT_EQ(s.code, 0) << s.err;
        char name[32];
        std::snprintf(name, sizeof name, "f_%04d.png", k);
        const auto framed = readBytes(dir / name);
        ASSERT_FALSE(framed.empty()) << name;
        EXPECT_EQ(framed, readBytes(one)) << "frame " << k;
    }
}

TEST(ColdStartCliGLTest, PngAndJpegNeedNoImageModule) {
    TempDir dir;
    // CesiumMan: a glTF with a texture, PNG patterns; frames as PNG and JPEG.
    const std::string env = "DERMIS_OIIO_MODULE=/nonexistent/libdermis_oiio.so ";
    for (const char* out : {"c.png", "c.jpg"}) {
        const std::string cmd = env + dermis::build::serverExe() + " render --scene " + kCesium +
                                " --out " + (dir / out) + " --size 128x128" + gl() +
                                " >/dev/null 2>" + (dir / "err.txt");
        EXPECT_EQ(std::system(cmd.c_str()), 0) << out << ": " << readText(dir / "err.txt");
        EXPECT_GT(readBytes(dir / out).size(), 100u) << out;
    }
}

TEST(ColdStartCliGLTest, ExrWithoutTheModuleIsAClearError) {
    TempDir dir;
    const std::string cmd = std::string("DERMIS_OIIO_MODULE=/nonexistent/libdermis_oiio.so ") +
                            dermis::build::serverExe() + " render --scene " + kDefaultScene +
                            " --out " + (dir / "f.exr") + " --size 64x64" + gl() +
                            " >/dev/null 2>" + (dir / "err.txt");
    const int status = std::system(cmd.c_str());
    EXPECT_EQ(WEXITSTATUS(status), 1);
    const std::string err = readText(dir / "err.txt");
    EXPECT_NE(err.find("libdermis_oiio.so"), std::string::npos) << err;
    EXPECT_NE(err.find("/nonexistent/libdermis_oiio.so"), std::string::npos) << err;
    EXPECT_FALSE(std::filesystem::exists(dir / "f.exr"));
}

TEST(ColdStartCliGLTest, HelpNeedsNeitherGlNorTheModule) {
    TempDir dir;
    const std::string cmd = std::string("DERMIS_OIIO_MODULE=/nonexistent ") +
                            dermis::build::serverExe() + " --help >" + (dir / "out.txt") + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_NE(readText(dir / "out.txt").find("render"), std::string::npos);
}
