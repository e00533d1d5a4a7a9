// dermis (client) — `render`'s frame range through the batch route: the pending frames cut into
// batches of `batch`, sent by `parallel` workers at once (each its own connection, so replicas
// behind a load balancer render side by side), each frame written atomically as its part arrives.
// A batch that breaks off (a replica gone, a proxy's 502) is asked for again for the frames it did
// not deliver, after a pause that grows while no frame arrives, up to retries + 1 times in a row.
#pragma once

#include "content.hpp"
#include "context.hpp"
#include "output.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace dermis::cli {

struct RangeJob {
    nlohmann::json scene;                  ///< the document every batch sends
    const ContentFiles* content = nullptr; ///< its files by address (scene files), or none
    std::string format, view, out;         ///< frame format, view, file pattern
    std::vector<double> times;             ///< frame k's time
    std::vector<std::size_t> pending;      ///< the frames to render, ascending
    std::size_t batch = 100;               ///< frames per request
    int parallel = 1;                      ///< requests in flight at once
};

struct RangeOutcome {
    std::size_t written = 0, contentSent = 0, retries = 0;
    std::vector<std::pair<std::size_t, std::string>> failed; ///< frame, message (ascending)
    bool interrupted = false;
};

/// Renders `job` (progress steps as frames arrive; retries noted on stderr). Throws CliError:
/// exit 1 when the server refuses a batch, exit 3 when no batch could be delivered after the
/// retries (frames already written stay: --resume goes on from them).
RangeOutcome renderRange(const GlobalOptions& options, const RangeJob& job, Progress& progress);

} // namespace dermis::cli
