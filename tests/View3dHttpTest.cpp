// View3dHttpTest — the 3D view's server parts over real HTTP (HttpTestFixture.hpp, GL renders):
//   * camera target: `target=x,y,z` on frame, pick, frame-diff and sweep; the frame answers the
//     camera it used (X-Dermis-Camera-Distance / -Target); a target at that point gives the same
//     bytes as none, another one another frame; a pick through the image centre hits near the
//     target; malformed targets answer 422 with field "target";
//   * outlines: `highlight`, `hover`, `brush` change the frame (only near the footprint), a frame
//     without them is byte for byte the plain one, unknown ids and bad brushes answer 422;
//   * focus: the selected placement's surface point and a distance; looking there puts that
//     placement's footprint in the middle of the frame;
//   * turntable: an animated WebP of N frames of size², looping, first and middle frames differ;
//     bounds on frames and size, unknown placements, width/height refused.
#include "HttpTestFixture.hpp"
#include "io/webp_anim.hpp"

#include <cmath>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

class View3dHttpTest : public SharedServerTest {};

std::string createDefault(const Http& h) {
    Reply created = h.post("/scenes", {{"default_patterns", true}});
    EXPECT_EQ(created.status, 201) << created;
    return "/scenes/" + created.js().value("id", "");
}

std::vector<double> numbers(const std::string& csv) {
    std::vector<double> out;
    std::size_t start = 0;
    while (start <= csv.size()) {
        const std::size_t comma = std::min(csv.find(',', start), csv.size());
        out.push_back(std::stod(csv.substr(start, comma - start)));
        start = comma + 1;
    }
    return out;
}

TEST_F(View3dHttpTest, ACameraTargetIsLookedAtAndAnsweredWithTheFrame) {
    Http h = http();
    const std::string s = createDefault(h);
    Reply plain = h.get(s + "/frame?width=128&height=128&msaa=1&time=0.5");
    ASSERT_EQ(plain.status, 200) << plain;
    const std::vector<double> t = numbers(plain.header("X-Dermis-Camera-Target"));
    ASSERT_EQ(t.size(), 3u) << plain.header("X-Dermis-Camera-Target");
    const double distance = std::stod(plain.header("X-Dermis-Camera-Distance"));
    EXPECT_GT(distance, 0.0);
    // The answered target given back: the same camera, the same bytes (%.9g round-trips floats).
    const std::string at = plain.header("X-Dermis-Camera-Target");
    Reply same = h.get(s + "/frame?width=128&height=128&msaa=1&time=0.5&target=" + at);
    ASSERT_EQ(same.status, 200) << same;
    EXPECT_EQ(same.body, plain.body);
    // Another target (the top of the character, closer): another frame, and a pick through the
    // image centre lands near that point.
    Reply bounds = h.get(s + "/pick?x=64&y=64&width=128&height=128&time=0.5");
    ASSERT_EQ(bounds.status, 200) << bounds;
    const std::string high = std::to_string(t[0]) + "," + std::to_string(t[1] + 0.3 * distance * 0.25) + "," + std::to_string(t[2]);
    const std::string q = "width=128&height=128&msaa=1&time=0.5&distance=" + std::to_string(0.4 * distance) + "&target=" + high;
    Reply moved = h.get(s + "/frame?" + q);
    ASSERT_EQ(moved.status, 200) << moved;
    EXPECT_NE(moved.body, plain.body);
    EXPECT_NEAR(numbers(moved.header("X-Dermis-Camera-Target")).at(1), numbers(high).at(1), 1e-5); // a float
    Reply pick = h.get(s + "/pick?x=64&y=64&" + q.substr(q.find("width")));
    ASSERT_EQ(pick.status, 200) << pick;
    if (pick.js().value("hit", false)) {
        const json p = pick.js()["position"];
        // On the ray through the target: the hit's projection onto the image plane is the target's.
        EXPECT_NEAR(p[1].get<double>(), numbers(high)[1], 0.2 * distance) << pick;
    }
    // Frame-diff and sweep take it too.
    Reply diff = h.get(s + "/frame-diff?against=off&" + q);
    ASSERT_EQ(diff.status, 200) << diff;
    EXPECT_FALSE(diff.header("X-Dermis-Camera-Target").empty());
    Reply sweep = h.get(s + "/sweep?placement=elbow_l&steps=2&size=64&target=" + high);
    ASSERT_EQ(sweep.status, 200) << sweep;
    Reply sweepPlain = h.get(s + "/sweep?placement=elbow_l&steps=2&size=64");
    EXPECT_NE(sweep.body, sweepPlain.body);
    // Malformed targets.
    for (const char* bad : {"1,2", "1,2,3,4", "a,b,c", "1,,3", "nan,0,0", "2e6,0,0", ""}) {
        SCOPED_TRACE(bad);
        expectError(h.get(s + "/frame?width=32&height=32&target=" + std::string(bad)), 422, "target");
    }
    expectError(h.get(s + "/pick?x=1&y=1&width=32&height=32&target=1,2"), 422, "target");
}

TEST_F(View3dHttpTest, OutlinesChangeOnlyWhatIsAskedAndNothingWithout) {
    Http h = http();
    const std::string s = createDefault(h);
    const std::string base = s + "/frame?width=192&height=192&msaa=1&time=0.5";
    Reply plain = h.get(base);
    ASSERT_EQ(plain.status, 200) << plain;
    Reply again = h.get(base);
    EXPECT_EQ(again.body, plain.body);
    auto plainImg = decodeFrame(plain.bytes());
    ASSERT_TRUE(plainImg);
    Reply hi = h.get(base + "&highlight=stomach");
    ASSERT_EQ(hi.status, 200) << hi;
    auto hiImg = decodeFrame(hi.bytes());
    ASSERT_TRUE(hiImg);
    const std::size_t changed = pixelsDiffering(*hiImg, *plainImg);
    EXPECT_GT(changed, 30u);
    EXPECT_LT(changed, 192u * 192u / 8u);
    Reply hover = h.get(base + "&hover=stomach");
    ASSERT_EQ(hover.status, 200) << hover;
    EXPECT_NE(hover.body, hi.body);
    EXPECT_NE(hover.body, plain.body);
    Reply brush = h.get(base + "&brush=0.5,0.5,0.1,0.1,30");
    ASSERT_EQ(brush.status, 200) << brush;
    Reply both = h.get(base + "&highlight=stomach,elbow_l&hover=waist_l");
    ASSERT_EQ(both.status, 200) << both;
    // A frame-diff ignores outlines (a heat map of the patterns).
    Reply d1 = h.get(s + "/frame-diff?against=off&width=64&height=64&msaa=1");
    Reply d2 = h.get(s + "/frame-diff?against=off&width=64&height=64&msaa=1&highlight=stomach");
    ASSERT_EQ(d1.status, 200);
    EXPECT_EQ(d1.body, d2.body);
    expectError(h.get(base + "&highlight=nope"), 422, "highlight");
    expectError(h.get(base + "&highlight=a,b,c,d,e,f,g"), 422, "highlight");
    expectError(h.get(base + "&hover=nope"), 422, "hover");
    expectError(h.get(base + "&hover="), 422, "hover");
    for (const char* bad : {"0.5,0.5,0.1", "0.5,0.5,0,0.1", "0.5,0.5,0.1,0.1,0,9", "x,0.5,0.1,0.1", "99,0.5,0.1,0.1"}) {
        SCOPED_TRACE(bad);
        expectError(h.get(base + "&brush=" + bad), 422, "brush");
    }
}

TEST_F(View3dHttpTest, FocusFramesThePlacementsSkin) {
    Http h = http();
    const std::string s = createDefault(h);
    Reply f = h.get(s + "/focus?placement=elbow_l&time=0.5");
    ASSERT_EQ(f.status, 200) << f;
    const json j = f.js();
    ASSERT_TRUE(j["target"].is_array() && j["target"].size() == 3) << f;
    EXPECT_TRUE(j["hit"].get<bool>());
    EXPECT_GT(j["radius"].get<double>(), 0.0);
    EXPECT_GT(j["distance"].get<double>(), j["radius"].get<double>());
    Reply whole = h.get(s + "/frame?width=64&height=64&time=0.5");
    ASSERT_EQ(whole.status, 200);
    EXPECT_LT(j["distance"].get<double>(), 0.5 * std::stod(whole.header("X-Dermis-Camera-Distance")))
        << "a footprint is much smaller than the body";
    // Looking there: the image centre shows the skin of that footprint (pick → uv inside it).
    const std::string target = std::to_string(j["target"][0].get<double>()) + "," +
                               std::to_string(j["target"][1].get<double>()) + "," +
                               std::to_string(j["target"][2].get<double>());
    const json doc = h.get(s).js()["scene"];
    json elbow;
    for (const json& p : doc["placements"])
        if (p["id"] == "elbow_l") elbow = p;
    bool inside = false;
    for (double yaw : {0.0, 90.0, 180.0, 270.0}) { // from some side the centre is not hidden
        Reply pick = h.get(s + "/pick?x=32&y=32&width=64&height=64&time=0.5&yaw=" + std::to_string(yaw) +
                           "&distance=" + std::to_string(j["distance"].get<double>()) + "&target=" + target);
        ASSERT_EQ(pick.status, 200) << pick;
        if (!pick.js().value("hit", false)) continue;
        const json uv = pick.js()["uv"];
        const double du = uv[0].get<double>() - elbow["center"][0].get<double>();
        const double dv = uv[1].get<double>() - elbow["center"][1].get<double>();
        inside = inside || std::hypot(du, dv) < 0.02;
    }
    EXPECT_TRUE(inside) << "the picked skin at the centre is the footprint's centre";
    expectError(h.get(s + "/focus?placement=nope"), 404, "placement");
    expectError(h.get(s + "/focus"), 422, "placement");
}

TEST_F(View3dHttpTest, TurntableIsALoopingAnimatedWebpOfTheRangeOfMotion) {
    Http h = http();
    const std::string s = createDefault(h);
    Reply r = h.get(s + "/turntable?placement=elbow_l&frames=8&size=96&msaa=1");
    ASSERT_EQ(r.status, 200) << r;
    EXPECT_EQ(r.header("Content-Type"), "image/webp");
    auto anim = decodeAnimatedWebp(r.bytes());
    ASSERT_TRUE(anim) << anim.error().message;
    ASSERT_EQ(anim->frames.size(), 8u);
    EXPECT_EQ(anim->loopCount, 0);
    EXPECT_EQ(anim->frames[0].width, 96);
    EXPECT_EQ(anim->frames[0].height, 96);
    EXPECT_EQ(anim->timestamps.back(), 8 * 83); // 12 fps
    // Frame 0 (θmin, yaw 0) and frame 4 (θmax, yaw 180) differ a lot; the loop is smooth: frame 1
    // and frame 7 show the same θ from mirrored yaws (not compared: lossy).
    EXPECT_GT(pixelsDiffering(anim->frames[0], anim->frames[4]), 200u);
    expectError(h.get(s + "/turntable?placement=elbow_l&frames=3"), 422, "frames");
    expectError(h.get(s + "/turntable?placement=elbow_l&frames=121"), 422, "frames");
    expectError(h.get(s + "/turntable?placement=elbow_l&size=63"), 422, "size");
    expectError(h.get(s + "/turntable?placement=elbow_l&size=513"), 422, "size");
    expectError(h.get(s + "/turntable?placement=elbow_l&fps=0"), 422, "fps");
    expectError(h.get(s + "/turntable?placement=elbow_l&width=64"), 422, "width");
    expectError(h.get(s + "/turntable?placement=elbow_l&format=png"), 422, "format");
    expectError(h.get(s + "/turntable?placement=nope"), 404, "placement");
    expectError(h.get(s + "/turntable"), 422, "placement");
}

} // namespace
