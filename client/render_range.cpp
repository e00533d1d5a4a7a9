// The frame range of `render`: batches on a shared queue, taken by worker threads.
#include "render_range.hpp"

#include "batch.hpp"
#include "frames.hpp"
#include "http_client.hpp"
#include "common/sha256.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>

namespace dermis::cli {

RangeOutcome renderRange(const GlobalOptions& options, const RangeJob& job, Progress& progress) {
    std::mutex mutex; // guards everything below and `progress`
    std::deque<std::vector<std::size_t>> queue;
    for (std::size_t at = 0; at < job.pending.size(); at += job.batch)
        queue.emplace_back(job.pending.begin() + static_cast<std::ptrdiff_t>(at),
                           job.pending.begin() + static_cast<std::ptrdiff_t>(std::min(job.pending.size(), at + job.batch)));
    RangeOutcome out;
    std::optional<CliError> fatal;
    std::size_t left = job.pending.size(); // frames not yet written or failed

    // One content key per worker: the scene's content (its addresses, or the document) plus the
    // worker's slot, so that behind nginx each worker's batches stay on one replica (content sent
    // once there) while --parallel workers still spread over replicas.
    std::string contentOf;
    if (job.content && !job.content->empty())
        for (const auto& [address, path] : job.content->paths) contentOf += address + "\n";
    else
        contentOf = job.scene.dump();
    const std::string contentKey = toHex(sha256(std::string_view(contentOf))).substr(0, 16);
    std::atomic<int> slots{0};
    const auto worker = [&] {
        try {
            Http http(options);
            http.setContentKey(contentKey + "-" + std::to_string(slots++));
            int stalls = 0; // broken answers in a row without a frame
            for (;;) {
                std::vector<std::size_t> chunk;
                {
                    std::lock_guard<std::mutex> lock(mutex);
                    if (fatal || out.interrupted || queue.empty()) return;
                    chunk = std::move(queue.front());
                    queue.pop_front();
                }
                nlohmann::json frames = nlohmann::json::array();
                for (std::size_t k : chunk) frames.push_back({{"time", job.times[k]}});
                BatchOutcome r = renderBatch(http, job.scene, frames, job.format, job.view, [&](std::size_t j, std::string bytes) {
                    const std::size_t k = chunk[j];
                    const std::string path = framePath(job.out, static_cast<int>(k));
                    writeFileAtomically(path, bytes);
                    std::lock_guard<std::mutex> lock(mutex);
                    ++out.written;
                    --left;
                    progress.step("frame " + std::to_string(k) + " " + path);
                    return true;
                }, job.content);
                std::unique_lock<std::mutex> lock(mutex);
                out.contentSent += r.contentSent;
                if (r.interrupted) {
                    out.interrupted = true;
                    return;
                }
                if (r.broken) {
                    // A replica went away (or the connection broke): the frames not received go
                    // back on the queue, first, after a pause that grows while none arrives.
                    std::vector<std::size_t> rest(chunk.begin() + static_cast<std::ptrdiff_t>(r.received), chunk.end());
                    stalls = r.received > 0 ? 1 : stalls + 1;
                    if (stalls > std::max(0, options.retries) + 1) {
                        fatal = CliError(kExitCannotConnect, r.brokenWhy + " (after " + std::to_string(out.retries) +
                                                                 " retries; run again with --resume for the rest)");
                        return;
                    }
                    ++out.retries;
                    progress.note("retrying the batch of frames " + std::to_string(chunk.front()) + "–" +
                                  std::to_string(chunk.back()) + " (" + std::to_string(rest.size()) + " not received) after: " +
                                  r.brokenWhy);
                    queue.push_front(std::move(rest));
                    lock.unlock();
                    std::this_thread::sleep_for(std::chrono::duration<double>(0.25 * double(1 << std::min(stalls, 5))));
                    continue;
                }
                stalls = 0;
                if (r.failedFrame >= 0) {
                    // The stream ended at that frame: note it and go on after it.
                    const auto f = static_cast<std::size_t>(r.failedFrame);
                    out.failed.emplace_back(chunk[f], r.failure);
                    --left;
                    progress.step("frame " + std::to_string(chunk[f]) + " failed: " + r.failure, true);
                    if (f + 1 < chunk.size())
                        queue.emplace_front(chunk.begin() + static_cast<std::ptrdiff_t>(f + 1), chunk.end());
                }
            }
        } catch (const CliError& e) {
            std::lock_guard<std::mutex> lock(mutex);
            if (!fatal) fatal = e;
        }
    };

    const int n = std::max(1, std::min<int>(job.parallel, static_cast<int>(queue.size())));
    std::vector<std::thread> threads;
    for (int t = 1; t < n; ++t) threads.emplace_back(worker);
    worker();
    for (std::thread& t : threads) t.join();
    if (fatal) throw *fatal;
    std::sort(out.failed.begin(), out.failed.end());
    return out;
}

} // namespace dermis::cli
