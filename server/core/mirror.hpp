// Dermis core — the mirror twin of a placement (SPEC §6 Mirror), by geometry, not only by names.
//
//   symmetry plane: of the planes through the centre of the rest-pose bounds perpendicular to x,
//                   y or z (world space, after the rest pose: CesiumMan's Z-up root included),
//                   the one whose reflection maps a sample of the rest vertices closest onto the
//                   mesh;
//   centre:         the footprint centre's rest surface point (UvLookup), reflected across the
//                   plane, snapped to the nearest point of the rest mesh, and that point's UV;
//   footprint:      two short steps along the footprint's own axes go through the same map; the
//                   twin's rotation is the angle of the mapped first axis, its scale the old one
//                   times how much each step stretched (a reflection cannot flip an image: the
//                   twin keeps the same pattern, rotated);
//   joint:          by name pairs (_l/_r, .l/.r, .L/.R, Left/Right, L_/R_, _L_/_R_ inside, any
//                   case), else the joint nearest the reflected rest position of the joint
//                   (within 5% of the body's size; none → NotFound); a name twin farther than
//                   that from the reflected position gives way to the nearest joint there
//                   (names that do not pair the same places: CesiumMan's arm joints);
//   axis:           an axial vector: world a_w = Q_j·a, mirrored a_w' = −R·a_w (R the
//                   reflection), twin-local a' = Q_t⁻¹·a_w' (Q the joints' rest world rotations),
//                   so a pose and its mirror image give both twins the same θ, hence the same t;
//                   written rounded (components within 1e-6 of 0 are 0, the others rounded to
//                   6 decimals); θ range, h, model, target and response are kept;
//   label:          mirrorLabel (side words swapped, else " (mirror)" appended).
//
// Pure; O(vertices) per mirror for the nearest-point search (no index yet). What depends only on
// the model (the rest-pose skinning, RestSkin) can be computed once and passed in; the overloads
// without it compute it per call.
#pragma once

#include "camera.hpp"
#include "rig.hpp"
#include "scene.hpp"
#include "uv_lookup.hpp"

#include <glm/glm.hpp>

#include <optional>
#include <string>

namespace dermis {

struct SymmetryPlane {
    int axis = 0;          ///< 0 = x, 1 = y, 2 = z (world, rest pose)
    float offset = 0.0f;   ///< the plane is world[axis] = offset
    float error = 0.0f;    ///< mean distance of reflected sample vertices to the mesh, world units
};

/// The model's rest pose as the mirror reads it; depends only on the model, so it can be made
/// once per model (core ModelDerived::restSkin) and passed to the overloads below. Plain values
/// (no pointer into the model).
struct RestSkin {
    std::vector<glm::mat4> world;     ///< worldMatrices(model, restPose(model)): one per node
    std::vector<SkinnedPart> parts;   ///< skin(model, world): rest positions, one per part
    Bounds bounds;                    ///< framingBounds(parts)
};

/// The RestSkin of `model` (O(vertices · influences)). Never fails; an empty model gives empty
/// vectors and the cube bounds.
RestSkin restSkin(const Model& model);

/// The rest pose's symmetry plane (see above). A model without vertices gets x = 0.
SymmetryPlane symmetryPlane(const Model& model);
/// The same from a precomputed `rest`, which must be restSkin(model) of the model meant.
SymmetryPlane symmetryPlane(const RestSkin& rest);

/// The twin joint's name for `joint` by the naming conventions above ("" when none applies or
/// the model has no such joint).
std::string mirrorJointName(const Model& model, const std::string& joint);

/// `s` with every side token swapped, left for right and right for left, each keeping its case:
/// the words "left"/"right" (any case, at a word start: after a non-letter, or a capital after a
/// small letter as in "ArmLeft"; and not followed by a small letter, so "cleft" and "Leftover"
/// have none) and the letters "l"/"r" standing alone between non-alphanumerics or the ends
/// ("elbow_l", "forearm.L", "L_arm", "leg_L_1", "elbow L", "(L)"). nullopt when `s` has none.
std::optional<std::string> swapSides(const std::string& s);

/// The side of `name` by its first side token: 'l', 'r', or 0 when it has none (see swapSides).
char sideOf(const std::string& name);

/// The id a mirror twin of placement `id` gets before it is made unique: `id` with its sides
/// swapped (swapSides: elbow_l → elbow_r, Left → Right, .L → .R); else, when the twin joint has
/// a side, `id` + "_l" or "_r" (that side); else `id` + "_twin".
std::string mirrorPlacementId(const std::string& id, const std::string& twinJoint);

/// The label of a mirror twin: `label` with its side words swapped (swapSides: "elbow L" →
/// "elbow R", "left" → "right", "(L)" → "(R)"), else `label` + " (mirror)"; "" stays "". Cut
/// to kMaxLabelLength bytes at a UTF-8 character boundary.
std::string mirrorLabel(const std::string& label);

/// How far (height-map texels of the scene) a placement may be from where another mirrors to
/// and still be its twin: the mirror route's duplicate check and lint's mirror pairs.
inline constexpr double kMirrorCenterTexels = 4.0;

/// How far (a fraction of the twin's larger size) a surface placement's anchor may be from where
/// another's mirrors to and still be its twin (SPEC §8; the UV analogue is kMirrorCenterTexels).
inline constexpr double kMirrorAnchorFraction = 0.1;

/// The index in `scene.placements` of a placement that already is `twin` — the mirror image
/// mirrorPlacement made of some placement: the same joint, pattern, target and projection, and a
/// centre within kMirrorCenterTexels of the scene's height map (`heightmapSize`) of twin's — for
/// surface placements an anchor within kMirrorAnchorFraction · max(size) of twin's — or −1.
/// Compares the patterns as named (resolve aliases in both first). The first such, in order.
int findMirrorTwin(const Scene& scene, const Placement& twin);

/// Distance between two placements' anchor positions (bind space, model units).
double surfaceAnchorDistance(const Placement& a, const Placement& b);

/// The mirror twin of `p` (id left empty for the caller). A surface placement (SPEC §8) goes to
/// mirrorSurfacePlacement (no UVs needed). Fails: Unsupported ("/uvs") without UVs; NotFound
/// ("center") when the footprint centre is on no UV chart; NotFound ("joint") when the joint has
/// no twin by name or position.
Result<Placement> mirrorPlacement(const Placement& p, const Model& model, const UvLookup& lookup,
                                  const SymmetryPlane& plane);
/// The same, bit for bit, without the per-call rest-pose skinning: `rest` must be
/// restSkin(model) of this same model (not checked; another model's gives wrong twins, and a
/// RestSkin with fewer nodes or parts than the model is read only within its bounds).
Result<Placement> mirrorPlacement(const Placement& p, const Model& model, const UvLookup& lookup,
                                  const SymmetryPlane& plane, const RestSkin& rest);

/// The driver part of mirrorPlacement into `out`: the twin joint (by name, else by reflected
/// rest position) and the mirrored axis (see the header comment). Fails like mirrorPlacement
/// ("joint", "axis").
Status mirrorDriver(const Placement& p, const Model& model, const SymmetryPlane& plane,
                    const RestSkin& rest, Placement& out);

/// The mirror twin of surface placement `p` (SPEC §8): the anchor taken to
/// rest world space through the skinning at its nearest bind-space surface point, reflected
/// across the plane, snapped to the nearest rest surface point and taken back to bind space
/// through the skinning there; the normal reflected likewise. A reflection cannot flip an image,
/// so one of the pattern's axes keeps its direction relative to the body (as a mirror image
/// would) and the other is turned: the one that lies more within the symmetry plane is kept
/// (up/down, front/back stay), the one across it (towards/away from the plane) is turned — the
/// twin looks like the original carried across, not upside down. `rotation`, size, depth, the
/// driver's range and the rest are kept (joint and axis mirrored as for UV placements); the UV
/// footprint members are kept as they are. Fails: InvalidArgument ("anchor") on a model without
/// triangles near the anchor; like mirrorDriver.
Result<Placement> mirrorSurfacePlacement(const Placement& p, const Model& model,
                                         const SymmetryPlane& plane, const RestSkin& rest);

/// The reflection of a local rotation delta for the twin joint, for tests and tools: given the
/// rest world rotations Q_j, Q_t and a delta Δ of joint j (pose = rest·Δ), the twin's delta Δ'
/// of the mirror-image pose: Q_t⁻¹·(R·Q_j·Δ·Q_j⁻¹·R)·Q_t, as a quaternion.
glm::quat mirrorDelta(const glm::quat& restWorldJ, const glm::quat& restWorldT, const glm::quat& delta,
                      int axis);

/// Rest world rotation of node `n` (rotation part of its rest world matrix, scale removed).
glm::quat restWorldRotation(const Model& model, int n);

/// The twin-local axis of `axis` (joint j's rest frame) for twin t (see above).
glm::vec3 mirrorAxis(const Model& model, int j, int t, const glm::vec3& axis, int planeAxis);

} // namespace dermis
