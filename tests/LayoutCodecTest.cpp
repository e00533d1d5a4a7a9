// LayoutCodecTest — texture layouts as bytes (core/layout_codec): a round trip is exact, damaged,
// truncated or stale bytes are refused, and the content key follows what a generator reads.
#include "core/layout_codec.hpp"

#include <gtest/gtest.h>

using namespace dermis;

namespace {

Model twoTriangleModel() {
    Model m;
    MeshPart p;
    p.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    p.normals.assign(4, glm::vec3(0, 0, 1));
    p.uvs = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    p.indices = {0, 1, 2, 2, 1, 3};
    m.parts.push_back(p);
    MeshPart noUv = p;
    noUv.uvs.clear();
    m.parts.push_back(noUv);
    return m;
}

TextureLayout splitLayout() {
    // The second triangle gets its own copies of vertices 1 and 2: a seam along the diagonal.
    TextureLayout l;
    l.kind = "generated";
    PartLayout a;
    a.source = {0, 1, 2, 2, 1, 3};
    a.uvs = {{0.1f, 0.1f}, {0.4f, 0.1f}, {0.1f, 0.4f}, {0.6f, 0.9f}, {0.9f, 0.6f}, {0.9f, 0.9f}};
    a.indices = {0, 1, 2, 3, 4, 5};
    l.parts = {a, PartLayout{}};
    return l;
}

} // namespace

TEST(LayoutCodecTest, RoundTripIsExact) {
    const Model m = twoTriangleModel();
    const TextureLayout l = splitLayout();
    const auto bytes = encodeTextureLayout(l);
    auto back = decodeTextureLayout(bytes, m);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->kind, "generated");
    ASSERT_EQ(back->parts.size(), 2u);
    EXPECT_EQ(back->parts[0].source, l.parts[0].source);
    EXPECT_EQ(back->parts[0].uvs, l.parts[0].uvs);
    EXPECT_EQ(back->parts[0].indices, l.parts[0].indices);
    EXPECT_TRUE(back->parts[1].indices.empty());
    EXPECT_EQ(encodeTextureLayout(*back), bytes);
}

TEST(LayoutCodecTest, ModelLayoutRoundTrips) {
    const Model m = twoTriangleModel();
    const TextureLayout l = modelTextureLayout(m);
    EXPECT_EQ(l.kind, "model");
    ASSERT_EQ(l.parts.size(), 2u);
    EXPECT_EQ(l.parts[0].indices, m.parts[0].indices);
    EXPECT_TRUE(l.parts[1].source.empty()); // no UVs: nothing laid out
    auto back = decodeTextureLayout(encodeTextureLayout(l), m);
    ASSERT_TRUE(back);
    EXPECT_EQ(back->parts[0].uvs, m.parts[0].uvs);
}

TEST(LayoutCodecTest, RefusesDamagedOrStaleBytes) {
    const Model m = twoTriangleModel();
    const auto good = encodeTextureLayout(splitLayout());
    // Every truncation is refused, never read past the end.
    for (std::size_t n = 0; n < good.size(); ++n) {
        std::vector<std::uint8_t> cut(good.begin(), good.begin() + static_cast<long>(n));
        EXPECT_FALSE(decodeTextureLayout(cut, m)) << n;
    }
    auto extra = good;
    extra.push_back(0);
    EXPECT_FALSE(decodeTextureLayout(extra, m));
    auto magic = good;
    magic[0] = 'X';
    EXPECT_FALSE(decodeTextureLayout(magic, m));
    // A layout of another model: a different part count, or a source past the positions.
    Model one = m;
    one.parts.pop_back();
    auto r = decodeTextureLayout(good, one);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("parts"), std::string::npos) << r.error().message;
    Model fewer = m;
    fewer.parts[0].positions.resize(3);
    EXPECT_FALSE(decodeTextureLayout(good, fewer));
    // A UV that is not a number.
    TextureLayout nan = splitLayout();
    nan.parts[0].uvs[2].x = std::nanf("");
    EXPECT_FALSE(decodeTextureLayout(encodeTextureLayout(nan), m));
}

TEST(LayoutCodecTest, ContentKeyFollowsTheMeshAndTheSalt) {
    const Model m = twoTriangleModel();
    const std::string k = layoutContentKey(m, "gen1");
    EXPECT_EQ(k.size(), 32u);
    EXPECT_EQ(layoutContentKey(twoTriangleModel(), "gen1"), k);
    EXPECT_NE(layoutContentKey(m, "gen2"), k);
    Model moved = m;
    moved.parts[0].positions[3].z = 0.01f;
    EXPECT_NE(layoutContentKey(moved, "gen1"), k);
    Model uv = m;
    uv.parts[0].uvs[0].x = 0.5f;
    EXPECT_NE(layoutContentKey(uv, "gen1"), k);
    Model reindexed = m;
    std::swap(reindexed.parts[0].indices[0], reindexed.parts[0].indices[1]);
    EXPECT_NE(layoutContentKey(reindexed, "gen1"), k);
}
