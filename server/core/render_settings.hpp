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

namespace dermis {

/// Limits a caller may tighten below the format's own (kMaxRenderSize).
struct RenderLimits {
    int maxSide = kMaxRenderSize; ///< a server's configured limit (≤ kMaxRenderSize)
};

/// Checks ranges, naming the first offending field by JSON pointer under "/render":
/// size sides in [1, kMaxRenderSize] (InvalidArgument) and ≤ limits.maxSide (TooLarge);
/// camera yaw finite, pitch in [−90, 90], distance finite and > 0 when set; displacement_scale
/// finite and ≥ 0 when set; bump_strength finite and ≥ 0; msaa 1, 2 or 4.
/// `where` names the calling function in the message.
Status validateRenderSettings(const RenderSettings& render, const RenderLimits& limits = {},
                              const char* where = "dermis::validateRenderSettings");

} // namespace dermis
