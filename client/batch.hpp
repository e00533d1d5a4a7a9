// dermis (client) — one call of the batch route POST /render: a scene document and a list of
// frames ({time} or {pose}) rendered by the server and streamed back as multipart/mixed parts,
// each handed to `onFrame` as soon as it is complete. Used by `render` and `check`.
#pragma once

#include "content.hpp"
#include "http_client.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>

namespace dermis::cli {

struct BatchOutcome {
    std::size_t received = 0;  ///< frames handed to onFrame (the first `received`: parts come in order)
    bool interrupted = false;  ///< g_interrupted or onFrame stopped it
    long failedFrame = -1;     ///< the frame (index in `frames`) whose error part ended the stream
    std::string failure;       ///< its error message (and field)
    /// The answer broke off: no connection, the connection lost mid-stream, or a proxy's 502/503/
    /// 504 (a replica gone). The frames after `received` may be asked for again.
    bool broken = false;
    std::string brokenWhy;
    std::size_t contentSent = 0; ///< content parts sent after 409 missing_content answers
};

/// Renders `frames` of `scene` (format "png" or "jpeg", view "shaded", …). `onFrame(index, bytes)`
/// gets each frame as it arrives (false stops). When the scene names content by address and the
/// server answers 409 missing_content, the batch is sent again as multipart with the listed
/// files of `content` (twice at most). Other error answers of the whole request throw (CliError
/// exit 1); broken connections and proxy errors are reported as `broken`; a frame that fails after
/// the stream began ends it and is reported in the outcome. Stops early (interrupted) when
/// g_interrupted is set.
BatchOutcome renderBatch(Http& http, const nlohmann::json& scene, const nlohmann::json& frames,
                         const std::string& format, const std::string& view,
                         const std::function<bool(std::size_t index, std::string bytes)>& onFrame,
                         const ContentFiles* content = nullptr);

} // namespace dermis::cli
