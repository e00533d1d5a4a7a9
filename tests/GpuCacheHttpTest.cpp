// GpuCacheHttpTest — GPU memory of deleted content is given back (issue #12, part 4), end to end
// on one server (HttpTestFixture.hpp: a real dermis::Service + dermis::Api on 127.0.0.1 in this
// process, a GL context on $DERMIS_TEST_GL — Mesa's llvmpipe keeps textures in process memory, so
// the process's resident memory shows what the renderer holds). It checks:
//   * 20 cycles of upload a 4096² pattern → render a frame with it → delete the scene and the
//     pattern grow the resident memory by less than 100 MB (each cycle's R32F texture is 64 MB;
//     without eviction they add 1.2 GB), with the server's default GPU cache budget;
//   * GET /info reports the GPU cache (entries, bytes, budget), and a deleted pattern's and
//     model's GPU objects are gone from it.
#include "ProcessStats.hpp"
#include "HttpTestFixture.hpp"

#include <fstream>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// Resident memory of this process (the server runs in it) in MB, from /proc/self/status.
double rssMb() {
    const long kb = test::residentKb();
    return kb < 0 ? -1.0 : kb / 1024.0;
}

/// A 4096² pattern as PNG bytes: flat (128 = height 0) with a dome in the middle, so that it
/// compresses to little while the server still decodes and uploads all of its 16 M texels.
std::vector<std::uint8_t> bigPatternPng() {
    constexpr int n = 4096;
    Image8 img;
    img.width = img.height = n;
    img.rgba.assign(static_cast<std::size_t>(n) * n * 4, 128);
    for (int y = n / 4; y < 3 * n / 4; ++y)
        for (int x = n / 4; x < 3 * n / 4; ++x) {
            const double dx = (x + 0.5) / n - 0.5, dy = (y + 0.5) / n - 0.5;
            const double r = std::min(1.0, std::sqrt(dx * dx + dy * dy) * 4.0);
            std::uint8_t* p = &img.rgba[(static_cast<std::size_t>(y) * n + x) * 4];
            p[0] = p[1] = p[2] = static_cast<std::uint8_t>(128 + std::lround(127 * (1.0 - r * r)));
        }
    for (std::size_t i = 3; i < img.rgba.size(); i += 4)
        img.rgba[i] = 255;
    auto png = encodePng(img, false);
    EXPECT_TRUE(png) << png.error().message;
    return png ? *png : std::vector<std::uint8_t>{};
}

/// A server whose uploads may hold a 4096² PNG; otherwise the main limits and the default GPU
/// cache budget (the renderer Service::open creates).
class GpuCacheHttpTest : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        ServerLimits limits = mainLimits();
        limits.maxUploadBytes = 64u << 20;
        server_ = LiveServer::start(limits, "", error_);
    }
    static void TearDownTestSuite() { server_.reset(); }
    void SetUp() override {
        ASSERT_TRUE(server_ && error_.empty()) << "the server did not start: " << error_;
    }
    static Http http() { return Http(server_->port()); }

    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

/// A scene on the default character with one placement of `pattern`, driven, small maps and frame.
json sceneWith(const std::string& pattern) {
    json doc = smallScene();
    doc["placements"] = {placementOf(pattern, "dome")};
    doc["pose"] = {{"joints", {{"forearm.l", {{"axis_angles", {{"x", 60}}}}}}}};
    return doc;
}

/// One upload → frame → delete cycle of `png`; false (with failures recorded) when a step fails.
bool patternCycle(const Http& h, const std::vector<std::uint8_t>& png) {
    Reply up = h.upload("/patterns?name=big", png, "image/png");
    EXPECT_EQ(up.status, 201) << up;
    if (up.status != 201) return false;
    const std::string pid = up.js()["id"];
    EXPECT_EQ(up.js()["width"], 4096);
    Reply created = h.post("/scenes", sceneWith(pid));
    EXPECT_EQ(created.status, 201) << created;
    if (created.status != 201) return false;
    const std::string sid = created.js()["id"];
    Reply frame = h.get("/scenes/" + sid + "/frame");
    EXPECT_EQ(frame.status, 200) << frame;
    EXPECT_TRUE(isPng(frame.body));
    EXPECT_EQ(h.del("/scenes/" + sid).status, 204);
    Reply removed = h.del("/patterns/" + pid);
    EXPECT_EQ(removed.status, 204) << removed;
    return frame.status == 200 && removed.status == 204;
}

TEST_F(GpuCacheHttpTest, DeletedPatternsGiveTheirTexturesBack) {
    Http h = http();
    const std::vector<std::uint8_t> png = bigPatternPng();
    ASSERT_FALSE(png.empty());
    // The first cycle creates what every frame reuses (targets, the default character's buffers).
    ASSERT_TRUE(patternCycle(h, png));
    const double before = rssMb();
    double peak = before;
    for (int cycle = 1; cycle < 20; ++cycle) {
        ASSERT_TRUE(patternCycle(h, png)) << "cycle " << cycle;
        peak = std::max(peak, rssMb());
    }
    const double after = rssMb();
    std::cout << "[ rss ] before " << before << " MB, after 19 more cycles " << after
              << " MB, peak " << peak << " MB\n";
    // Under AddressSanitizer freed memory stays resident in its quarantine (up to 256 MB), which
    // adds ~100 MB of noise here: the bound doubles there (a leaked 64 MB texture per cycle would
    // still be over 1 GB after 19 cycles).
#if defined(__SANITIZE_ADDRESS__)
    constexpr double kGrowthMb = 200.0;
#else
    constexpr double kGrowthMb = 100.0;
#endif
    EXPECT_LT(after - before, kGrowthMb) << "resident memory grew by " << after - before << " MB";

    // The deletes reached the renderer: a frame after them (the render queue runs in order)
    // finds no texture of a deleted pattern left in the cache.
    const std::string sid = h.post("/scenes", smallScene()).js().value("id", "");
    ASSERT_EQ(h.get("/scenes/" + sid + "/frame").status, 200);
    const json info = h.get("/info").js();
    ASSERT_TRUE(info.contains("gpu_cache")) << info.dump();
    const json& cache = info["gpu_cache"];
    EXPECT_GT(cache["budget_bytes"].get<double>(), 0.0);
    EXPECT_LE(cache["texture_bytes"].get<double>() + cache["model_bytes"].get<double>(),
              cache["budget_bytes"].get<double>());
    EXPECT_LT(cache["texture_bytes"].get<double>(), 64.0 * 1024 * 1024) << cache.dump();
    EXPECT_GE(cache["textures"].get<int>(), 1) << cache.dump(); // the crease of smallScene()
}

TEST_F(GpuCacheHttpTest, DeletedModelsGiveTheirBuffersBack) {
    Http h = http();
    const std::string builtin = h.post("/scenes", smallScene()).js().value("id", "");
    ASSERT_EQ(h.get("/scenes/" + builtin + "/frame").status, 200);
    const int modelsBefore = h.get("/info").js()["gpu_cache"].value("models", -1);
    ASSERT_GE(modelsBefore, 1);

    Reply up = h.upload("/models?name=cesium", readBytes(kCesiumMan), "model/gltf-binary");
    ASSERT_EQ(up.status, 201) << up;
    const std::string mid = up.js()["id"];
    json doc = smallScene();
    doc["model"] = mid;
    doc["placements"] = json::array();
    doc.erase("pose");
    Reply created = h.post("/scenes", doc);
    ASSERT_EQ(created.status, 201) << created;
    const std::string sid = created.js()["id"];
    ASSERT_EQ(h.get("/scenes/" + sid + "/frame").status, 200);
    EXPECT_EQ(h.get("/info").js()["gpu_cache"].value("models", -1), modelsBefore + 1);

    EXPECT_EQ(h.del("/scenes/" + sid).status, 204);
    EXPECT_EQ(h.del("/models/" + mid).status, 204);
    // A job queued after the delete (a frame of another scene) has run: the model is gone.
    ASSERT_EQ(h.get("/scenes/" + builtin + "/frame").status, 200);
    EXPECT_EQ(h.get("/info").js()["gpu_cache"].value("models", -1), modelsBefore);
}

} // namespace
