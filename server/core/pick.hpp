// Dermis core — from a pixel of a frame to the skin (SPEC §6 Pick): an exact CPU ray cast against
// the posed (skinned) mesh of the frame a plan describes, with the same camera the renderer uses
// (core/camera), and a suggested driver for a pattern placed there.
//
// The ray meets the skinned triangles, not the displaced surface: where displacement is large
// (a few % of the body), a pixel on a silhouette edge may hit or miss differently than the frame
// shows. Pure; O(triangles) per pick (no acceleration structure: the default character takes a
// fraction of a millisecond).
#pragma once

#include "camera.hpp"
#include "frame_plan.hpp"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace dermis {

struct PickHit {
    int part = -1, triangle = -1;
    glm::vec3 bary{0.0f};         ///< barycentric weights of the triangle's corners
    glm::vec2 uv{0.0f};           ///< TEXCOORD_0 there (0, 0 for a part without UVs)
    glm::vec3 position{0.0f};     ///< world position on the posed mesh
    double distance = 0.0;        ///< from the eye
    /// The (at most 4) largest skin weights there: node index, weight; largest first.
    std::vector<std::pair<int, float>> joints;
};

/// The nearest posed triangle under pixel (x, y) (pixel coordinates of core/camera: the centre
/// of pixel (col, row) is (col + 0.5, row + 0.5)) of the frame `plan` renders; nullopt on the
/// background. Fails (InvalidArgument, field "x"/"y") when the pixel is outside the frame.
/// The camera the renderer uses for `plan` (core/camera frameCamera on the posed bounds, with the
/// plan's displacement scale): "auto" distance resolved. Pure; never fails.
FrameCamera planCamera(const FramePlan& plan, const Model& model);

class UvLookup;
/// The skin at texture point `uv` (SPEC §6 pick by UV, for the texture view): the rest-mesh
/// triangle there (`position` in bind space, `distance` 0) and its top-4 skin weights; nullopt
/// where no UV chart is. `lookup` must index `model`.
std::optional<PickHit> pickUv(const Model& model, const UvLookup& lookup, glm::dvec2 uv);

Result<std::optional<PickHit>> pickFrame(const FramePlan& plan, const Model& model, double x, double y);

struct TextureLayout;

/// The UV of `hit` in `layout` (SPEC §8: pick's uv is in the layout the scene uses): the layout
/// triangle with the hit triangle's index, its corners' UVs blended by the hit's barycentrics
/// (a layout keeps the part's triangle order and corner order). nullopt where the layout has no
/// such triangle (a part it does not cover) or an index is out of range.
std::optional<glm::vec2> layoutUv(const TextureLayout& layout, const PickHit& hit);

/// Where a surface placement would sit at a hit (SPEC §8 pick `anchor`), in bind space.
struct PickAnchor {
    glm::dvec3 position{0.0};       ///< the hit triangle's bind-space corners blended
    glm::dvec3 normal{0, 0, 1};     ///< its corners' normals blended (the face normal without), unit
    glm::dvec3 tangent{1, 0, 0};    ///< unit, ⟂ normal, across the bone of `joint`
};

/// The anchor at `hit` (part, triangle and barycentrics of a pick of `model`): position and
/// normal from the rest mesh; the tangent runs across the bending direction of node `joint`
/// (the suggested driver): perpendicular, in the tangent plane, to its bone — from the joint to
/// the mean of its child joints, else from its parent joint to it — carried from rest world into
/// bind space by the skinning of the hit's most weighted influence. Without a usable bone (no
/// joint, a bone along the normal) any unit vector ⟂ normal, chosen deterministically.
/// `restWorld` is worldMatrices(model, restPose(model)) (ModelDerived::restSkin().world).
PickAnchor pickAnchor(const Model& model, const PickHit& hit, int joint,
                      const std::vector<glm::mat4>& restWorld);

struct SuggestedDriver {
    std::string joint;
    std::string axis = "x"; ///< "x", "y" or "z" (the joint's rest frame)
    double thetaMin = 0.0, thetaMax = 90.0;
};

/// A driver for a pattern on the skin held by `joints` (node, weight): of the weighted joints
/// (each the child of the pair it forms with its parent joint), the one and axis whose angle
/// moves most over the model's clips, weighted by its skin weight; θ from the angle nearest the
/// rest pose (0 when the motion passes through it) to the far end of the motion, rounded to
/// 0.5°. Without clips: the most weighted joint, x, 0–90. Empty joint name when `joints` is.
SuggestedDriver suggestDriver(const Model& model, const std::vector<std::pair<int, float>>& joints);

/// A joint angle's range over sampled poses, degrees (lo > hi: nothing sampled yet).
struct AngleRange {
    double lo = 1e9, hi = -1e9;
};

/// suggestDriver's choice from the angle ranges it sampled: `ranges[j]` (about x, y, z) belongs
/// to `joints[j]`. The joint and axis with the largest weight × range; θ from the angle nearest
/// the rest pose (0 when the motion passes through it) to the far end, rounded to 0.5°; 0–90
/// about x of the first joint when nothing moves. Precondition: `joints` non-empty, node indices
/// valid, `ranges` as long as `joints`.
SuggestedDriver chooseDriver(const Model& model, const std::vector<std::pair<int, float>>& joints,
                             const std::vector<std::array<AngleRange, 3>>& ranges);

} // namespace dermis
