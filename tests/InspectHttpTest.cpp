// InspectHttpTest — probe and activation over real HTTP (HttpTestFixture.hpp): the probe's
// bump value equals the served f32 map at that texel, contributions name the placement;
// activation of the scene's clip lists every placement; bad parameters are clear 4xx errors.
#include "HttpTestFixture.hpp"

#include <cstring>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

class InspectHttpTest : public SharedServerTest {};

TEST_F(InspectHttpTest, ProbeAndActivation) {
    Http h = http();
    const std::string id = createScene(smallScene());
    const std::string s = "/scenes/" + id;
    const json placement = smallScene()["placements"][0];
    const double u = placement["center"][0], v = placement["center"][1];

    Reply probe = h.get(s + "/probe?u=" + std::to_string(u) + "&v=" + std::to_string(v));
    ASSERT_EQ(probe.status, 200) << probe;
    const json p = probe.js();
    ASSERT_EQ(p["contributions"].size(), 1u) << p;
    EXPECT_EQ(p["contributions"][0]["placement"], "elbow");
    EXPECT_EQ(p["contributions"][0]["pattern"], "crease");
    EXPECT_EQ(p["contributions"][0]["target"], "bump");
    EXPECT_EQ(p["map_size"], json({256, 256}));
    // The served map holds the same value at that texel (GPU, within its tolerance).
    Reply map = h.get(s + "/heightmaps/bump?format=f32");
    ASSERT_EQ(map.status, 200);
    const int x = p["texel"][0], y = p["texel"][1];
    float served = 0;
    std::memcpy(&served, map.body.data() + (static_cast<std::size_t>(y) * 256 + x) * 4, 4);
    EXPECT_NEAR(served, p["bump"].get<double>(), 2e-3);
    EXPECT_NE(p["bump"].get<double>(), 0.0) << "the elbow crease is active at time 0.5 of elbow_curl";

    Reply act = h.get(s + "/activation?clip=elbow_curl&fps=10");
    ASSERT_EQ(act.status, 200) << act;
    const json a = act.js();
    ASSERT_TRUE(a["placements"].contains("elbow")) << a;
    EXPECT_EQ(a["placements"]["elbow"].size(), a["times"].size());
    EXPECT_TRUE(a["flags"].is_array());

    expectError(h.get(s + "/probe?u=1.5&v=0.5"), 422, "u");
    expectError(h.get(s + "/probe?u=0.5&v=-0.1"), 422, "v");
    expectError(h.get(s + "/probe?u=0.5"), 422, "v");
    expectError(h.get(s + "/probe?u=abc&v=0.5"), 422, "u");
    expectError(h.get(s + "/probe?u=0.5&v=0.5&time=-1"), 422, "time");
    expectError(h.get(s + "/activation?clip=no_such_clip"), 404, "clip");
    expectError(h.get(s + "/activation"), 422, "clip");
    expectError(h.get(s + "/activation?clip=elbow_curl&fps=0"), 422, "fps");
    expectError(h.get(s + "/activation?clip=elbow_curl&fps=1000"), 422, "fps");
    expectError(h.get("/scenes/s_0000000000000000/probe?u=0.5&v=0.5"), 404, "id");
    ASSERT_EQ(h.del(s).status, 204);
}

} // namespace
