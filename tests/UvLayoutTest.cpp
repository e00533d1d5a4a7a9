// UvLayoutTest — pictures for people and model queries in the core: UV edges and their raster,
// height previews, the joint-parent walk. Pure.
#include "core/model.hpp"
#include "core/preview.hpp"
#include "core/uv_layout.hpp"

#include <gtest/gtest.h>

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
