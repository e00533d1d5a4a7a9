// Helpers of the GL suites that render through `dermis-server render` as a child process
// (PbrShadingGLTest, SkinShadingGLTest, KeyLightGLTest): the backend option from $DERMIS_TEST_GL,
// one frame of a model with options, Radiance skies, a white sphere (over a floor), the mean of a
// channel over the foreground. Test code only.
#pragma once

#include "GltfTestBuilder.hpp"
#include "TestFiles.hpp"
#include "io/frame_io.hpp"

#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

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

/// A white rough dielectric sphere of radius 1 at the origin (a latitude-longitude grid, normals =
/// positions) as `dir`/sphere.glb; with `floor`, also a 6 × 6 floor square at y = −1.5 facing up
/// (its own part, the same material), so that the sphere can cast a shadow on it. Returns the path.
inline std::string whiteSphereGlb(const TempDir& dir, bool floor = false) {
    namespace g = dermis::test::gltf;
    using nlohmann::json;
    constexpr int kLon = 48, kLat = 24;
    std::vector<float> pos, uv;
    std::vector<std::uint16_t> idx;
    for (int j = 0; j <= kLat; ++j)
        for (int i = 0; i <= kLon; ++i) {
            const double th = M_PI * j / kLat, ph = 2.0 * M_PI * i / kLon;
            pos.insert(pos.end(), {float(std::sin(th) * std::cos(ph)), float(std::cos(th)),
                                   float(std::sin(th) * std::sin(ph))});
            uv.insert(uv.end(), {float(i) / kLon, float(j) / kLat});
        }
    for (int j = 0; j < kLat; ++j)
        for (int i = 0; i < kLon; ++i) {
            const auto a = std::uint16_t(j * (kLon + 1) + i), b = std::uint16_t(a + kLon + 1);
            idx.insert(idx.end(), {a, std::uint16_t(a + 1), b, std::uint16_t(a + 1), std::uint16_t(b + 1), b});
        }
    g::Builder b;
    const int p = b.add(pos, g::kFloat, "VEC3"), n = b.add(pos, g::kFloat, "VEC3");
    const int t = b.add(uv, g::kFloat, "VEC2"), i = b.add(idx, g::kUShort, "SCALAR");
    json pbr = {{"baseColorFactor", {0.9, 0.9, 0.9, 1.0}}, {"metallicFactor", 0}, {"roughnessFactor", 0.6}};
    b.doc["materials"] = json::array({{{"pbrMetallicRoughness", pbr}}});
    json prims = json::array({{{"attributes", {{"POSITION", p}, {"NORMAL", n}, {"TEXCOORD_0", t}}}, {"indices", i}, {"material", 0}}});
    if (floor) {
        const std::vector<float> fp = {-3, -1.5f, -3, 3, -1.5f, -3, 3, -1.5f, 3, -3, -1.5f, 3};
        const std::vector<float> fn = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
        const std::vector<float> ft = {0, 0, 1, 0, 1, 1, 0, 1};
        const std::vector<std::uint16_t> fi = {0, 2, 1, 0, 3, 2};
        const int a = b.add(fp, g::kFloat, "VEC3"), an = b.add(fn, g::kFloat, "VEC3");
        const int at = b.add(ft, g::kFloat, "VEC2"), ai = b.add(fi, g::kUShort, "SCALAR");
        prims.push_back({{"attributes", {{"POSITION", a}, {"NORMAL", an}, {"TEXCOORD_0", at}}}, {"indices", ai}, {"material", 0}});
    }
    b.doc["meshes"] = json::array({{{"primitives", prims}}});
    b.doc["nodes"] = json::array({{{"mesh", 0}}});
    b.doc["scenes"] = json::array({{{"nodes", {0}}}});
    b.doc["scene"] = 0;
    const std::vector<std::uint8_t> glb = b.glb();
    writeText(dir / "sphere.glb", std::string(glb.begin(), glb.end()));
    return dir / "sphere.glb";
}

/// Mean of channel `c` over the pixels of rows [y0, y1) and columns [x0, x1) (all when x1 ≤ 0)
/// that differ from the background (pixel 0).
inline double meanChannel(const Image8& img, int c, int y0, int y1, int x0 = 0, int x1 = -1) {
    double sum = 0.0;
    std::size_t n = 0;
    if (x1 <= 0) x1 = img.width;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const std::size_t p = (std::size_t(y) * img.width + x) * 4;
            bool fg = false;
            for (int k = 0; k < 3; ++k)
                fg = fg || std::abs(int(img.rgba[p + k]) - int(img.rgba[k])) > 8;
            if (!fg) continue;
            sum += img.rgba[p + c];
            ++n;
        }
    return n ? sum / n : 0.0;
}

} // namespace dermis::test
