// Frame ranges "A:B:STEP" and farm shards "I/N" / "auto/N" (core/frame_range): counts, the
// interleaved split covering every frame exactly once, the engines' task-index variables, and one
// case per kind of bad input naming its option. Pure: no files, no environment.
#include "core/frame_range.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <set>
#include <string>

using dermis::FrameRange;
using dermis::Shard;

namespace {

dermis::EnvLookup envOf(std::map<std::string, std::string> vars) {
    return [vars = std::move(vars)](const char* name) -> const char* {
        auto it = vars.find(name);
        return it == vars.end() ? nullptr : it->second.c_str();
    };
}

} // namespace

TEST(FrameRangeTest, CountsIncludeTheEndWithinRounding) {
    auto r = dermis::parseFrameRange("0:1:0.1");
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->count, 11);
    EXPECT_DOUBLE_EQ(r->time(10), 1.0);
    EXPECT_EQ(dermis::parseFrameRange("0:2.5:0.04")->count, 63);
    EXPECT_EQ(dermis::parseFrameRange("0.5:0.5:1")->count, 1);
    EXPECT_EQ(dermis::parseFrameRange("0:0.95:0.1")->count, 10);
    EXPECT_DOUBLE_EQ(dermis::parseFrameRange("1:2:0.25")->time(3), 1.75);
}

TEST(FrameRangeTest, BadRangesNameTheOption) {
    for (const char* bad : {"", "1", "0:1", "0:1:0.1:2", "a:1:0.1", "0:1:0", "0:1:-1", "1:0:0.1",
                            "-1:1:0.1", "0:1e9:0.001", "0:inf:1", "0:nan:1", " 0:1:0.1", "0:1:0.1x"}) {
        auto r = dermis::parseFrameRange(bad);
        ASSERT_FALSE(r.ok()) << bad;
        EXPECT_EQ(r.error().field, "--frames") << bad;
        EXPECT_NE(r.error().message.find("--frames"), std::string::npos) << r.error().message;
    }
}

TEST(FrameRangeTest, ShardsSplitEveryFrameExactlyOnceInterleaved) {
    const FrameRange range = *dermis::parseFrameRange("0:2.3:0.1"); // 24 frames
    ASSERT_EQ(range.count, 24);
    for (int n : {1, 2, 3, 4, 5, 7, 24, 30}) {
        std::multiset<int> seen;
        for (int i = 0; i < n; ++i) {
            auto frames = dermis::shardFrames(range, Shard{i, n});
            for (std::size_t j = 0; j < frames.size(); ++j) {
                EXPECT_EQ(frames[j] % n, i);
                if (j) EXPECT_EQ(frames[j] - frames[j - 1], n);
                seen.insert(frames[j]);
            }
        }
        ASSERT_EQ(seen.size(), 24u) << n;
        for (int k = 0; k < 24; ++k) EXPECT_EQ(seen.count(k), 1u) << "frame " << k << " of " << n;
    }
    EXPECT_EQ(dermis::shardFrames(range, Shard{1, 4}), (std::vector<int>{1, 5, 9, 13, 17, 21}));
}

TEST(FrameRangeTest, ExplicitShards) {
    auto s = dermis::parseShard("2/4", envOf({}));
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_EQ(s->index, 2);
    EXPECT_EQ(s->count, 4);
    EXPECT_EQ(dermis::parseShard("0/1", envOf({}))->count, 1);
}

TEST(FrameRangeTest, AutoReadsSlurmThenKubernetes) {
    auto slurm = dermis::parseShard("auto/4", envOf({{"SLURM_ARRAY_TASK_ID", "3"}}));
    ASSERT_TRUE(slurm.ok()) << slurm.error().message;
    EXPECT_EQ(slurm->index, 3);
    auto k8s = dermis::parseShard("auto/4", envOf({{"JOB_COMPLETION_INDEX", "1"}}));
    ASSERT_TRUE(k8s.ok()) << k8s.error().message;
    EXPECT_EQ(k8s->index, 1);
    auto both = dermis::parseShard("auto/4", envOf({{"SLURM_ARRAY_TASK_ID", "0"}, {"JOB_COMPLETION_INDEX", "2"}}));
    EXPECT_EQ(both->index, 0);
}

TEST(FrameRangeTest, BadShardsNameTheOptionAndTheVariable) {
    for (const char* bad : {"", "4", "1/0", "4/4", "-1/4", "a/4", "1/b", "1/4/2", "1/1000000"}) {
        auto r = dermis::parseShard(bad, envOf({}));
        ASSERT_FALSE(r.ok()) << bad;
        EXPECT_EQ(r.error().field, "--shard") << bad;
    }
    auto none = dermis::parseShard("auto/4", envOf({}));
    ASSERT_FALSE(none.ok());
    EXPECT_NE(none.error().message.find("SLURM_ARRAY_TASK_ID"), std::string::npos);
    EXPECT_NE(none.error().message.find("JOB_COMPLETION_INDEX"), std::string::npos);
    auto outside = dermis::parseShard("auto/4", envOf({{"SLURM_ARRAY_TASK_ID", "4"}}));
    ASSERT_FALSE(outside.ok());
    EXPECT_NE(outside.error().message.find("outside 0 … 3"), std::string::npos) << outside.error().message;
    auto garbage = dermis::parseShard("auto/4", envOf({{"JOB_COMPLETION_INDEX", "x1"}}));
    ASSERT_FALSE(garbage.ok());
    EXPECT_NE(garbage.error().message.find("JOB_COMPLETION_INDEX"), std::string::npos);
}

TEST(FrameRangeTest, FramePathsLikePrintf) {
    for (const char* pattern : {"out/frame_%04d.png", "f%d.jpg", "f%6d.png", "x_%012d"}) {
        for (int k : {0, 7, 123, 99999}) {
            char expected[256];
            std::snprintf(expected, sizeof expected, pattern, k);
            EXPECT_EQ(dermis::framePath(pattern, k), expected) << pattern << " " << k;
        }
    }
    EXPECT_EQ(dermis::framePath("still.png", 3), "still.png");
    EXPECT_FALSE(dermis::hasFrameField("still.png"));
    EXPECT_FALSE(dermis::hasFrameField("100%.png"));
    EXPECT_TRUE(dermis::hasFrameField("f_%04d.png"));
}
