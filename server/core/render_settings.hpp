// Dermis core — the one check of render settings (SPEC §2b "render"): every shell that changes
// them (scene documents, frame query parameters, the command line's --size, the renderer's own
// entry) applies its overrides to a RenderSettings first and then calls this, so a range is
// written once.
//
// Pure. Does not check what only a GL knows (renderbuffer limits: the renderer adds that) and
// does not parse: types are the document parser's job.
#pragma once

#include "result.hpp"
#include "scene.hpp"

#include <optional>
#include <string>
#include <string_view>

namespace dermis {

/// What a frame shows of the posed, displaced character (a frame's choice, like its camera
/// overrides: not part of scene documents). Shaded is the picture; the others are unlit
/// pictures of the maps on the surface for authoring: Bump and Displacement the height map's
/// channel as grey, byte = 128 + 127·clamp(height, −1, 1) (the inverse of SPEC §2's 8-bit
/// pattern mapping: height 0 is 128, ±1 is 255 / 1); Normal the bump-mapped world normal as
/// rgb, byte = 255·(n·0.5 + 0.5). Sizes, camera, MSAA and displacement are the same in every
/// view; the background is the shaded view's.
enum class FrameView { Shaded, Bump, Displacement, Normal };

/// "shaded", "bump", "displacement", "normal".
std::string_view toString(FrameView v);
/// The view spelled `s` as toString writes it; nullopt for any other string (case-sensitive).
std::optional<FrameView> frameViewFromString(std::string_view s);

/// Limits a caller may tighten below the format's own (kMaxRenderSize).
struct RenderLimits {
    int maxSide = kMaxRenderSize; ///< a server's configured limit (≤ kMaxRenderSize)
};

/// What a frame's anti-aliasing resolves to: the samples of its colour target and whether the
/// post-process edge pass runs after it (never both: Post and None draw one sample).
struct ResolvedAntiAliasing {
    AntiAliasing mode = AntiAliasing::Msaa; ///< never Auto
    int samples = 1;
    /// "msaa4", "msaa2", "post" or "none" (MSAA with one sample is "none"): the frame answer's
    /// X-Dermis-AA header and the benchmarks' label.
    std::string label() const;
};

/// The one place `render.aa: auto` is decided (SPEC §2b "render"): Auto is Post on a software
/// rasterizer and MSAA with `render.msaa` samples elsewhere; Msaa uses min(render.msaa,
/// maxSamples) samples (the GL's limit; ≥ 1); Post and None draw one sample. Pure; does not check
/// ranges (validateRenderSettings does).
ResolvedAntiAliasing resolveAntiAliasing(const RenderSettings& render, bool softwareRasterizer,
                                         int maxSamples);

/// Checks ranges, naming the first offending field by JSON pointer under "/render":
/// size sides in [1, kMaxRenderSize] (InvalidArgument) and ≤ limits.maxSide (TooLarge);
/// camera yaw in [−kMaxTurnAngle, kMaxTurnAngle], pitch in [−90, 90], distance in (0, kMaxCameraDistance]
/// when set; displacement_scale in [0, kMaxDisplacementScale] when set; bump_strength in
/// [0, kMaxBumpStrength] (bounds in scene.hpp); msaa 1, 2 or 4.
/// `where` names the calling function in the message.
Status validateRenderSettings(const RenderSettings& render, const RenderLimits& limits = {},
                              const char* where = "dermis::validateRenderSettings");

} // namespace dermis
