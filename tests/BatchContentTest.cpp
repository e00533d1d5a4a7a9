// BatchContentTest — content addresses in stateless batches (SPEC §7, issue #15), pure (a Service
// with the CPU fake renderer; no GL, no HTTP): a batch naming its model and pattern as
// "sha256:<hex>" is refused with MissingContent listing what the service lacks; sent again with
// the bytes it renders, and the content cache then serves the same addresses without bytes; bytes
// that do not match their address, malformed addresses and mixed roles are refused; uploads with
// the same SHA-256 count; a small cache forgets (LRU) and frees the GPU copies; stored scenes never
// name content by address; a cached model keeps its rest-surface map across batches; an
// environment (render.environment) by address is listed, sent, cached, matched to an upload of
// the same bytes, and refused when its bytes are no environment. Plus ContentCache itself.
#include "BuildPaths.hpp"
#include "ServiceFixture.hpp"

#include "common/sha256.hpp"
#include "service/content_cache.hpp"

#include <map>

namespace dermis::test {
namespace {

using Parts = std::map<std::string, std::vector<std::uint8_t>>;

std::string addressOf(const std::vector<std::uint8_t>& bytes) { return "sha256:" + toHex(sha256(bytes)); }

class BatchContentTest : public ServiceFixture {
protected:
    void SetUp() override {
        ServiceFixture::SetUp();
        model_ =
            readBytes(std::string(dermis::build::testModelsDir()) + "/CesiumMan/CesiumMan.glb");
        ASSERT_FALSE(model_.empty());
        pattern_ = patternPng(32, 32);
    }

    /// CesiumMan and one pattern image, both by address; 32² frames.
    json scene() const {
        return {{"format", "dermis.scene/1"},
                {"model", addressOf(model_)},
                {"patterns", {{"mine", addressOf(pattern_)}}},
                {"placements",
                 {{{"id", "knee"}, {"pattern", "mine"}, {"center", {0.27, 0.46}}, {"scale", {0.09, 0.07}},
                   {"joint", "leg_joint_L_2"}, {"axis", "y"}, {"theta_min", 0}, {"theta_max", 90}}}},
                {"render", {{"size", {32, 32}}}}};
    }
    json body(const json& sceneDoc) const {
        return {{"scene", sceneDoc}, {"frames", {{{"time", 0.1}}, {{"time", 0.6}}}}};
    }
    Parts both() const { return {{addressOf(model_), model_}, {addressOf(pattern_), pattern_}}; }
    void renderAll(const Service::BatchJob& job) {
        for (std::size_t k = 0; k < job.frames; ++k) {
            auto img = job.render(k);
            ASSERT_TRUE(img) << img.error().message;
            EXPECT_EQ(pngSize(img->bytes), (std::pair<int, int>{32, 32}));
        }
    }
    json cacheStats() { return svc_->info()["content_cache"]; }

    std::vector<std::uint8_t> model_, pattern_;
};

TEST_F(BatchContentTest, WhatIsLackingIsListedThenSentThenCached) {
    auto first = svc_->batch(body(scene()));
    ASSERT_FALSE(first);
    EXPECT_EQ(first.error().code, ErrorCode::MissingContent);
    EXPECT_EQ(first.error().field, "/scene/model");
    std::vector<std::string> want = {addressOf(model_), addressOf(pattern_)};
    std::sort(want.begin(), want.end());
    auto missing = first.error().missing;
    std::sort(missing.begin(), missing.end());
    EXPECT_EQ(missing, want);
    EXPECT_NE(first.error().message.find("multipart/form-data"), std::string::npos) << first.error().message;

    auto sent = svc_->batch(body(scene()), both());
    ASSERT_TRUE(sent) << sent.error().message;
    ASSERT_EQ(sent->frames, 2u);
    renderAll(*sent);
    EXPECT_EQ(cacheStats()["insertions"], 2);
    EXPECT_EQ(cacheStats()["entries"], 2);

    // The same addresses again, without bytes: from the cache.
    const auto hits = cacheStats()["hits"].get<int>();
    auto again = svc_->batch(body(scene()));
    ASSERT_TRUE(again) << again.error().message;
    renderAll(*again);
    EXPECT_EQ(cacheStats()["hits"].get<int>(), hits + 2);
    EXPECT_EQ(cacheStats()["insertions"], 2);

    // The pattern named directly by a placement (no alias), and the base, resolve too.
    json direct = scene();
    direct.erase("patterns");
    direct["placements"][0]["pattern"] = addressOf(pattern_);
    direct["heightmap"] = {{"base", addressOf(pattern_)}};
    auto d = svc_->batch(body(direct));
    ASSERT_TRUE(d) << d.error().message;
    renderAll(*d);

    // Only what is lacking is listed: a new pattern, the model cached.
    const auto other = patternPng(16, 8);
    json more = scene();
    more["patterns"]["mine"] = addressOf(other);
    auto m = svc_->batch(body(more));
    ASSERT_FALSE(m);
    EXPECT_EQ(m.error().missing, std::vector<std::string>{addressOf(other)});
    EXPECT_EQ(m.error().field, "/scene/patterns/mine");
}

// A surface placement (SPEC §8) needs the model's rest-surface map: baked once for the cached
// model and kept with it (its derived data rides in the content cache), not once per batch or per
// posed frame.
TEST_F(BatchContentTest, ACachedModelKeepsItsRestSurfaceMapAcrossBatches) {
    json doc = scene();
    doc["placements"][0] = {{"id", "decal"}, {"pattern", "mine"}, {"joint", "leg_joint_L_2"}, {"axis", "y"},
                            {"theta_min", -360}, {"theta_max", -359}, {"projection", "surface"},
                            {"anchor", {{"position", {0.1, 0.0, 0.5}}, {"normal", {0, 0, 1}}, {"tangent", {1, 0, 0}}}},
                            {"size", {0.1, 0.1}}};
    json b = body(doc);
    b["frames"].push_back({{"pose", {{"joints", {{"leg_joint_L_2", {{"axis_angles", {{"y", 30}}}}}}}}}});
    b["frames"].push_back({{"pose", {{"joints", {{"leg_joint_L_2", {{"axis_angles", {{"y", 60}}}}}}}}}});
    auto first = svc_->batch(b, both());
    ASSERT_TRUE(first) << first.error().message;
    ASSERT_EQ(first->frames, 4u);
    renderAll(*first);
    EXPECT_EQ(cacheStats()["rest_surface_builds"], 1) << "one rest map for four frames, two of them posed";
    for (int k = 0; k < 2; ++k) { // by address from the cache, and with the bytes sent again
        auto again = k == 0 ? svc_->batch(b) : svc_->batch(b, both());
        ASSERT_TRUE(again) << again.error().message;
        renderAll(*again);
    }
    EXPECT_EQ(cacheStats()["rest_surface_builds"], 1) << "the next batches bake none";
}

TEST_F(BatchContentTest, PartsMustMatchTheirAddressAndAddressesMustBeWellFormed) {
    // Bytes under another address.
    Parts swapped = {{addressOf(model_), pattern_}, {addressOf(pattern_), pattern_}};
    auto r = svc_->batch(body(scene()), swapped);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
    EXPECT_EQ(r.error().field, addressOf(model_));
    EXPECT_NE(r.error().message.find(addressOf(pattern_)), std::string::npos) << r.error().message;
    EXPECT_EQ(cacheStats()["insertions"], 0); // nothing is kept from a batch with a wrong part

    // A part name that is no address.
    r = svc_->batch(body(scene()), {{"model.glb", model_}});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
    EXPECT_EQ(r.error().field, "model.glb");

    // Malformed addresses in the document, at their field.
    for (const std::string& bad : std::vector<std::string>{"sha256:abc", "sha256:" + std::string(64, 'G'),
                                  "sha256:" + toHex(sha256(model_)).substr(0, 63) + "A"}) {
        json doc = scene();
        doc["model"] = bad;
        r = svc_->batch(body(doc));
        ASSERT_FALSE(r) << bad;
        EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument) << bad;
        EXPECT_EQ(r.error().field, "/scene/model") << r.error().message;
    }

    // One address as both model and pattern.
    json mixed = scene();
    mixed["patterns"]["mine"] = addressOf(model_);
    r = svc_->batch(body(mixed), both());
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
    EXPECT_EQ(r.error().field, "/scene/patterns/mine");

    // Bytes that are no model (a pattern image named as the model's address is checked first:
    // here a garbage file under its own correct address).
    const std::vector<std::uint8_t> junk = {'n', 'o', 't', ' ', 'g', 'l', 'T', 'F'};
    json junkDoc = scene();
    junkDoc["model"] = addressOf(junk);
    r = svc_->batch(body(junkDoc), {{addressOf(junk), junk}, {addressOf(pattern_), pattern_}});
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find(addressOf(junk)), std::string::npos) << r.error().message;

    // Parts the document does not name are ignored (not decoded, not kept).
    auto ok = svc_->batch(body(scene()), {{addressOf(model_), model_}, {addressOf(pattern_), pattern_},
                                          {addressOf(junk), junk}});
    ASSERT_TRUE(ok) << ok.error().message;
    EXPECT_EQ(cacheStats()["entries"], 2); // the model and the pattern
    json named = scene();
    named["patterns"]["mine"] = addressOf(junk);
    auto notKept = svc_->batch(body(named));
    ASSERT_FALSE(notKept);
    EXPECT_EQ(notKept.error().missing, std::vector<std::string>{addressOf(junk)});
    // Parts sent again for content already cached are not decoded again.
    const auto insertions = cacheStats()["insertions"].get<int>();
    ASSERT_TRUE(svc_->batch(body(scene()), both()));
    EXPECT_EQ(cacheStats()["insertions"].get<int>(), insertions);
}

TEST_F(BatchContentTest, UploadsWithTheSameBytesServeTheirAddress) {
    ASSERT_TRUE(svc_->addModel(model_, "cesium"));
    ASSERT_TRUE(svc_->addPattern(pattern_, "mine"));
    auto r = svc_->batch(body(scene()));
    ASSERT_TRUE(r) << r.error().message;
    renderAll(*r);
    EXPECT_EQ(cacheStats()["entries"], 0);

    // Also after a restart (the digest is recomputed from the stored bytes).
    open();
    r = svc_->batch(body(scene()));
    ASSERT_TRUE(r) << r.error().message;
}

TEST_F(BatchContentTest, ASmallCacheForgetsLeastRecentlyUsedAndFreesTheGpuCopies) {
    ServerLimits limits;
    limits.contentCacheBytes = 64 * 1024; // the pattern fits, CesiumMan (≈ 1.5 MB decoded) does not
    open(limits);
    auto r = svc_->batch(body(scene()), both());
    ASSERT_TRUE(r) << r.error().message;
    renderAll(*r); // the request holds what it decoded, cached or not
    EXPECT_EQ(cacheStats()["entries"], 1);
    EXPECT_EQ(cacheStats()["evictions"], 1);
    EXPECT_EQ(fake_->forgottenModels, 1);
    auto again = svc_->batch(body(scene()));
    ASSERT_FALSE(again);
    EXPECT_EQ(again.error().missing, std::vector<std::string>{addressOf(model_)});

    // Newer patterns push the oldest out.
    const auto before = fake_->forgottenPatterns;
    for (int k = 0; k < 8; ++k) {
        const auto png = patternPng(64, 40 + k);
        json doc = scene();
        doc["model"] = "builtin:default";
        doc["placements"][0]["joint"] = "forearm.l";
        doc["placements"][0]["axis"] = "x";
        doc["patterns"]["mine"] = addressOf(png);
        auto p = svc_->batch(body(doc), {{addressOf(png), png}});
        ASSERT_TRUE(p) << p.error().message;
    }
    EXPECT_LE(cacheStats()["bytes"].get<std::size_t>(), limits.contentCacheBytes);
    EXPECT_GT(fake_->forgottenPatterns, before);
    auto old = svc_->batch(body(scene()), {{addressOf(model_), model_}});
    ASSERT_FALSE(old);
    EXPECT_EQ(old.error().missing, std::vector<std::string>{addressOf(pattern_)}); // pushed out
}

TEST_F(BatchContentTest, StoredScenesCannotNameContentByAddress) {
    json doc = scene();
    doc["model"] = "builtin:default";
    doc["placements"][0]["joint"] = "forearm.l";
    doc["placements"][0]["axis"] = "x";
    ASSERT_TRUE(svc_->batch(body(doc), both())); // cached now, still not for stored scenes
    auto r = svc_->createScene(doc);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::NotFound);
    EXPECT_NE(r.error().message.find("POST /render"), std::string::npos) << r.error().message;
}

// The image-based light of a batch (render.environment, issue #26) by content address, as a farm
// sends a scene file's .hdr: listed when lacking, decoded from its part, cached, served by an
// upload with the same bytes; bytes that are no environment and role clashes are refused.
TEST_F(BatchContentTest, AnEnvironmentByAddressIsListedSentCachedAndMatchedToUploads) {
    const float sky[3] = {0.25f, 0.5f, 1.0f};
    const std::string text = radianceHdr(16, 8, sky, sky);
    const std::vector<std::uint8_t> hdr(text.begin(), text.end());
    json doc = scene();
    doc["render"]["shading"] = "pbr";
    doc["render"]["environment"] = addressOf(hdr);

    auto first = svc_->batch(body(doc), both());
    ASSERT_FALSE(first);
    EXPECT_EQ(first.error().code, ErrorCode::MissingContent);
    EXPECT_EQ(first.error().missing, std::vector<std::string>{addressOf(hdr)});
    EXPECT_EQ(first.error().field, "/scene/render/environment");

    Parts parts = both();
    parts[addressOf(hdr)] = hdr;
    auto sent = svc_->batch(body(doc), parts);
    ASSERT_TRUE(sent) << sent.error().message;
    renderAll(*sent);
    auto env = fake_->lastEnvironment();
    ASSERT_TRUE(env);
    EXPECT_EQ(env->width, 16);
    EXPECT_EQ(env->height, 8);
    EXPECT_NEAR(env->at(3, 2).z, 1.0f, 0.01f);
    EXPECT_NEAR(env->at(3, 2).x, 0.25f, 0.01f);

    // Again without bytes: from the cache, the same decoded image.
    auto again = svc_->batch(body(doc));
    ASSERT_TRUE(again) << again.error().message;
    renderAll(*again);
    EXPECT_EQ(fake_->lastEnvironment(), env);

    // Legacy frames light nothing by it (and decode nothing).
    json legacy = doc;
    legacy["render"]["shading"] = "legacy";
    auto l = svc_->batch(body(legacy));
    ASSERT_TRUE(l) << l.error().message;
    renderAll(*l);
    EXPECT_FALSE(fake_->lastEnvironment());

    // After a restart (empty cache) an upload with the same bytes serves the address.
    open();
    ASSERT_FALSE(svc_->batch(body(doc), both()));
    ASSERT_TRUE(svc_->addEnvironment(hdr, "sky"));
    auto up = svc_->batch(body(doc), both());
    ASSERT_TRUE(up) << up.error().message;
    renderAll(*up);
    ASSERT_TRUE(fake_->lastEnvironment());
    EXPECT_EQ(fake_->lastEnvironment()->width, 16);

    // Bytes that are no environment, under their own (correct) address.
    const auto png = patternPng(8, 8);
    json notEnv = doc;
    notEnv["render"]["environment"] = addressOf(png);
    Parts withPng = both();
    withPng[addressOf(png)] = png;
    auto bad = svc_->batch(body(notEnv), withPng);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().code, ErrorCode::Parse) << bad.error().message;
    EXPECT_NE(bad.error().message.find("/render/environment"), std::string::npos) << bad.error().message;

    // One address as a pattern and as the environment.
    json clash = doc;
    clash["patterns"]["mine"] = addressOf(hdr);
    auto c = svc_->batch(body(clash), parts);
    ASSERT_FALSE(c);
    EXPECT_EQ(c.error().code, ErrorCode::InvalidArgument);
    EXPECT_NE(c.error().message.find("environment"), std::string::npos) << c.error().message;
}

// --- ContentCache --------------------------------------------------------------------------------

std::shared_ptr<const PatternImage> image(int side) { return makePatternImage(HeightImage(side, side)); }

TEST(ContentCacheTest, KeepsTheMostRecentlyUsedWithinItsBudget) {
    ContentCache cache(300);
    EXPECT_FALSE(cache.find("a").pattern);
    EXPECT_TRUE(cache.put("a", {nullptr, image(1)}, 100).empty());
    EXPECT_TRUE(cache.put("b", {nullptr, image(1)}, 100).empty());
    EXPECT_TRUE(cache.put("c", {nullptr, image(1)}, 100).empty());
    EXPECT_TRUE(cache.find("a").pattern); // a is now the most recent: b is the oldest
    auto gone = cache.put("d", {nullptr, image(2)}, 100);
    ASSERT_EQ(gone.size(), 1u);
    EXPECT_FALSE(cache.find("b").pattern);
    EXPECT_TRUE(cache.find("a").pattern && cache.find("c").pattern && cache.find("d").pattern);
    // Larger than the whole budget: handed back, nothing else lost.
    gone = cache.put("huge", {nullptr, image(1)}, 301);
    ASSERT_EQ(gone.size(), 1u);
    EXPECT_FALSE(cache.find("huge").pattern);
    EXPECT_TRUE(cache.find("a").pattern);
    // Replacing an entry hands back the old item and keeps the bytes right.
    gone = cache.put("a", {nullptr, image(3)}, 50);
    ASSERT_EQ(gone.size(), 1u);
    const auto s = cache.stats();
    EXPECT_EQ(s.entries, 3u);
    EXPECT_EQ(s.bytes, 250u);
    EXPECT_EQ(s.budget, 300u);
    EXPECT_EQ(s.evictions, 2u);
    EXPECT_EQ(s.insertions, 5u);
    EXPECT_GE(s.misses, 3u);
    // Budget 0 keeps nothing.
    ContentCache none(0);
    EXPECT_EQ(none.put("a", {nullptr, image(1)}, 1).size(), 1u);
    EXPECT_EQ(none.stats().entries, 0u);
}

TEST(ContentCacheTest, EstimatesDecodedSizes) {
    EXPECT_GE(ContentCache::approxBytes(*image(64)), 64u * 64u * sizeof(float));
    Model m;
    m.parts.resize(1);
    m.parts[0].positions.resize(1000);
    m.parts[0].indices.resize(3000);
    EXPECT_GE(ContentCache::approxBytes(m), 1000u * 12u + 3000u * 4u);
}

} // namespace
} // namespace dermis::test
