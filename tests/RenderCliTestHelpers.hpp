// Helpers of the GL suites that render through `dermis-server render` as a child process
// (PbrShadingGLTest, SkinShadingGLTest): the backend option from $DERMIS_TEST_GL, one frame of a
// model with options, Radiance skies. Test code only.
#pragma once

#include "TestFiles.hpp"
#include "io/frame_io.hpp"

#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <string>

namespace dermis::test {

/// " --gl <backend>": $DERMIS_TEST_GL, else auto.
inline std::string gl() {
    const char* env = std::getenv("DERMIS_TEST_GL");
    return std::string(" --gl ") + (env && *env ? env : "auto");
}

/// The frame of `model` rendered with `options` at 128² (no anti-aliasing: exact pixels), the
/// scene's `render` member being `render`; expects success (an empty image otherwise).
inline Image8 render(const TempDir& dir, const std::string& model, const std::string& options,
                     const nlohmann::json& render = nlohmann::json::object()) {
    nlohmann::json scene = {{"format", "dermis.scene/1"}, {"model", model}, {"render", render}};
    writeText(dir / "s.json", scene.dump());
    CliRun r = runServer(dir, "render --scene " + (dir / "s.json") + " --out " + (dir / "f.png") +
                                  " --size 128x128 --aa none " + options + gl());
    EXPECT_EQ(r.code, 0) << options << ": " << r.err;
    auto img = decodeFrame(readBytes(dir / "f.png"));
    EXPECT_TRUE(img) << options;
    return img ? *img : Image8{};
}

/// A Radiance .hdr file: radiance `sky` above the horizon and `ground` below (radianceHdr).
inline void writeSkyHdr(const std::string& path, int w, int h, glm::vec3 sky, glm::vec3 ground) {
    const float top[3] = {sky.r, sky.g, sky.b}, bottom[3] = {ground.r, ground.g, ground.b};
    writeText(path, radianceHdr(w, h, top, bottom));
}

/// A Radiance .hdr file of one radiance `rgb`.
inline void writeUniformHdr(const std::string& path, int w, int h, glm::vec3 rgb) {
    writeSkyHdr(path, w, h, rgb, rgb);
}

} // namespace dermis::test
