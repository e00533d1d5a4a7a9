// Test helper: a GL suite's one renderer — created once per suite on the backend the suite asks
// for ($DERMIS_TEST_GL, GlTestBackend.hpp), shared by its tests, destroyed after the last; it checks
// every draw's buffer bindings (RendererOptions::checkBindings). A
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
        RendererOptions options;
        options.checkBindings = true; // every draw of every GL suite (DrawBindingsGLTest)
        auto r = Renderer::create(requestedBackend(), options);
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
