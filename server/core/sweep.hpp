// Dermis core — the steps of a sweep (SPEC §6 Sweep): a placement's driver joint driven from
// θmin to θmax, or a clip's time from 0 to its duration, in N evenly spaced steps, with every
// placement's t at each step. The HTTP route renders each step as one cell of a contact sheet
// (or answers the steps as JSON); this file only plans them. CPU only, no images needed.
//
//   joint sweep: the scene's pose (its clip at its time, or at `time`, and its joint overrides)
//                with the driver joint's local rotation q replaced by q·R(a, θk − θ(q)): the
//                twist about the placement's axis a set to θk, the rest of that joint's posed
//                rotation (its swing) kept, every other joint as posed. θk = θmin + k/(N−1)·
//                (θmax − θmin); θ is measured as SPEC §2 says, so angles beyond (−180, 180]
//                wrap.
//   clip sweep:  the clip alone at tk = k/(N−1)·duration (the scene's joint overrides are not
//                applied), exactly as GET …/activation samples a clip, so both give the same t.
//
// Each step's `pose` is a scene Pose: a caller plans a frame with it (planFrame), which gives
// the same t. Pure; thread-safe on const inputs.
#pragma once

#include "bake.hpp"

#include <optional>
#include <string>
#include <vector>

namespace dermis {

/// Fewest and most steps a sweep may take (a shell may allow fewer for rendered sweeps).
inline constexpr int kMinSweepSteps = 2;
inline constexpr int kMaxSweepSteps = 1000;

struct SweepStep {
    double theta = 0.0;    ///< joint sweeps: the driver's angle θk (degrees); clip sweeps: 0
    double time = 0.0;     ///< clip sweeps: seconds into the clip; joint sweeps: the pose time
    Pose pose;             ///< the pose of this step (replaces Scene::pose)
    std::vector<double> t; ///< every placement's t, scene order (disabled ones too)
};

struct Sweep {
    std::optional<std::size_t> placement; ///< the swept placement (joint sweeps; clip sweeps: none)
    std::string clip;                     ///< the swept clip ("" for joint sweeps)
    double duration = 0.0;                ///< the clip's duration (clip sweeps)
    std::vector<SweepStep> steps;
};

/// Drives the joint of placement `placement` (index into scene.placements) over its θ range in
/// `steps` steps, the pose evaluated at `time` (default the scene's pose time). Fails:
/// InvalidArgument ("steps") unless kMinSweepSteps ≤ steps ≤ kMaxSweepSteps; InvalidArgument
/// ("time") for a time that is not finite and ≥ 0; NotFound ("placement") for an index out of
/// range; like evaluatePose ("/pose/…") and placementAngle ("/placements/<i>/joint").
Result<Sweep> jointSweep(const Scene& scene, const Model& model, std::size_t placement, int steps,
                         std::optional<double> time = std::nullopt);

/// Samples clip `clip` at `steps` evenly spaced times from 0 to its duration (a clip of
/// duration 0 gives every step time 0). Fails: InvalidArgument ("steps") as above; NotFound
/// ("clip") for a clip the model lacks; like placementAngle.
Result<Sweep> clipSweep(const Scene& scene, const Model& model, const std::string& clip, int steps);

} // namespace dermis
