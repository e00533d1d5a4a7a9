// RendersHttpTest — renders without a stored scene and under load, end to end (HttpTestFixture.hpp:
// a real dermis::Service + dermis::Api on 127.0.0.1, a GL context on $DERMIS_TEST_GL, cpp-httplib
// clients over loopback). It checks:
//   * the stateless batch (POST /render): multipart/mixed with one decodable image part per frame,
//     PNG and JPEG, and a view other than shaded;
//   * content addresses (SPEC §7): a batch naming a pattern as sha256:<hex> that the server lacks
//     answers 409 missing_content with the list; sent again as multipart/form-data with the bytes
//     it renders, and at the upload body limit rather than the JSON one;
//   * back-pressure: with a render queue of 1 (a second server), concurrent frames answer 200 or
//     503 + Retry-After, and renders go through again once the burst is over.
#include "HttpTestFixture.hpp"
#include "common/sha256.hpp"
#include "io/webp_encode.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// One server (no token).
class RendersHttpTest : public SharedServerTest {};

// ================================================================================================
// Frames with their parameters in a POST body (issue #27, item 8)
// ================================================================================================

std::string percentEncoded(const std::string& s) {
    std::string out;
    char buf[4];
    for (unsigned char c : s) {
        if (std::isalnum(c) || c == '-' || c == '_' || c == '.') out += static_cast<char>(c);
        else {
            std::snprintf(buf, sizeof buf, "%%%02X", c);
            out += buf;
        }
    }
    return out;
}

TEST_F(RendersHttpTest, PostFrameTakesAPreviewTooLargeForTheRequestLine) {
    Http h = http();
    json doc = smallScene();
    doc["placements"] = json::array();
    for (int k = 0; k < 24; ++k) doc["placements"].push_back(placementOf("crease", "p" + std::to_string(k)));
    const std::string id = createScene(doc);
    // A small preview: GET and POST give the same bytes, and not the plain frame's.
    const json small = {{"p3", {{"center", {0.35, 0.42}}}}};
    Reply get = h.get("/scenes/" + id + "/frame?msaa=1&preview=" + percentEncoded(small.dump()));
    Reply post = h.post("/scenes/" + id + "/frame", {{"msaa", 1}, {"preview", small}});
    ASSERT_EQ(get.status, 200) << get;
    ASSERT_EQ(post.status, 200) << post;
    EXPECT_EQ(post.header("Content-Type"), "image/png");
    EXPECT_EQ(get.body, post.body) << "one parser for both";
    // Every placement disabled in the preview: the frame without patterns, byte for byte.
    json off = json::object();
    for (int k = 0; k < 24; ++k) off["p" + std::to_string(k)] = {{"enabled", false}};
    Reply none = h.post("/scenes/" + id + "/frame", {{"msaa", 1}, {"preview", off}});
    Reply patternsOff = h.get("/scenes/" + id + "/frame?msaa=1&patterns=off");
    ASSERT_EQ(none.status, 200) << none;
    EXPECT_EQ(none.body, patternsOff.body) << "the preview was applied";
    // A 4 KB preview is over 8 KB percent-encoded: the GET is refused (414), the POST renders.
    json large = json::object();
    for (int k = 0; k < 24; ++k)
        large["p" + std::to_string(k)] = {{"label", std::string(120, '/')}, {"center", {0.3 + 0.01 * k, 0.4}}};
    ASSERT_GT(percentEncoded(large.dump()).size(), 8192u);
    ASSERT_LT(large.dump().size(), 16384u);
    EXPECT_EQ(h.get("/scenes/" + id + "/frame?preview=" + percentEncoded(large.dump())).status, 414);
    Reply big = h.post("/scenes/" + id + "/frame", {{"preview", large}, {"format", "jpeg"}, {"target", {0, 1, 0}}});
    ASSERT_EQ(big.status, 200) << big;
    EXPECT_EQ(big.header("Content-Type"), "image/jpeg");
    expectError(h.post("/scenes/" + id + "/frame", {{"bogus", 1}}), 422, "/bogus");
    expectError(h.post("/scenes/" + id + "/frame", json::array()), 422);
    EXPECT_EQ(h.get("/scenes/" + id).js()["revision"], 1) << "nothing stored";
}

// ================================================================================================
// Anti-aliasing per frame (issue #28, item 3) and the render time the editor paces by (item 1)
// ================================================================================================

TEST_F(RendersHttpTest, FramesSayWhichAntiAliasingTheyUsedAndHowLongTheyTook) {
    Http h = http();
    json doc = smallScene();
    doc["render"]["msaa"] = 4;
    const std::string id = createScene(doc);
    const std::string frame = "/scenes/" + id + "/frame?width=96&height=96";
    const json info = h.get("/info").js();
    const std::string autoMode = info["aa_auto"];
    EXPECT_TRUE(autoMode == "post" || autoMode == "msaa4") << info.dump();
    const bool software = info["gl"]["renderer"].get<std::string>().find("llvmpipe") != std::string::npos;
    EXPECT_EQ(autoMode, software ? "post" : "msaa4");
    Reply plain = h.get(frame);
    ASSERT_EQ(plain.status, 200) << plain;
    EXPECT_EQ(plain.header("X-Dermis-AA"), autoMode) << "the scene's render.aa is auto";
    EXPECT_EQ(h.get(frame + "&aa=msaa").header("X-Dermis-AA"), "msaa4");
    EXPECT_EQ(h.get(frame + "&msaa=2").header("X-Dermis-AA"), "msaa2") << "msaa alone selects MSAA";
    EXPECT_EQ(h.get(frame + "&msaa=1").header("X-Dermis-AA"), "none");
    Reply post = h.get(frame + "&aa=post");
    EXPECT_EQ(post.header("X-Dermis-AA"), "post");
    Reply none = h.get(frame + "&aa=none");
    EXPECT_EQ(none.header("X-Dermis-AA"), "none");
    EXPECT_NE(post.body, none.body) << "the edge pass changed the frame";
    EXPECT_EQ(h.post("/scenes/" + id + "/frame", {{"width", 96}, {"height", 96}, {"aa", "post"}}).body, post.body);
    expectError(h.get(frame + "&aa=fxaa"), 422, "aa");
    // The scene's own render.aa is a document field like msaa.
    doc["render"]["aa"] = "none";
    Reply put = h.put("/scenes/" + id, doc);
    ASSERT_EQ(put.status, 200) << put;
    EXPECT_EQ(put.js()["scene"]["render"]["aa"], "none") << put.body;
    EXPECT_EQ(h.get(frame).header("X-Dermis-AA"), "none");
    doc["render"]["aa"] = "smaa";
    expectError(h.put("/scenes/" + id, doc), 422, "/render/aa");
    // Server-Timing: render;dur=<ms>, a plausible duration.
    const std::string timing = plain.header("Server-Timing");
    ASSERT_EQ(timing.rfind("render;dur=", 0), 0u) << timing;
    const double ms = std::stod(timing.substr(11));
    EXPECT_GT(ms, 0.0);
    EXPECT_LT(ms, 60000.0);
}

// ================================================================================================
// Stateless batch
// ================================================================================================

TEST_F(RendersHttpTest, BatchStreamsOneImagePartPerFrame) {
    Http h = http();
    json body = {{"scene", smallScene()},
                 {"frames", json::array({{{"time", 0.2}},
                                         {{"time", 0.8}},
                                         {{"pose", {{"animation", "squat"}, {"time", 1.0}}}}})},
                 {"format", "png"}};
    Reply r = h.post("/render", body);
    ASSERT_EQ(r.status, 200) << r;
    EXPECT_EQ(r.header("X-Dermis-Frames"), "3");
    const std::string ct = r.header("Content-Type");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(ct, m, std::regex("^multipart/mixed; *boundary=\"?([^\";]+)\"?")))
        << ct;
    const auto parts = multipartParts(r.body, m[1]);
    ASSERT_EQ(parts.size(), 3u) << r.body.size();
    std::vector<Image8> frames;
    for (std::size_t k = 0; k < parts.size(); ++k) {
        SCOPED_TRACE(k);
        EXPECT_NE(parts[k].headers.find("Content-Type: image/png"), std::string::npos)
            << parts[k].headers;
        EXPECT_NE(parts[k].headers.find("X-Dermis-Frame: " + std::to_string(k)), std::string::npos);
        auto img = decodeFrame({parts[k].content.begin(), parts[k].content.end()});
        ASSERT_TRUE(img) << img.error().message;
        EXPECT_EQ(img->width, 128);
        EXPECT_EQ(img->height, 128);
        frames.push_back(std::move(*img));
    }
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_GT(pixelsDiffering(frames[0], frames[2]), 20u); // squat vs elbow curl

    // JPEG batches too.
    body["format"] = "jpeg";
    body["frames"] = json::array({{{"time", 0.0}}});
    Reply jr = h.post("/render", body);
    ASSERT_EQ(jr.status, 200) << jr;
    const auto jparts = multipartAnswerParts(jr);
    ASSERT_EQ(jparts.size(), 1u);
    EXPECT_NE(jparts[0].headers.find("image/jpeg"), std::string::npos);
    EXPECT_TRUE(decodeFrame({jparts[0].content.begin(), jparts[0].content.end()}));

    // Lossless WebP batches: image/webp parts that libwebp decodes to the PNG batch's pixels.
    body["format"] = "png";
    Reply pr = h.post("/render", body);
    ASSERT_EQ(pr.status, 200) << pr;
    const auto pparts = multipartAnswerParts(pr);
    ASSERT_EQ(pparts.size(), 1u);
    auto pimg = decodeFrame({pparts[0].content.begin(), pparts[0].content.end()});
    ASSERT_TRUE(pimg);
    body["format"] = "webp";
    Reply wr = h.post("/render", body);
    ASSERT_EQ(wr.status, 200) << wr;
    const auto wparts = multipartAnswerParts(wr);
    ASSERT_EQ(wparts.size(), 1u);
    EXPECT_NE(wparts[0].headers.find("Content-Type: image/webp"), std::string::npos);
    auto wimg = decodeWebp({wparts[0].content.begin(), wparts[0].content.end()});
    ASSERT_TRUE(wimg) << wimg.error().message;
    EXPECT_EQ(wimg->rgba, pimg->rgba);
    body["format"] = "gif";
    EXPECT_EQ(h.post("/render", body).status, 422);

    // A view for every frame of the batch; an unknown one is refused before any render.
    body["format"] = "png";
    body["view"] = "bump";
    Reply br = h.post("/render", body);
    ASSERT_EQ(br.status, 200) << br;
    const auto bparts = multipartAnswerParts(br);
    ASSERT_EQ(bparts.size(), 1u);
    auto bump = decodeFrame({bparts[0].content.begin(), bparts[0].content.end()});
    ASSERT_TRUE(bump);
    EXPECT_GT(pixelsDiffering(*bump, frames[0]), 20u);
    body["view"] = "nope";
    expectError(h.post("/render", body), 422, "/view");
}

TEST_F(RendersHttpTest, ContentNamedByAddressIsAskedForThenSentAsMultipart) {
    Http h = http();
    // A pattern image this server has never seen, named by the SHA-256 of its bytes.
    Image8 img;
    img.width = img.height = 24;
    img.rgba.assign(24 * 24 * 4, 255);
    for (std::size_t k = 0; k < img.rgba.size(); k += 4) img.rgba[k] = img.rgba[k + 1] = img.rgba[k + 2] = static_cast<std::uint8_t>(k * 7);
    const std::vector<std::uint8_t> png = *encodePng(img, false);
    const std::string address = "sha256:" + toHex(sha256(png));
    json scene = smallScene();
    scene["patterns"] = {{"mine", address}};
    scene["placements"][0]["pattern"] = "mine";
    const json batch = {{"scene", scene}, {"frames", json::array({{{"time", 0.5}}})}, {"format", "png"}};

    Reply first = h.post("/render", batch);
    expectError(first, 409, "/scene/patterns/mine");
    EXPECT_EQ(first.js()["error"]["code"], "missing_content");
    EXPECT_EQ(first.js()["missing"], json::array({address}));

    // Sent again as multipart/form-data: part "request", then the bytes under their address.
    const auto multipart = [&](const std::string& pngBytes) {
        const std::string b = "dermis-test-boundary";
        std::string body = "--" + b + "\r\nContent-Disposition: form-data; name=\"request\"\r\n"
                           "Content-Type: application/json\r\n\r\n" + batch.dump() + "\r\n";
        body += "--" + b + "\r\nContent-Disposition: form-data; name=\"" + address +
                "\"; filename=\"mine.png\"\r\nContent-Type: image/png\r\n\r\n" + pngBytes + "\r\n--" + b + "--\r\n";
        return h.call("POST", "/render", body, "multipart/form-data; boundary=" + b);
    };
    Reply wrong = multipart(std::string(png.begin(), png.end() - 1) + "x");
    expectError(wrong, 422, address);
    Reply sent = multipart(std::string(png.begin(), png.end()));
    ASSERT_EQ(sent.status, 200) << sent;
    ASSERT_EQ(multipartAnswerParts(sent).size(), 1u);
    // Now without the bytes: the server kept them by address.
    Reply again = h.post("/render", batch);
    ASSERT_EQ(again.status, 200) << again;
    EXPECT_EQ(multipartAnswerParts(again)[0].content, multipartAnswerParts(sent)[0].content);
    const json info = h.get("/info").js();
    EXPECT_GE(info["content_cache"]["entries"].get<int>(), 1) << info.dump();
    EXPECT_GE(info["content_cache"]["hits"].get<int>(), 1) << info.dump();

    // A multipart batch may be as large as an upload (the JSON limit is smaller), no larger.
    const std::string big(kMaxUpload / 2, 'x');
    Reply large = h.call("POST", "/render",
                         "--b\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n" + batch.dump() +
                             "\r\n--b\r\nContent-Disposition: form-data; name=\"unused\"\r\n\r\n" + big + "\r\n--b--\r\n",
                         "multipart/form-data; boundary=b");
    expectError(large, 422, "unused"); // read whole, then refused for its name (not 413)
    Reply huge = h.call("POST", "/render", std::string(kMaxUpload + 1024, 'x'), "multipart/form-data; boundary=b");
    EXPECT_EQ(huge.status, 413) << huge;
}

// ================================================================================================
// Back-pressure (a second server, with a render queue of 1)
// ================================================================================================

class RendersHttpQueueTest : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        ServerLimits l = mainLimits();
        l.queueLength = 1;
        server_ = LiveServer::start(l, "", error_);
    }
    static void TearDownTestSuite() { server_.reset(); }
    void SetUp() override {
        ASSERT_TRUE(server_ && error_.empty()) << "the server did not start: " << error_;
    }
    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

TEST_F(RendersHttpQueueTest, AFullQueueAnswers503WithRetryAfter) {
    Http h(server_->port());
    const std::string id = h.post("/scenes", {{"default_patterns", true}}).js().value("id", "");
    ASSERT_FALSE(id.empty());
    constexpr int kClients = 8;
    std::vector<Reply> replies(kClients);
    std::vector<std::thread> threads;
    std::atomic<int> ready{0};
    for (int i = 0; i < kClients; ++i)
        threads.emplace_back([&, i] {
            ++ready;
            while (ready < kClients)
                std::this_thread::yield();
            replies[static_cast<std::size_t>(i)] =
                h.get("/scenes/" + id + "/frame?width=1024&height=1024&msaa=4");
        });
    for (std::thread& t : threads)
        t.join();
    int ok = 0, busy = 0;
    for (const Reply& r : replies) {
        if (r.status == 200) {
            ++ok;
            auto img = decodeFrame(r.bytes());
            ASSERT_TRUE(img);
            EXPECT_EQ(img->width, 1024);
        } else {
            ++busy;
            expectError(r, 503);
            EXPECT_EQ(r.js()["error"]["code"], "unavailable") << r;
            EXPECT_FALSE(r.header("Retry-After").empty()) << r;
        }
    }
    EXPECT_GE(ok, 1);
    std::cout << "[ RendersHttpQueueTest ] " << ok << " × 200, " << busy << " × 503\n";
    // Once the burst is over, renders go through again.
    EXPECT_EQ(h.get("/scenes/" + id + "/frame?width=64&height=64").status, 200);
    Reply info = h.get("/info");
    EXPECT_EQ(info.js()["render_queue"], 0);
}

} // namespace
