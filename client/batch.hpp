// dermis (client) — one call of the batch route POST /render: a scene document and a list of
// frames ({time} or {pose}) rendered by the server and streamed back as multipart/mixed parts,
// each handed to `onFrame` as soon as it is complete. Used by `render` and `check`.
#pragma once

#include "http_client.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>

namespace dermis::cli {

struct BatchOutcome {
    std::size_t received = 0;  ///< frames handed to onFrame
    bool interrupted = false;  ///< g_interrupted or onFrame stopped it
    long failedFrame = -1;     ///< the frame (index in `frames`) whose error part ended the stream
    std::string failure;       ///< its error message (and field)
};

/// Renders `frames` of `scene` (format "png" or "jpeg", view "shaded", …). `onFrame(index, bytes)`
/// gets each frame as it arrives (false stops). Error answers of the whole request throw
/// (CliError exit 1), connection failures exit 3; a frame that fails after the stream began
/// ends it and is reported in the outcome. Stops early (interrupted) when g_interrupted is set.
BatchOutcome renderBatch(Http& http, const nlohmann::json& scene, const nlohmann::json& frames,
                         const std::string& format, const std::string& view,
                         const std::function<bool(std::size_t index, std::string bytes)>& onFrame);

} // namespace dermis::cli
