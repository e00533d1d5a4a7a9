// dermis-charactergen — the default character's skeleton (51 joints) in its rest pose.
//
// Conventions (glTF 2.0): metres, Y up, the character faces +Z, its left side is +X. The rest
// pose is a relaxed A-pose (arms 40° below horizontal, palms facing the thighs, thumbs forward).
// Every joint has a rest frame whose local +Y points along the bone (toward its child, or the
// bone's tip for a leaf) and whose local +X is the joint's main bending axis, chosen so that a
// POSITIVE rotation about +X is the natural flexion on both sides of the body:
//   spine, neck, head: bend forward; clavicle, upper arm: swing forward; forearm: elbow bends;
//   hand, fingers, thumb: curl toward the palm; thigh: hip flexes (leg forward); shin: knee bends;
//   foot: toes up (dorsiflexion); toes: toes up.
// Local +Y is the twist axis. Rotations about Y and Z are mirrored between the sides (left arm
// raise = +Z, right arm raise = −Z), as in Blender's mirrored rigs.
// Twist joints (upper_arm_twist, forearm_twist, thigh_twist, shin_twist) are leaf children of
// their main bone, placed at mid-bone, so animating them never moves the rest of the chain.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <string>
#include <vector>

namespace dermis::chargen {

struct Joint {
    std::string name;
    int parent = -1;    ///< index into Skeleton::joints, −1 for the root
    glm::vec3 head{0};  ///< rest world position of the joint (the bone's start)
    glm::vec3 tail{0};  ///< rest world position of the bone's end (child joint or tip)
    glm::mat3 frame{1}; ///< rest world orientation: columns X (bend), Y (along bone), Z
};

struct Skeleton {
    std::vector<Joint> joints; ///< parents before children
    /// Index of the joint named `name`; −1 when there is none.
    int find(const std::string& name) const;
    /// Like find, but aborts the generator with a message when the joint is missing (a
    /// programming error in the generator's tables).
    int at(const std::string& name) const;
    /// Rest local rotation of joint j relative to its parent (world frame for the root).
    glm::quat restLocalRotation(int j) const;
    /// Rest local translation of joint j in its parent's frame.
    glm::vec3 restLocalTranslation(int j) const;
};

/// The default character's skeleton. Deterministic.
Skeleton buildSkeleton();

/// A proper rotation frame (columns X, Y, Z) with Y = normalize(along) and X chosen so that a
/// positive rotation about X moves Y toward `flex` (X = normalize(Y × flex)). Precondition:
/// `along` and `flex` are not parallel.
glm::mat3 boneFrame(const glm::vec3& along, const glm::vec3& flex);

} // namespace dermis::chargen
