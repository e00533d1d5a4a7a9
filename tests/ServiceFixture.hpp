// Test helper — a Service on a temporary data folder with the source tree's built-in content and
// a CPU fake renderer (FakeRenderer.hpp), plus small helpers for its answers. Used by the
// Service*Test suites (pure: no GL, no HTTP).
#pragma once

#include "BuildPaths.hpp"
#include "FakeRenderer.hpp"
#include "TestFiles.hpp"
#include "service/service.hpp"

#include "io/frame_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace dermis::test {

using json = nlohmann::json;

inline const std::string kSource = dermis::build::sourceDir();

/// Width and height from a PNG's IHDR chunk.
inline std::pair<int, int> pngSize(const std::vector<std::uint8_t>& b) {
    if (b.size() < 24 || b[0] != 0x89 || b[1] != 'P') return {0, 0};
    auto be = [&](std::size_t o) { return int(b[o]) << 24 | int(b[o + 1]) << 16 | int(b[o + 2]) << 8 | int(b[o + 3]); };
    return {be(16), be(20)};
}

/// An 8-bit grey PNG pattern of w×h.
inline std::vector<std::uint8_t> patternPng(int w, int h) {
    Image8 img;
    img.width = w;
    img.height = h;
    img.rgba.resize(static_cast<std::size_t>(w) * h * 4);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            std::uint8_t* p = &img.rgba[(static_cast<std::size_t>(j) * w + i) * 4];
            p[0] = p[1] = p[2] = static_cast<std::uint8_t>((i * 255) / std::max(1, w - 1));
            p[3] = 255;
        }
    return *encodePng(img, false);
}

/// A live event's "type" field (its JSON data's).
inline std::string typeOf(const SceneEvent& e) {
    return json::parse(e.data).value("type", "");
}

class ServiceFixture : public ::testing::Test {
protected:
    void SetUp() override { open(); }

    void open(const ServerLimits& limits = {}, const std::string& content = kSource) {
        svc_.reset();
        auto fake = std::make_unique<FakeRenderer>();
        fake_ = fake.get();
        ServiceConfig config;
        config.dataDir = dir_ / "data";
        config.contentDir = content;
        config.limits = limits;
        auto s = Service::open(config, std::move(fake));
        ASSERT_TRUE(s) << s.error().message;
        svc_ = std::move(*s);
    }

    std::string defaultScene() {
        auto r = svc_->createScene({{"default_patterns", true}});
        EXPECT_TRUE(r) << r.error().message;
        return r ? (*r)["id"].get<std::string>() : "";
    }

    std::uint64_t revisionOf(const std::string& id) { return (*svc_->getScene(id))["revision"].get<std::uint64_t>(); }

    TempDir dir_;
    std::unique_ptr<Service> svc_;
    FakeRenderer* fake_ = nullptr;
};

} // namespace dermis::test
