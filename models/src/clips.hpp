// dermis-charactergen — the default character's animation clips.
//
// Each clip is sampled from smooth analytic joint curves at 15 keys per second into LINEAR
// channels (rotations; the squat and the walk also move the pelvis so that the feet stay on the
// ground). Rotations are rest · R_x(a) · R_y(b) · R_z(c) in the joint's rest frame (the scene
// document's axis_angles convention, SPEC §2b), so a clip's angle about a joint axis is exactly
// what jointAngle measures. Every clip starts and ends at the rest pose (they loop).
//   elbow_curl  2.0 s  both elbows flex 0 → 130° → 0 (forearm x)
//   squat       2.5 s  hips flex to 95°, knees to 120°, feet flat, torso leans, arms forward
//   torso_bend  3.0 s  spine bends forward 75° in total, then back 30° (spine_0n/chest x)
//   torso_twist 2.0 s  spine twists ±45° in total (spine_0n y)
//   neck_turn   3.0 s  head turns ±60° (neck_0n/head y), then nods forward 35° and back
//   arm_raise   2.5 s  arms rise to the side (upper_arm z 90°, clavicle z 25°), then swing
//                      back (upper_arm x −40°)
//   walk        1.1 s  an in-place walk cycle
#pragma once

#include "core/model.hpp"
#include "skeleton.hpp"

#include <vector>

namespace dermis::chargen {

/// The clips, with channel node indices equal to joint indices (node i = joint i).
std::vector<dermis::Clip> buildClips(const Skeleton& skeleton);

} // namespace dermis::chargen
