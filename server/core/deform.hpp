// Dermis core — the deformation model of the paper (§4.2, eq. 1 and 2) as pinned by SPEC §2.
//
// Pure functions of scalars; no allocation, no state, safe from any thread.
#pragma once

#include "result.hpp"

#include <optional>
#include <string_view>

namespace dermis {

/// How a pattern's height L is altered by the joint angle.
enum class DeformModel {
    Scale, ///< wrinkles, bulges: paper eq. 1, L_out = L·h·gain(t)
    Bias,  ///< protruding bones: paper eq. 2, L_out = max(h·(L − offset(t)), 0)
};

/// The curve between the end points t = 0 and t = 1 (SPEC §2 table).
enum class Response {
    Log2,       ///< default: gain = log2(1+t), offset = log2(2−t); continuous at both ends
    Ln,         ///< the paper's formula to the letter (jumps at t = 1)
    Linear,     ///< gain = t, offset = 1 − t
    Smoothstep, ///< gain = t²(3−2t), offset = 1 − gain
};

/// Which height map a placement writes to.
enum class Target { Bump, Displacement };

/// The pattern kinds of the paper §3.
enum class PatternKind { Wrinkle, Bulge, Bone };

std::string_view toString(DeformModel m);
std::string_view toString(Response r);
std::string_view toString(Target t);
std::string_view toString(PatternKind k);
/// Parse the scene-document spellings ("scale", "log2", "bump", "wrinkle", …); nullopt if unknown.
std::optional<DeformModel> deformModelFromString(std::string_view s);
std::optional<Response> responseFromString(std::string_view s);
std::optional<Target> targetFromString(std::string_view s);
std::optional<PatternKind> patternKindFromString(std::string_view s);

/// SPEC §2 defaults per kind: wrinkle → bump/scale, bulge → displacement/scale, bone → bump/bias.
DeformModel defaultModel(PatternKind k);
Target defaultTarget(PatternKind k);

/// t = clamp((theta − thetaMin) / (thetaMax − thetaMin), 0, 1). Works for reversed ranges
/// (thetaMin > thetaMax). Precondition: validateDrive(d) succeeded and theta is finite.
double normalizedT(double theta, double thetaMin, double thetaMax);

/// gain(t) of the scale model for 0 < t < 1 (SPEC §2 table).
double responseGain(Response r, double t);
/// offset(t) of the bias model for 0 < t < 1 (SPEC §2 table).
double responseOffset(Response r, double t);

/// L_out for a pattern value L ∈ [−1, 1] at normalised angle t ∈ [0, 1] (paper eq. 1 and 2 with
/// SPEC §2's normalisation): 0 at t = 0, L·h at t = 1, otherwise L·h·gain(t) (Scale) or
/// max(h·(L − offset(t)), 0) (Bias). Inline: it runs per texel.
inline float applyDeform(DeformModel m, float L, float h, double t, float gainOrOffset) {
    if (t <= 0.0) return 0.0f;
    if (t >= 1.0) return L * h;
    if (m == DeformModel::Scale) return L * h * gainOrOffset;
    float v = h * (L - gainOrOffset);
    return v > 0.0f ? v : 0.0f;
}

/// Convenience: the per-placement constant of applyDeform (gain for Scale, offset for Bias).
float deformConstant(DeformModel m, Response r, double t);

} // namespace dermis
