// Dermis core — what each joint of a character is (SPEC §8 proposals and transfer): its side and
// its role in a human body (elbow, knee, …), read from the name across the common conventions
// and, where names say nothing, from the skeleton's shape.
//
//   names:     mixamorig:LeftForeArm, lowerarm_l (Unreal), forearm.L (Blender), CC_Base_L_Forearm
//              (Character Creator), leftLowerArm (VRM), upperarm.l, shin.l, calf_l, LeftUpLeg, …
//              — side tokens and prefixes removed, then keywords (roleFromName).
//   shape:     a limb is the chain of skin joints from a joint off the symmetry plane whose parent
//              is on it, following the child with the longest reach; a limb whose end is in the
//              lowest fifth of the body is a leg, else an arm; where no joint of the limb was
//              named elbow or knee, the joint of the chain nearest to half the chain's length is
//              (its parent is the shoulder or hip, its child the wrist or ankle).
//   side:      the name's side token, else the side of the symmetry plane (+x is the character's
//              left, glTF's convention; within 4 % of the body's width of the plane: centre).
//
// A role names the place the node sits at: the node Blender calls "forearm.L" sits at the elbow
// and its rotation bends the elbow, so its role is Elbow. Pure; O(joints²) at most.
#pragma once

#include "mirror.hpp"
#include "model.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace dermis {

enum class JointRole {
    Other,
    Pelvis,
    Spine,
    Neck,
    Head,
    Clavicle,
    Shoulder, ///< the upper arm's node
    Elbow,    ///< the forearm's node
    Wrist,    ///< the hand's node
    Finger,
    Hip,      ///< the thigh's node
    Knee,     ///< the shin's node
    Ankle,    ///< the foot's node
    Toe,
    Twist,    ///< a twist helper (upperarm_twist_01_l)
};

/// "elbow", "knee", … ("joint" for Other).
std::string_view roleWord(JointRole r);

/// The role a name says (side tokens, prefixes such as "mixamorig:" and "CC_Base_" and digits
/// ignored); Other when it says none.
JointRole roleFromName(const std::string& name);

struct JointInfo {
    int node = -1;
    char side = 0;            ///< 'l', 'r' or 0 (centre)
    JointRole role = JointRole::Other;
    int limb = -1;            ///< index into BodyMap::limbs, −1 off the limbs
    double reach = 0.0;       ///< rest-world distance to the farthest descendant joint
    bool deforms = false;     ///< some vertex has weight ≥ 0.05 on it
};

struct Limb {
    std::vector<int> chain; ///< node indices, root first
    bool leg = false;
    char side = 0;
};

struct BodyMap {
    std::vector<JointInfo> byNode; ///< one per model node (role Other, node −1 for non-joints)
    std::vector<Limb> limbs;
    double height = 1.0;           ///< rest bounds' extent along world y
    double width = 1.0;            ///< rest bounds' extent along the symmetry plane's axis

    /// The node of `role` on `side` (the first along the limbs, else in node order), −1 if none.
    int find(JointRole role, char side) const;
    const JointInfo* info(int node) const {
        return node >= 0 && static_cast<std::size_t>(node) < byNode.size() && byNode[static_cast<std::size_t>(node)].node >= 0
                   ? &byNode[static_cast<std::size_t>(node)]
                   : nullptr;
    }
};

/// The body map of `model` from its rest skin and symmetry plane (see above). Never fails; a
/// model without joints gives an empty map.
BodyMap mapBody(const Model& model, const RestSkin& rest, const SymmetryPlane& plane);

/// The main child joint of `node` (the one reaching farthest), −1 for none.
int mainChild(const Model& model, const BodyMap& body, int node);
/// The bone's ends around joint `j` with twist helpers skipped: the parent joint (−1 for none)
/// and the main child (a twist helper only when it is a leaf; −1 for none). The skipped helpers
/// are added to `skipped` when given.
int boneParent(const Model& model, const BodyMap& body, int j, std::vector<int>* skipped = nullptr);
int boneChild(const Model& model, const BodyMap& body, int j, std::vector<int>* skipped = nullptr);

/// "left elbow", "right knee", "neck", … for node `node` (the role's word, the side word
/// first); the node's name when its role is Other.
std::string describeJoint(const Model& model, const BodyMap& body, int node);

} // namespace dermis
