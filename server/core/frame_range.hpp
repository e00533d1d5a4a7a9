// Dermis core — animation frame ranges and how a render farm splits them (SPEC §7).
//
// A range "A:B:STEP" (seconds) names the frames k = 0 … count-1 at times A + k·STEP, the last one
// ≤ B (within 1e-9 of a step, so 0:1:0.1 has 11 frames). A shard "I/N" takes every N-th frame
// starting at frame I — interleaved, not contiguous: each shard gets early and late frames alike,
// so shards of a clip whose cost varies over time finish together, and a range extended at the end
// keeps every existing frame in its shard. "auto/N" takes I from the engine's task index:
// SLURM_ARRAY_TASK_ID (Slurm job arrays, `sbatch --array=0-(N-1)`) or JOB_COMPLETION_INDEX
// (Kubernetes Indexed Jobs). Frame k keeps its number k in file names whatever shard renders it.
//
// Pure: no files, no environment access of its own (the caller passes a lookup). Fails with
// InvalidArgument naming `field` ("--frames", "--shard") and what is wrong.
#pragma once

#include "core/result.hpp"

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace dermis {

/// The largest number of frames a range may name.
inline constexpr int kMaxRangeFrames = 100000;

struct FrameRange {
    double start = 0.0, end = 0.0, step = 1.0;
    int count = 1; ///< frames in the range, ≥ 1

    /// The time of frame k (0 ≤ k < count): start + k·step.
    double time(int k) const { return start + k * step; }
};

/// Parses "A:B:STEP" with 0 ≤ A ≤ B, STEP > 0, at most kMaxRangeFrames frames.
Result<FrameRange> parseFrameRange(std::string_view spec, const std::string& field = "--frames");

struct Shard {
    int index = 0; ///< I, 0 ≤ I < count
    int count = 1; ///< N ≥ 1
};

/// Reads an environment variable: its value, or nullptr when unset (std::getenv in programs,
/// a map in tests).
using EnvLookup = std::function<const char*(const char*)>;

/// Parses "I/N" or "auto/N" (I from SLURM_ARRAY_TASK_ID, else JOB_COMPLETION_INDEX, through
/// `env`). Fails when N < 1 or N > kMaxRangeFrames, I is outside 0 … N-1, or "auto" finds neither
/// variable (the message names both).
Result<Shard> parseShard(std::string_view spec, const EnvLookup& env,
                         const std::string& field = "--shard");

/// The frame numbers of `range` that `shard` renders, ascending: k with k mod N = I.
std::vector<int> shardFrames(const FrameRange& range, const Shard& shard);

/// `pattern` with its first printf-style integer field (%d, %4d, %04d) replaced by `index`
/// ("out/frame_%04d.png", 7 → "out/frame_0007.png"); `pattern` unchanged when it has none.
std::string framePath(const std::string& pattern, int index);

/// True when `pattern` has a field framePath replaces.
bool hasFrameField(const std::string& pattern);

} // namespace dermis
