// ServiceTest — the server's state and operations without HTTP and without GL: a Service on a
// temporary data folder with the source tree's built-in content and a CPU fake renderer
// (FakeRenderer.hpp). Edits, revisions and events, failed edits changing nothing, limits, frame
// parameters, height maps, batches, reopening, locking (a render in flight blocks no reader and no
// upload), event back-pressure (resync), and opening with broken content.
#include "GltfTestBuilder.hpp"
#include "ServiceFixture.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <future>
#include <set>

using namespace dermis;
using namespace dermis::test;
using json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

class ServiceTest : public ServiceFixture {};

TEST_F(ServiceTest, OpensWithTheBuiltinContentAndTheInjectedRenderer) {
    EXPECT_EQ(svc_->info()["backend"], "fake");
    bool hasDefault = false;
    const json models = svc_->listModels(), patternList = svc_->listPatterns();
    for (const json& m : models["models"]) hasDefault = hasDefault || m["id"] == "builtin:default";
    EXPECT_TRUE(hasDefault);
    std::set<std::string> patterns;
    for (const json& p : patternList["patterns"]) {
        patterns.insert(p["id"].get<std::string>());
        EXPECT_TRUE(p["builtin"].get<bool>());
        EXPECT_GT(p["width"].get<int>(), 0);
    }
    EXPECT_GE(patterns.size(), 9u);
    EXPECT_TRUE(patterns.count("crease"));
    EXPECT_TRUE(svc_->listScenes()["scenes"].empty());
}

TEST_F(ServiceTest, CreatesASceneFromTheDefaultPatternSet) {
    const json set = json::parse(readBytes(kSource + "/models/default.scene.json"));
    const std::string id = defaultScene();
    auto s = svc_->getScene(id);
    ASSERT_TRUE(s);
    EXPECT_EQ((*s)["revision"], 1);
    EXPECT_EQ((*s)["scene"]["placements"].size(), set["placements"].size());
    EXPECT_EQ(svc_->listScenes()["scenes"].size(), 1u);
    // Only for the default character.
    auto other = svc_->createScene({{"default_patterns", true}, {"model", "m_0000000000000000"}});
    ASSERT_FALSE(other);
    EXPECT_EQ(other.error().field, "/default_patterns");
}

TEST_F(ServiceTest, EditsBumpTheRevisionAndAreAnnouncedInOrder) {
    const std::string id = defaultScene();
    auto sub = svc_->subscribe(id);
    ASSERT_TRUE(sub);
    EXPECT_EQ(typeOf(*(*sub)->next(1000)), "hello");

    auto added = svc_->addPlacement(id, {{"pattern", "crease"}, {"joint", "forearm.l"}, {"id", "extra"}});
    ASSERT_TRUE(added) << added.error().message;
    EXPECT_EQ((*added)["revision"], 2);
    auto patched = svc_->patchPlacement(id, "extra", {{"h", 0.5}, {"center", {0.4, 0.6}}});
    ASSERT_TRUE(patched) << patched.error().message;
    EXPECT_EQ((*patched)["revision"], 3);
    json order = json::array();
    for (const json& p : (*patched)["scene"]["placements"]) order.insert(order.begin(), p["id"]);
    ASSERT_TRUE(svc_->reorderPlacements(id, order));
    ASSERT_TRUE(svc_->patchPose(id, {{"time", 0.5}}));
    ASSERT_TRUE(svc_->deletePlacement(id, "extra"));
    EXPECT_EQ(revisionOf(id), 6u);
    auto scene = svc_->getScene(id);
    EXPECT_EQ((*scene)["scene"]["pose"]["time"], 0.5);
    EXPECT_EQ((*scene)["scene"]["placements"][0]["id"], order[1]);

    std::vector<std::string> types;
    while (auto e = (*sub)->next(50)) types.push_back(typeOf(*e));
    EXPECT_EQ(types, (std::vector<std::string>{"placement_added", "placement_updated", "placements_reordered",
                                               "pose", "placement_deleted"}));
    svc_->unsubscribe(id, *sub);
}

TEST_F(ServiceTest, AFailedEditChangesNothingAndAnnouncesNothing) {
    const std::string id = defaultScene();
    const json before = *svc_->getScene(id);
    auto sub = svc_->subscribe(id);
    ASSERT_TRUE(sub);
    (*sub)->next(1000); // hello
    struct Case {
        Result<json> result;
        std::string field;
    };
    std::vector<Case> cases;
    cases.push_back({svc_->patchPlacement(id, "stomach", {{"theta_max", 0}}), "/placements/0/theta_max"});
    cases.push_back({svc_->patchPlacement(id, "stomach", {{"id", "renamed"}}), "/id"});
    cases.push_back({svc_->patchPlacement(id, "nope", {{"h", 1}}), "pid"});
    cases.push_back({svc_->deletePlacement(id, "nope"), "pid"});
    cases.push_back({svc_->addPlacement(id, {{"pattern", "no_such_pattern"}, {"joint", "spine_02"}}),
                     "/placements/18/pattern"});
    cases.push_back({svc_->addPlacement(id, {{"pattern", "crease"}, {"joint", "no_such_joint"}}),
                     "/placements/18/joint"});
    cases.push_back({svc_->reorderPlacements(id, json::array({"stomach"})), ""});
    cases.push_back({svc_->patchPose(id, {{"animation", "no_such_clip"}}), "/pose/animation"});
    json otherModel = before["scene"];
    otherModel["model"] = "m_0123456789abcdef";
    cases.push_back({svc_->replaceScene(id, otherModel), "/model"});
    cases.push_back({svc_->addPlacement("s_0123456789abcdef", {{"pattern", "crease"}}), "id"});
    for (std::size_t k = 0; k < cases.size(); ++k) {
        ASSERT_FALSE(cases[k].result) << "case " << k;
        EXPECT_EQ(cases[k].result.error().field, cases[k].field) << "case " << k << ": " << cases[k].result.error().message;
        EXPECT_NE(cases[k].result.error().message.find("dermis::"), std::string::npos) << "case " << k;
    }
    EXPECT_EQ(*svc_->getScene(id), before);
    EXPECT_FALSE((*sub)->next(50)) << "a failed edit must not be announced";
    svc_->unsubscribe(id, *sub);
}

TEST_F(ServiceTest, LimitsAreEnforced) {
    ServerLimits limits;
    limits.maxPlacements = 3;
    limits.maxMapSide = 512;
    limits.maxRenderSide = 256;
    open(limits);
    auto many = svc_->createScene({{"default_patterns", true}});
    ASSERT_FALSE(many);
    EXPECT_EQ(many.error().code, ErrorCode::TooLarge);
    EXPECT_EQ(many.error().field, "/placements");
    json small = {{"format", "dermis.scene/1"}, {"model", "builtin:default"}, {"heightmap", {{"size", {1024, 256}}}}};
    auto big = svc_->createScene(small);
    ASSERT_FALSE(big);
    EXPECT_EQ(big.error().code, ErrorCode::TooLarge);
    EXPECT_EQ(big.error().field, "/heightmap/size/0");
    small["heightmap"]["size"] = {256, 256};
    small["render"] = {{"size", {300, 200}}};
    auto wide = svc_->createScene(small);
    ASSERT_FALSE(wide);
    EXPECT_EQ(wide.error().field, "/render/size/0");
    small["render"]["size"] = {128, 128};
    auto ok = svc_->createScene(small);
    ASSERT_TRUE(ok) << ok.error().message;
    FrameParams p;
    p.width = 300;
    auto f = svc_->frame((*ok)["id"], p);
    ASSERT_FALSE(f);
    EXPECT_EQ(f.error().code, ErrorCode::TooLarge);
    EXPECT_EQ(f.error().field, "width");
}

TEST_F(ServiceTest, FrameParametersOverrideTheSceneAndAreCheckedOnce) {
    const std::string id = defaultScene();
    FrameParams p;
    p.width = 64;
    p.height = 48;
    p.yaw = 30.0;
    auto f = svc_->frame(id, p);
    ASSERT_TRUE(f) << f.error().message;
    EXPECT_EQ(pngSize(f->bytes), (std::pair<int, int>{64, 48}));
    EXPECT_EQ(f->contentType, "image/png");
    EXPECT_EQ(f->backend, "fake");
    EXPECT_EQ(fake_->lastSettings().size, (std::array<int, 2>{64, 48}));
    EXPECT_EQ(fake_->lastSettings().camera.yaw, 30.0);
    EXPECT_EQ(fake_->lastSettings().camera.pitch, 10.0); // the document's
    // The document is not changed by a frame's overrides.
    EXPECT_EQ((*svc_->getScene(id))["scene"]["render"]["size"], json({1024, 1024}));

    const struct {
        FrameParams p;
        std::string field;
    } bad[] = {
        {[] { FrameParams q; q.width = 0; return q; }(), "width"},
        {[] { FrameParams q; q.height = 100000; return q; }(), "height"},
        {[] { FrameParams q; q.msaa = 3; return q; }(), "msaa"},
        {[] { FrameParams q; q.pitch = 200.0; return q; }(), "pitch"},
        {[] { FrameParams q; q.distance = -1.0; return q; }(), "distance"},
        {[] { FrameParams q; q.time = -1.0; return q; }(), "time"},
        {[] { FrameParams q; q.format = "gif"; return q; }(), "format"},
    };
    const int framesBefore = fake_->frames();
    for (const auto& b : bad) {
        auto r = svc_->frame(id, b.p);
        ASSERT_FALSE(r) << b.field;
        EXPECT_EQ(r.error().field, b.field) << r.error().message;
    }
    EXPECT_EQ(fake_->frames(), framesBefore) << "invalid parameters never reach the renderer";
    auto missing = svc_->frame("s_0123456789abcdef", {});
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().code, ErrorCode::NotFound);
}

TEST_F(ServiceTest, PoseEditsChangeTheFrame) {
    const std::string id = defaultScene();
    FrameParams p;
    p.width = p.height = 16;
    auto a = svc_->frame(id, p);
    ASSERT_TRUE(svc_->patchPose(id, {{"time", 0.3}}));
    auto b = svc_->frame(id, p);
    ASSERT_TRUE(a && b);
    EXPECT_NE(a->bytes, b->bytes);
}

TEST_F(ServiceTest, HeightMapsInEveryFormat) {
    json doc = {{"format", "dermis.scene/1"}, {"model", "builtin:default"}, {"heightmap", {{"size", {64, 32}}}}};
    doc["placements"] = json::parse(readBytes(kSource + "/models/default.scene.json"))["placements"];
    doc["pose"] = {{"animation", "squat"}, {"time", 1.25}};
    auto created = svc_->createScene(doc);
    ASSERT_TRUE(created) << created.error().message;
    const std::string id = (*created)["id"];
    auto f32 = svc_->heightmap(id, "bump", "f32");
    ASSERT_TRUE(f32) << f32.error().message;
    EXPECT_EQ(f32->bytes.size(), 64u * 32u * 4u);
    EXPECT_EQ(f32->contentType, "application/octet-stream");
    auto png = svc_->heightmap(id, "displacement", "png16");
    ASSERT_TRUE(png) << png.error().message;
    EXPECT_EQ(pngSize(png->bytes), (std::pair<int, int>{64, 32}));
    auto exr = svc_->heightmap(id, "bump", "exr");
    ASSERT_TRUE(exr) << exr.error().message;
    ASSERT_GE(exr->bytes.size(), 4u);
    EXPECT_EQ(exr->bytes[0], 0x76); // OpenEXR magic
    auto normal = svc_->heightmap(id, "normal", "png");
    ASSERT_TRUE(normal) << normal.error().message;
    EXPECT_EQ(pngSize(normal->bytes), (std::pair<int, int>{64, 32}));
    EXPECT_EQ(fake_->bakes(), 4);
    // The data folder holds no temp files afterwards.
    for (const auto& e : fs::recursive_directory_iterator(dir_ / "data"))
        EXPECT_EQ(e.path().filename().string().find("tmp"), std::string::npos) << e.path();

    auto unknown = svc_->heightmap(id, "albedo", "png16");
    ASSERT_FALSE(unknown);
    EXPECT_EQ(unknown.error().field, "map");
    auto format = svc_->heightmap(id, "bump", "jpeg");
    ASSERT_FALSE(format);
    EXPECT_EQ(format.error().field, "format");
}

TEST_F(ServiceTest, BatchesAreValidatedWholeAndRenderEveryFrame) {
    const json scene = {{"format", "dermis.scene/1"}, {"model", "builtin:default"}, {"render", {{"size", {32, 32}}}}};
    auto job = svc_->batch({{"scene", scene}, {"frames", {{{"time", 0.1}}, {{"pose", {{"time", 0.2}}}}}}});
    ASSERT_TRUE(job) << job.error().message;
    ASSERT_EQ(job->frames, 2u);
    for (std::size_t k = 0; k < 2; ++k) {
        auto img = job->render(k);
        ASSERT_TRUE(img) << img.error().message;
        EXPECT_EQ(pngSize(img->bytes), (std::pair<int, int>{32, 32}));
    }
    const struct {
        json body;
        std::string field;
    } bad[] = {
        {{{"frames", {{{"time", 0}}}}}, "/scene"},
        {{{"scene", scene}, {"frames", json::array()}}, "/frames"},
        {{{"scene", scene}, {"frames", {{{"time", -1}}}}}, "/frames/0/time"},
        {{{"scene", scene}, {"frames", {json::object()}}}, "/frames/0"},
        {{{"scene", scene}, {"frames", {{{"pose", {{"animation", "nope"}}}}}}}, "/frames/0/pose/animation"},
        {{{"scene", {{"format", "dermis.scene/1"}, {"model", "builtin:nope"}}}, {"frames", {{{"time", 0}}}}}, "/scene/model"},
        {{{"scene", scene}, {"frames", {{{"time", 0}}}}, {"format", "gif"}}, "/format"},
    };
    for (const auto& b : bad) {
        auto r = svc_->batch(b.body);
        ASSERT_FALSE(r) << b.body.dump();
        EXPECT_EQ(r.error().field, b.field) << r.error().message;
    }
}

TEST_F(ServiceTest, ARenderInFlightBlocksNoReaderNoUploadAndNoEdit) {
    const std::string id = defaultScene();
    fake_->block();
    FrameParams p;
    p.width = p.height = 16;
    auto render = std::async(std::launch::async, [&] { return svc_->frame(id, p); });
    ASSERT_TRUE(fake_->waitUntilEntered(30000)) << "the render never reached the renderer";
    // Everything else goes on while the render waits in the renderer.
    auto others = std::async(std::launch::async, [&] {
        auto added = svc_->addPattern(patternPng(8, 8), "bumps");
        if (!added) return added.error().message;
        const std::string pid = (*added)["id"];
        if (svc_->listPatterns()["patterns"].size() < 10) return std::string("list");
        if (!svc_->getScene(id)) return std::string("get");
        if (!svc_->patchPose(id, {{"time", 0.75}})) return std::string("edit");
        if (auto im = svc_->patternImage(pid, 16); !im) return im.error().message;
        if (auto d = svc_->deletePattern(pid); !d) return d.error().message;
        return std::string("ok");
    });
    ASSERT_EQ(others.wait_for(std::chrono::seconds(60)), std::future_status::ready)
        << "uploads, reads or edits waited for a render";
    EXPECT_EQ(others.get(), "ok");
    fake_->release();
    auto frame = render.get();
    ASSERT_TRUE(frame) << frame.error().message;
}

TEST_F(ServiceTest, DeletingAPatternInUseIsAConflictAndUnusedOnesGo) {
    auto added = svc_->addPattern(patternPng(16, 8), "ridge");
    ASSERT_TRUE(added) << added.error().message;
    const std::string pid = (*added)["id"];
    EXPECT_EQ((*added)["width"], 16);
    auto scene = svc_->createScene({{"format", "dermis.scene/1"}, {"model", "builtin:default"},
                                    {"placements", {{{"pattern", pid}, {"joint", "spine_02"}}}}});
    ASSERT_TRUE(scene) << scene.error().message;
    auto busy = svc_->deletePattern(pid);
    ASSERT_FALSE(busy);
    EXPECT_EQ(busy.error().code, ErrorCode::Conflict);
    ASSERT_TRUE(svc_->deleteScene((*scene)["id"]));
    ASSERT_TRUE(svc_->deletePattern(pid));
    EXPECT_EQ(svc_->patternImage(pid, 16).error().code, ErrorCode::NotFound);
    EXPECT_EQ(svc_->deletePattern("crease").error().code, ErrorCode::Conflict); // built-in
    EXPECT_EQ(svc_->addPattern({1, 2, 3}, "junk").error().code, ErrorCode::Parse);
}

// A pattern whose header declares sides over the limit is refused from the header: nothing is
// decoded (a small flat PNG declaring 8192² cost the whole decode before the side limit).
TEST_F(ServiceTest, OversizedPatternIsRefusedFromItsHeader) {
    std::vector<std::uint8_t> png = patternPng(8, 8);
    ASSERT_GE(png.size(), 24u);
    for (int k = 0; k < 2; ++k) { // IHDR width and height (big-endian) at bytes 16 and 20: 8192
        png[16 + 4 * k] = 0, png[17 + 4 * k] = 0, png[18 + 4 * k] = 0x20, png[19 + 4 * k] = 0;
    }
    auto refused = svc_->addPattern(png, "huge");
    ASSERT_FALSE(refused);
    // Decoding these bytes would fail as corrupt (the IHDR CRC and the data no longer match): the
    // TooLarge answer naming the declared size shows the header was checked first.
    EXPECT_EQ(refused.error().code, ErrorCode::TooLarge) << refused.error().message;
    EXPECT_NE(refused.error().message.find("8192x8192"), std::string::npos) << refused.error().message;
}

TEST_F(ServiceTest, ReopeningRestoresScenesAndUploads) {
    const std::string id = defaultScene();
    ASSERT_TRUE(svc_->patchPose(id, {{"time", 0.5}}));
    auto added = svc_->addPattern(patternPng(8, 8), "dots");
    ASSERT_TRUE(added);
    const json before = *svc_->getScene(id);
    open();
    EXPECT_TRUE(svc_->warnings().empty());
    EXPECT_EQ(*svc_->getScene(id), before);
    EXPECT_TRUE(svc_->patternImage((*added)["id"], 8));
}

TEST_F(ServiceTest, StoredModelsAreReloadedUnderTheLimits) {
    // A model of one mesh instanced by 16 nodes (16000 triangles) is taken under a limit of
    // 20000; reopened under 10000 it is skipped with a warning, checked from its declared sizes.
    ServerLimits generous;
    generous.maxTriangles = 20000;
    open(generous);
    auto added = svc_->addModel(gltf::instancedZeroMesh(3000, 16), "instanced");
    ASSERT_TRUE(added) << added.error().message;
    EXPECT_EQ((*added)["triangles"], 16000u);
    const std::string id = (*added)["id"];
    ServerLimits low;
    low.maxTriangles = 10000;
    open(low);
    EXPECT_FALSE(svc_->getModel(id));
    ASSERT_EQ(svc_->warnings().size(), 1u);
    EXPECT_NE(svc_->warnings()[0].find("max_triangles 10000"), std::string::npos) << svc_->warnings()[0];
    open(generous);
    EXPECT_TRUE(svc_->getModel(id));
}

TEST_F(ServiceTest, ModelsDescribeJointsParentsAndUvLayout) {
    auto m = svc_->getModel("builtin:default");
    ASSERT_TRUE(m) << m.error().message;
    std::set<std::string> names;
    for (const json& j : (*m)["joints"]) names.insert(j["name"].get<std::string>());
    int roots = 0;
    for (const json& j : (*m)["joints"]) {
        if (j["parent"].is_null()) ++roots;
        else EXPECT_TRUE(names.count(j["parent"].get<std::string>())) << j.dump();
    }
    EXPECT_EQ(roots, 1);
    auto uv = svc_->uvLayout("builtin:default");
    ASSERT_TRUE(uv);
    EXPECT_GT((*uv)["edge_count"].get<int>(), 100);
    EXPECT_EQ((*uv)["edges"].size(), 4 * (*uv)["edge_count"].get<std::size_t>());
    auto png = svc_->uvLayoutPng("builtin:default", 64);
    ASSERT_TRUE(png);
    EXPECT_EQ(pngSize(png->bytes), (std::pair<int, int>{64, 64}));
    EXPECT_EQ(svc_->uvLayoutPng("builtin:default", 8).error().field, "size");
    EXPECT_EQ(svc_->getModel("m_0123456789abcdef").error().code, ErrorCode::NotFound);
    EXPECT_EQ(svc_->deleteModel("builtin:default").error().code, ErrorCode::Conflict);
}

TEST(SubscriptionTest, AReaderFarBehindGetsOneResyncInsteadOfUnboundedEvents) {
    Subscription s("s_1");
    for (int k = 0; k < 3 * static_cast<int>(Subscription::kMaxQueued); ++k)
        s.push({"change", "{\"type\":\"pose\",\"n\":" + std::to_string(k) + "}"});
    std::vector<SceneEvent> got;
    while (auto e = s.next(0)) got.push_back(*e);
    ASSERT_FALSE(got.empty());
    EXPECT_LE(got.size(), Subscription::kMaxQueued);
    EXPECT_EQ(typeOf(got.back()), "resync");
    EXPECT_EQ(got.back().name, "resync");
    EXPECT_NE(got.back().data.find("\"scene\":\"s_1\""), std::string::npos);
    int resyncs = 0;
    for (const SceneEvent& e : got) resyncs += typeOf(e) == "resync";
    EXPECT_EQ(resyncs, 1);
    // Once the reader took the resync, events flow again.
    s.push({"change", "{\"type\":\"pose\"}"});
    auto next = s.next(0);
    ASSERT_TRUE(next);
    EXPECT_EQ(typeOf(*next), "pose");
}

class ServiceContentTest : public ::testing::Test {
protected:
    /// A content folder with the source tree's patterns and character and `setText` as the
    /// default pattern set (none when empty).
    std::string content(const std::string& setText) {
        const fs::path c = dir_ / "content";
        fs::create_directories(c / "models");
        fs::create_directory_symlink(kSource + "/patterns", c / "patterns");
        fs::create_symlink(kSource + "/models/default.glb", c / "models/default.glb");
        if (!setText.empty()) writeText((c / "models/default.scene.json").string(), setText);
        return c.string();
    }
    Result<std::unique_ptr<Service>> open(const std::string& contentDir) {
        ServiceConfig config;
        config.dataDir = dir_ / "data";
        config.contentDir = contentDir;
        return Service::open(config, std::make_unique<FakeRenderer>());
    }
    TempDir dir_;
};

TEST_F(ServiceContentTest, AnUnreadableDefaultPatternSetIsReportedNotIgnored) {
    auto broken = open(content("{ not json"));
    ASSERT_FALSE(broken);
    EXPECT_NE(broken.error().message.find("default.scene.json"), std::string::npos) << broken.error().message;
}

TEST_F(ServiceContentTest, AnInvalidDefaultPatternSetIsReported) {
    auto invalid = open(content(R"({"format": "dermis.scene/1", "model": "builtin:default", "placements": [{"pattern": "crease", "joint": "nope"}]})"));
    ASSERT_FALSE(invalid);
    EXPECT_NE(invalid.error().message.find("default.scene.json"), std::string::npos);
    EXPECT_NE(invalid.error().message.find("nope"), std::string::npos) << invalid.error().message;
}

TEST_F(ServiceContentTest, WithoutADefaultPatternSetScenesStillWork) {
    auto svc = open(content(""));
    ASSERT_TRUE(svc) << svc.error().message;
    auto r = (*svc)->createScene({{"default_patterns", true}});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::Unavailable);
    EXPECT_TRUE((*svc)->createScene({{"format", "dermis.scene/1"}, {"model", "builtin:default"}}));
}

TEST_F(ServiceContentTest, MissingContentFailsToOpen) {
    // A content folder that is not there: the service does not start on nothing, and says what it
    // looked for and where (the built-in character under the given folder).
    const std::string nowhere = dir_ / "nowhere";
    auto svc = open(nowhere);
    ASSERT_FALSE(svc);
    EXPECT_EQ(svc.error().code, ErrorCode::NotFound) << svc.error().message;
    EXPECT_NE(svc.error().message.find(nowhere + "/models/default.glb"), std::string::npos)
        << svc.error().message;
}

} // namespace
