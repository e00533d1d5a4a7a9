// Dermis core — from a scene document and a loaded character to the two height maps: evaluates
// the pose, measures each placement's joint angle, and runs the CPU height-map reference.
//
// Pure: the caller (a shell) loads the model and the pattern images and passes them in.
#pragma once

#include "heightmap.hpp"
#include "model.hpp"
#include "result.hpp"
#include "rig.hpp"
#include "scene.hpp"

#include <map>
#include <memory>
#include <optional>
#include <string>

namespace dermis {

/// The node a pose override or a placement's `joint` names: the joint of that name first, then
/// any named node (so non-skin nodes can be posed and drive patterns); −1 when none.
int findPosable(const Model& model, const std::string& name);

/// The local pose a scene asks for: the clip (`pose.animation`, else the model's first clip, else
/// rest) sampled at `timeOverride` or `pose.time` (clamped to the clip), then the `pose.joints`
/// overrides (`rotation` replaces the local rotation; `axis_angles` sets q_rest·Rx·Ry·Rz), then
/// `pose.morphs` (each sets every Model::morphWeights entry of that name).
/// Fails (NotFound) on an unknown clip "/pose/animation", joint "/pose/joints/<name>" or morph
/// target "/pose/morphs/<name>".
Result<LocalPose> evaluatePose(const Model& model, const Pose& pose,
                               std::optional<double> timeOverride = std::nullopt);

/// The joint angle (degrees) that drives placement `p` under `pose` (SPEC §2 "Joint angle").
/// Fails (NotFound) when the joint does not exist: field "/placements/<index>/joint".
Result<double> placementAngle(const Model& model, const LocalPose& pose, const Placement& p,
                              std::size_t index);

/// Pattern images by the id used in placements (custom ids and built-in ids). Shared and
/// immutable: a frame plan keeps the images it points to alive while the owner's map changes.
using PatternImages = std::map<std::string, std::shared_ptr<const PatternImage>>;

/// The anchor frame of surface placement `p` (SPEC §8) into `b`'s surface members: unit normal,
/// tangent made orthogonal to it (Gram–Schmidt, as the parser does) and turned by `rotation`
/// degrees about the normal (towards b = n × t), size and depth (default max(w, h)/2); sets
/// `b.surface`. Touches nothing else of `b`. False when the anchor is degenerate (possible only for
/// scenes built in code) — `b` is then partly written. The one place this frame is made: the bake,
/// lint and the renderer's decal outlines use it.
bool surfaceFrameOf(const Placement& p, BakePlacement& b);

/// Resolves every enabled placement to a BakePlacement (pointers into `images`, patternId set), in
/// document order; disabled ones are checked like the others but left out. A surface placement
/// (SPEC §8) gets its anchor frame (tangent orthonormalised and turned by `rotation` about the
/// normal), size and depth (default max(w, h)/2). `layout` is the height-map layout in use (null:
/// the model's own UVs). Fails when a UV placement has no UVs to live in — the layout given is
/// empty, or without one not every part has TEXCOORD_0 ("/placements/<i>": why) —, when a
/// surface placement's layout has no UVs at all ("/uv_layout"), on a degenerate anchor of a
/// scene built in code ("/placements/<i>/anchor"), an unknown joint or a missing image.
Result<std::vector<BakePlacement>> resolvePlacements(const Scene& scene, const Model& model,
                                                     const LocalPose& pose,
                                                     const PatternImages& images,
                                                     const TextureLayout* layout = nullptr);

struct SceneBakeOptions {
    std::optional<double> time; ///< overrides pose.time
    std::shared_ptr<const PatternImage> base;
    int threads = 0;
    /// The height-map layout (FrameOverrides::layout); null = the model's own UVs.
    std::shared_ptr<const TextureLayout> layout;
};

/// planFrame (core/frame_plan.hpp) → bakeHeightMaps at the scene's heightmap size.
Result<HeightMaps> bakeScene(const Scene& scene, const Model& model, const PatternImages& images,
                             const SceneBakeOptions& options = {});

} // namespace dermis
