// UvLayoutTest — pictures for people and model queries in the core: UV edges and their raster,
// height previews, downsized textures, the joint-parent walk, the dominant base-colour image.
// Pure.
#include "core/model.hpp"
#include "core/preview.hpp"
#include "core/uv_layout.hpp"

#include <gtest/gtest.h>

#include <cstdint>

using namespace dermis;

namespace {

Model quad() {
    Model m;
    MeshPart p;
    p.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    p.uvs = {{0.1f, 0.1f}, {0.9f, 0.1f}, {0.9f, 0.9f}, {0.1f, 0.9f}};
    p.indices = {0, 1, 2, 0, 2, 3};
    m.parts.push_back(p);
    return m;
}

TEST(UvLayoutTest, SharedEdgesAppearOnce) {
    const auto edges = uvEdges(quad());
    EXPECT_EQ(edges.size(), 5u); // 4 sides + the diagonal
    Model noUv = quad();
    noUv.parts[0].uvs.clear();
    EXPECT_TRUE(uvEdges(noUv).empty());
}

TEST(UvLayoutTest, RasterDrawsEdgesAndClipsTheRest) {
    auto edges = uvEdges(quad());
    edges.push_back({{-5.0f, -5.0f}, {-4.0f, 9.0f}}); // far outside: nothing drawn, no long loop
    const Image8 img = rasterizeUvEdges(edges, 100);
    ASSERT_EQ(img.rgba.size(), 100u * 100u * 4u);
    auto alpha = [&](int x, int y) { return img.rgba[(static_cast<std::size_t>(y) * 100 + x) * 4 + 3]; };
    EXPECT_EQ(alpha(50, 10), 255); // top side (v = 0.1)
    EXPECT_EQ(alpha(10, 50), 255); // left side
    EXPECT_EQ(alpha(50, 50), 255); // diagonal
    EXPECT_EQ(alpha(70, 30), 0);   // inside a triangle
    EXPECT_EQ(alpha(2, 2), 0);     // outside the chart
}

TEST(PreviewTest, HeightsMapToGreyWithTheAspectKept) {
    HeightImage h(4, 2);
    for (int i = 0; i < 4; ++i) {
        h.at(i, 0) = -1.0f;
        h.at(i, 1) = 1.0f;
    }
    const Image8 img = heightPreview(h, 8);
    EXPECT_EQ(img.width, 8);
    EXPECT_EQ(img.height, 4);
    EXPECT_EQ(img.rgba[0], 0);                        // L = −1: black
    EXPECT_EQ(img.rgba[(3 * 8 + 0) * 4], 255);        // L = +1: white
    EXPECT_EQ(img.rgba[3], 255);                      // opaque
    const Image8 flat = heightPreview(HeightImage(3, 3, 0.0f), 1);
    EXPECT_EQ(flat.rgba[0], 128);                     // L = 0: mid grey
    // Tall sources fit their height (issue #12.6), never more than maxSide² pixels.
    const Image8 tall = heightPreview(HeightImage(1, 4096, 0.0f), 256);
    EXPECT_EQ(tall.width, 1);
    EXPECT_EQ(tall.height, 256);
    const Image8 tall5 = heightPreview(HeightImage(2, 8, 0.0f), 5);
    EXPECT_EQ(tall5.width, 1);
    EXPECT_EQ(tall5.height, 5);
}

TEST(PreviewTest, DownsizeAveragesBoxesAndKeepsTheAspect) {
    Image8 src;
    src.width = 8;
    src.height = 4;
    src.rgba.resize(8 * 4 * 4);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x) {
            std::uint8_t* px = &src.rgba[(y * 8 + x) * 4];
            px[0] = x < 4 ? 0 : 200;        // left half black, right half 200
            px[1] = (x + y) % 2 ? 255 : 0;  // checkerboard: averages to mid
            px[2] = static_cast<std::uint8_t>(10 * y);
            px[3] = 255;
        }
    const Image8 half = downsizeImage(src, 4);
    ASSERT_EQ(half.width, 4);
    ASSERT_EQ(half.height, 2);
    ASSERT_EQ(half.rgba.size(), 4u * 2 * 4);
    EXPECT_EQ(half.rgba[0], 0);              // (0, 0): black half
    EXPECT_EQ(half.rgba[3 * 4], 200);        // (3, 0): the 200 half
    EXPECT_EQ(half.rgba[1], 128);            // 2×2 of the checkerboard: (0+255+255+0)/4 rounded
    EXPECT_EQ(half.rgba[2], 5);              // rows 0 and 1: (0+10)/2
    EXPECT_EQ(half.rgba[(4 + 0) * 4 + 2], 25); // rows 2 and 3
    EXPECT_EQ(half.rgba[3], 255);
    // Odd ratios keep the aspect, every output pixel averaging at least one source pixel.
    const Image8 odd = downsizeImage(src, 3);
    EXPECT_EQ(odd.width, 3);
    EXPECT_EQ(odd.height, 2); // round(4·3/8) = 2 (1.5 rounds up)
    const Image8 one = downsizeImage(src, 1);
    EXPECT_EQ(one.width, 1);
    EXPECT_EQ(one.height, 1);
    EXPECT_EQ(one.rgba[0], 100); // (4·0 + 4·200)/8
    // Never enlarged: a maxSide at or above the longer side is a copy.
    const Image8 same = downsizeImage(src, 8);
    EXPECT_EQ(same.width, 8);
    EXPECT_EQ(same.rgba, src.rgba);
    EXPECT_EQ(downsizeImage(src, 4096).rgba, src.rgba);
}

TEST(ModelQueriesTest, DominantBaseColorImageCountsTrianglesPerImage) {
    Model m = quad();                 // part 0: 2 triangles, no material
    EXPECT_EQ(m.dominantBaseColorImage(), -1);
    Image8 tex;
    tex.width = tex.height = 2;
    tex.rgba.assign(16, 255);
    m.images = {tex, tex};
    m.materials = {{"plain"}, {"a"}, {"b"}, {"b too"}};
    m.materials[1].baseColorTexture = 0;
    m.materials[2].baseColorTexture = 1;
    m.materials[3].baseColorTexture = 1;
    m.parts[0].material = 0; // untextured: counts for nothing
    EXPECT_EQ(m.dominantBaseColorImage(), -1);
    MeshPart three = m.parts[0];
    three.indices = {0, 1, 2, 0, 2, 3, 0, 1, 3};
    three.material = 1; // image 0: 3 triangles
    MeshPart two = m.parts[0];
    two.material = 2; // image 1: 2 triangles …
    m.parts.push_back(three);
    m.parts.push_back(two);
    EXPECT_EQ(m.dominantBaseColorImage(), 0);
    two.material = 3; // … plus 2 through another material naming the same image
    m.parts.push_back(two);
    EXPECT_EQ(m.dominantBaseColorImage(), 1);
    m.parts.pop_back();
    m.parts.back().indices = {0, 1, 2, 0, 2, 3, 1, 2, 3};
    EXPECT_EQ(m.dominantBaseColorImage(), 0); // a tie goes to the lower image index
    m.materials[1].baseColorTexture = 7;      // out of range: ignored
    EXPECT_EQ(m.dominantBaseColorImage(), 1);
    m.images[1] = Image8{};                   // empty: ignored
    EXPECT_EQ(m.dominantBaseColorImage(), -1);
}

TEST(ModelQueriesTest, ParentJointSkipsNonJointNodes) {
    Model m;
    m.nodes = {{"hips"}, {"helper"}, {"spine"}, {"prop"}};
    m.nodes[1].parent = 0;
    m.nodes[2].parent = 1;
    m.nodes[3].parent = 2;
    m.joints = {0, 2};
    EXPECT_EQ(m.parentJoint(2), 0);
    EXPECT_EQ(m.parentJoint(0), -1);
    EXPECT_EQ(m.parentJoint(3), 2);
    EXPECT_EQ(m.parentJoint(99), -1);
    m.nodes[0].parent = 2; // a cycle must not hang
    m.joints = {2};
    EXPECT_EQ(m.parentJoint(2), -1);
}

} // namespace
