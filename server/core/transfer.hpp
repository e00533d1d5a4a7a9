// Dermis core — another character's placements onto this one (SPEC §8 transfer).
//
//   joints:  an explicit map first, then the same name, then the same role and side
//            (core/body_map.hpp: mixamorig:LeftForeArm, lowerarm_l, forearm.L, CC_Base_L_Forearm,
//            leftLowerArm and CesiumMan's arm_joint_L__3_ are all "left elbow"); of several
//            joints of one role (spine_01…chest) the one at the same fraction of that run.
//   anchor:  re-expressed relative to the driver's bone — of the segments into and out of the
//            driver joint (twist helpers skipped), the one nearest to the anchor: position along
//            it (a fraction of its length) and angle around it (from the body's forward direction,
//            +z, to the anchor's normal made ⟂ the bone; to the anchor itself where the normal
//            runs along the bone) — then cast from the same place of the matching segment
//            of the target, outward at that angle, onto the target's rest surface (the skin of
//            the bone's joints first); taken to bind space through the rest skinning there. A
//            segment from the trunk (chest → shoulder where the target has no clavicle) runs
//            through the body: there the normal's world direction is cast along instead.
//   size:    scaled by the segments' length ratio (depth too, when set); the tangent and the
//            driver axis keep their angles to the bone's frame (so a T-pose and an A-pose
//            character get the same bend).
//   UV placements are first made surface placements (surfaceFromUv), so they follow a layout
//   the target does not share.
//
// Pure; O(triangles) per placement (a ray cast and a nearest-point search).
#pragma once

#include "body_map.hpp"
#include "mirror.hpp"
#include "scene.hpp"
#include "uv_lookup.hpp"

#include <map>
#include <string>
#include <vector>

namespace dermis {

/// One side of a transfer: a model with its rest skin and body map (and, for the source, the
/// UV index of the layout its UV placements live in; may be null when it has none).
struct TransferModel {
    const Model& model;
    const RestSkin& rest;
    const BodyMap& body;
    const UvLookup* lookup = nullptr;
    const Model* uvModel = nullptr; ///< the model `lookup` indexes (its UVs); null = `model`
};

/// The target joint for `joint` of the source (see above), "" when none matches. `explicitMap`
/// (source name → target name) wins when it names a joint of the target.
std::string matchJoint(const TransferModel& from, const TransferModel& to, const std::string& joint,
                       const std::map<std::string, std::string>& explicitMap = {});

/// The surface placement equivalent to UV placement `p` on `m` (lookup of the layout `p` lives
/// in): anchor at the footprint centre's rest-mesh point (bind space), tangent the footprint's
/// rotated u axis carried through that triangle's UV → position map, size its UV scale times
/// how much that map stretches each axis, rotation 0; the rest kept. Fails: NotFound
/// ("center") when the centre is on no UV chart; Unsupported ("/uvs") without a lookup.
/// `uvModel` is the model `lookup` indexes (the same triangles as `m`, maybe another layout's
/// UVs).
Result<Placement> surfaceFromUv(const Placement& p, const Model& m, const UvLookup* lookup, const Model& uvModel);

struct TransferResult {
    struct Mapped {
        std::string from;   ///< the source placement's id
        Placement placement; ///< on the target (id = the source's)
    };
    struct Unmapped {
        std::string from;
        std::string field;  ///< "joint", "anchor", "center"
        std::string reason;
    };
    std::vector<Mapped> mapped;
    std::vector<Unmapped> unmapped;
    std::map<std::string, std::string> joints; ///< source joint → target joint, as used
};

/// `placements` of `from` carried onto `to` (see above). Never fails as a whole: what cannot
/// follow is listed in `unmapped`.
TransferResult transferPlacements(const std::vector<Placement>& placements, const TransferModel& from,
                                  const TransferModel& to, const std::map<std::string, std::string>& explicitMap = {});

} // namespace dermis
