// Dermis core — range-of-motion analysis (SPEC §8 proposals): how each joint of a character
// moves over its clips, and how its skin stretches and compresses when it bends.
//
//   samples:   the rest pose, then every clip at up to 15 fps (at most kMaxSamplesPerClip per
//              clip and about kSampleBudget in all: a model with 76 clips gets ~6 each).
//   axis:      per skin joint, the principal axis of its rotation vectors log(q_rest⁻¹·q_pose)
//              over the samples (the top eigenvector of Σ r·rᵀ, in the joint's rest frame), its
//              sign chosen so that the larger excursion is positive; `planarity` is that
//              eigenvalue's share of the trace (1 for a hinge).
//   angles:    θ of SPEC §2 (core jointAngle) about that axis at each sample; `peak` the
//              largest, `neutral` the sampled angle nearest to the rest pose (0 when the motion
//              passes through it).
//   synthetic: a joint no clip turns by kMinMotionDegrees gets a synthetic range instead: a
//              bend of kSyntheticDegrees about the axis ⟂ its bone and the body's forward
//              direction (+z, glTF's), towards the front (the knee: towards the back).
//   strain:    principal stretches of a triangle between two poses (triangleStrain): the
//              deformation gradient F of the triangle's plane, λ² the eigenvalues of FᵀF, and
//              the rest-space direction of the smaller one.
//
// Pure; O(samples · nodes) for the analysis. Nothing here is cached: the service keeps one
// analysis per model (ModelDerived::motion).
#pragma once

#include "body_map.hpp"
#include "mirror.hpp"
#include "rig.hpp"

#include <glm/glm.hpp>

#include <vector>

namespace dermis {

inline constexpr int kMaxSamplesPerClip = 60;
inline constexpr int kSampleBudget = 480;
inline constexpr double kMinMotionDegrees = 8.0;
inline constexpr double kSyntheticDegrees = 90.0;

struct MotionSample {
    int clip = -1;     ///< −1: the rest pose
    float time = 0.0f; ///< seconds
};

struct JointMotion {
    int node = -1;
    glm::dvec3 axis{1, 0, 0}; ///< unit, the joint's rest frame
    double lo = 0.0, hi = 0.0; ///< θ range over the samples, degrees
    double neutral = 0.0, peak = 0.0;
    int neutralSample = 0, peakSample = 0; ///< indices into MotionAnalysis::samples (−1 synthetic)
    double planarity = 0.0;
    bool synthetic = false;
    /// θ range the clips give about `axis` (for a synthetic range too; 0, 0 without clips).
    double clipLo = 0.0, clipHi = 0.0;
};

struct MotionAnalysis {
    std::vector<MotionSample> samples;
    /// One per model node (node −1 for non-joints).
    std::vector<JointMotion> joints;
    /// Local rotation of each skin joint at each sample: rotations[sample][node].
    std::vector<std::vector<glm::quat>> rotations;

    const JointMotion* motion(int node) const {
        return node >= 0 && static_cast<std::size_t>(node) < joints.size() && joints[static_cast<std::size_t>(node)].node >= 0
                   ? &joints[static_cast<std::size_t>(node)]
                   : nullptr;
    }
};

/// The analysis of `model` (see above); `rest` and `body` of the same model. Never fails.
MotionAnalysis analyzeMotion(const Model& model, const RestSkin& rest, const BodyMap& body);

/// θ range, neutral and peak of node `node` about a given `axis` (its rest frame, unit) over the
/// analysis's samples, as analyzeMotion finds them for its own axis (peak: the larger of the
/// positive excursion; negative angles only when the motion never turns the positive way).
JointMotion motionAbout(const Model& model, const MotionAnalysis& a, int node, glm::dvec3 axis);

/// The local pose of sample `s` of the analysis.
LocalPose samplePose(const Model& model, const MotionSample& s);

/// The rest pose with node `node` turned by `degrees` about `axis` (its rest frame): θ of that
/// joint is then exactly `degrees`.
LocalPose bendPose(const Model& model, int node, glm::dvec3 axis, double degrees);

struct TriangleStrain {
    double minStretch = 1.0, maxStretch = 1.0; ///< principal stretches λ (1: unchanged)
    glm::dvec3 minDirection{1, 0, 0};          ///< rest space, unit, along which λ = minStretch
};

/// Principal stretches of the triangle (a, b, c) → (a2, b2, c2). A degenerate rest triangle
/// gives λ = 1 both.
TriangleStrain triangleStrain(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 a2, glm::dvec3 b2,
                              glm::dvec3 c2);

/// Rest-world position of node `n` (origin of its rest world matrix).
glm::dvec3 restJointPosition(const RestSkin& rest, int n);

} // namespace dermis
