// Test helper: a GL suite's one renderer — created once per suite on the backend the suite asks
// for ($DERMIS_TEST_GL, GlTestBackend.hpp), shared by its tests, destroyed after the last. A
// backend that cannot start fails every test of the suite with the reason (nothing is skipped).
#pragma once

#include "gl/renderer.hpp"

#include "GlTestBackend.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace dermis::test {

class RendererSuite : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        auto r = Renderer::create(requestedBackend());
        if (!r) {
            createError_ = r.error().message;
            return;
        }
        renderer_ = std::move(*r);
    }
    static void TearDownTestSuite() { renderer_.reset(); }
    void SetUp() override {
        ASSERT_TRUE(renderer_) << "no GL context for backend " << toString(requestedBackend()) << ": "
                               << createError_;
    }
    static Renderer& gl() { return *renderer_; }

    inline static std::unique_ptr<Renderer> renderer_;
    inline static std::string createError_;
};

} // namespace dermis::test
