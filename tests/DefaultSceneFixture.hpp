// Test fixture: the built-in default scene (models/default.scene.json with its character and
// pattern images) loaded once per suite, for the pure suites that inspect it (InspectTest,
// LintTest, SweepTest). Derive from DefaultSceneTest; `loaded_` is valid in every test (a load
// failure fails SetUp). Read only: tests copy the scene before changing it.
#pragma once

#include "BuildPaths.hpp"
#include "io/scene_files.hpp"

#include <gtest/gtest.h>

#include <string>

namespace dermis::test {

inline const std::string kDefaultScene =
    std::string(dermis::build::sourceDir()) + "/models/default.scene.json";

class DefaultSceneTest : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        auto l = loadSceneFile(kDefaultScene);
        ASSERT_TRUE(l) << l.error().message;
        loaded_ = new LoadedScene(std::move(*l));
    }
    static void TearDownTestSuite() {
        delete loaded_;
        loaded_ = nullptr;
    }
    void SetUp() override { ASSERT_NE(loaded_, nullptr); }
    static inline LoadedScene* loaded_ = nullptr;
};

} // namespace dermis::test
