// Dermis core — a full pattern set for a character (SPEC §8 proposals), from its range of motion
// (core/motion.hpp) and what each joint is (core/body_map.hpp).
//
// For each bending joint of the table below, on the side its bend makes concave (the direction
// its child joint moves at the peak bend, ⟂ the parent bone) and the other:
//
//   elbow   crease (pattern crease) on the inner elbow, bone (round_bulge, bias) on the elbow
//           tip, bulge (round_bulge, displacement) on the biceps: 55 % down the upper arm;
//   knee    crease on the back of the knee, bone on the knee cap, bulge (elongated_bulge) on the
//           back of the thigh, half-way down;
//   ankle   bulge (elongated_bulge) on the calf, a third of the way down the shin, driven by
//           the ankle's angle turned so that pointing the foot (the toe tip moving away from the
//           knee) is positive;
//   spine   the spine joint the clips bend forward most: stomach_wrinkles on the belly;
//   neck    the neck joint the clips bend forward most: neck_rings on the throat (both by
//           kMinMotionDegrees at least; synthetic only on a model without clips).
//
//   anchor:  a ray from the joint (or the point of the parent bone) towards that side meets the
//            rest surface of the limb (triangles weighted on the joint, its parent or child);
//            the hit, taken to bind space through the rest skinning there. The ray's length is
//            the limb's radius r there.
//   size:    crease 2r × 1.2r, bone 1.1r square, bulge 1.4r × 0.45 · the parent bone's length
//            (model units of the rest pose, then bind space); depth the default, or 1.25 × the
//            distance to the hit triangle's nearest corner when that is more (coarse meshes).
//   tangent: a crease's lines run across the compression direction (the strain-weighted
//            principal direction of its triangles at the peak bend); bone and bulge: across
//            the bone.
//   driver:  the joint, its principal axis (a vector), θmin = neutral angle, θmax = peak,
//            rounded to 0.5°.
//   twins:   a right-side joint whose left twin has a proposal gets that proposal's mirror image
//            (core mirrorSurfacePlacement); both get the θ range both joints reach (the larger
//            neutral, the smaller peak).
//   score:   0..1: how strongly the region compresses (crease, bulge) or stretches (bone) at the
//            peak bend, and how well that follows the joint's angle over the clips (Pearson r).
//
// A joint the clips turn less than kMinMotionDegrees bends synthetically (core/motion.hpp) where
// no clip turns it at all or the clips turn it the synthetic way (RiggedFigure's clip moves no
// elbow or knee); otherwise it gets no proposal (no clip would show it). Pure.
#pragma once

#include "body_map.hpp"
#include "motion.hpp"
#include "pick.hpp"
#include "scene.hpp"

#include <string>
#include <vector>

namespace dermis {

struct ProposalWhy {
    std::string joint;         ///< driver joint name
    std::string role;          ///< "left elbow", …
    glm::dvec3 axis{1, 0, 0};  ///< the joint's rest frame
    double neutral = 0.0, peak = 0.0;
    std::string peakClip;      ///< "" when synthetic or at the rest pose
    double peakTime = 0.0;
    bool synthetic = false;
    double planarity = 0.0;    ///< the axis's share of the joint's rotation
    double compression = 0.0;  ///< mean 1 − λmin of the region at the peak bend
    double stretch = 0.0;      ///< mean λmax − 1
    double correlation = 0.0;  ///< of the region's compression (stretch for bones) with θ
    double radius = 0.0;       ///< the limb's radius at the anchor, model units (rest)
};

struct Proposal {
    Placement placement; ///< projection surface; id like "elbow_crease_l", label "left elbow crease"
    std::string kind;    ///< "crease", "bone" or "bulge"
    double score = 0.0;
    ProposalWhy why;
    std::string twin;    ///< id of its mirror twin among the proposals ("" none)
};

/// The proposals for `model` (see above); `rest`, `plane`, `body` and `motion` of that model.
/// Never fails; a model without joints gets none.
std::vector<Proposal> proposePatterns(const Model& model, const RestSkin& rest, const SymmetryPlane& plane,
                                      const BodyMap& body, const MotionAnalysis& motion);

/// A pick's driver from the same analysis (SPEC §8 pick `suggested`; issue #23): the driver of
/// the proposal whose decal holds `position` (bind space: within its depth and its footprint;
/// the smallest such) — a point on the biceps gets the elbow; else, of the weighted `joints`,
/// the one whose clips move it most (weight × (peak − neutral)), with its principal axis (on a
/// right joint whose left twin moves too: the mirror image of the left's axis, so both sides
/// agree) and θ from its neutral angle to its peak; else core suggestDriver's answer.
struct MotionSuggestion {
    SuggestedDriver driver;            ///< axis "x"/"y"/"z", or "" with `axisVector`
    std::optional<glm::dvec3> axisVector;
    std::string role;                  ///< describeJoint of the driver ("left elbow")
    std::string proposal;              ///< the id of the proposal it came from ("" none)
};
MotionSuggestion suggestFromMotion(const Model& model, const RestSkin& rest, const SymmetryPlane& plane,
                                   const BodyMap& body, const MotionAnalysis& motion,
                                   const std::vector<Proposal>& proposals,
                                   const std::vector<std::pair<int, float>>& joints, glm::dvec3 position);

} // namespace dermis
