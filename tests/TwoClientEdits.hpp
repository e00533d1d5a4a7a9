// Test helper — two clients editing one scene at a steady rate (SPEC §6 Concurrency), each
// sending If-Match with the revision of its own last answer (a refusal's answer names the
// current revision, which the next edit then sends), and what became of their edits: refusals
// and lost updates. Used on the service (ServiceHistoryTest) and over HTTP (EditRebaseHttpTest).
//
// Lost updates, counted from the acknowledged edits and the final document:
//  * an acknowledged edit of a placement whose If-Match is older than the revision of the
//    previous acknowledged edit of that placement by the other client (it overwrote an edit it
//    had not seen);
//  * a placement whose final value is not that of its last acknowledged edit.
#pragma once

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <ostream>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace dermis::test {

/// What an edit answered: 200 (applied; `revision` the new one), 412 (refused; `revision` the
/// current one) or another status (an error the run counts).
struct EditAnswer {
    int status = 0;
    std::uint64_t revision = 0;
};

/// Sets placement `pid`'s h to `value` with If-Match `ifMatch` on behalf of client 0 or 1.
using EditCall = std::function<EditAnswer(int client, const std::string& pid, double value,
                                          std::uint64_t ifMatch)>;

struct TwoClientRun {
    struct Acked {
        int client = 0;
        std::string pid;
        double value = 0.0;
        std::uint64_t base = 0, revision = 0;
    };
    int edits[2] = {0, 0}, refusals[2] = {0, 0}, errors = 0, lost = 0;
    std::vector<Acked> acked;

    int totalRefusals() const { return refusals[0] + refusals[1]; }
    int totalEdits() const { return edits[0] + edits[1]; }
};

inline std::ostream& operator<<(std::ostream& os, const TwoClientRun& r) {
    return os << "client A " << r.edits[0] << " edits, " << r.refusals[0] << " refused; client B "
              << r.edits[1] << " edits, " << r.refusals[1] << " refused; " << r.acked.size()
              << " acknowledged, " << r.lost << " lost updates, " << r.errors << " errors";
}

/// Runs the two clients for `seconds` at `rate` edits per second each (±20% jitter): client 0
/// edits `pids[0]`, client 1 `pids[1]` (the same id for a same-placement run), both starting
/// from revision `start`; `finalDoc()` is the scene document afterwards (placements' h read).
inline TwoClientRun runTwoClients(const EditCall& edit, const std::function<nlohmann::json()>& finalDoc,
                                  const std::string pids[2], std::uint64_t start, double seconds,
                                  double rate) {
    TwoClientRun run;
    std::mutex m;
    const auto t0 = std::chrono::steady_clock::now();
    const auto until = t0 + std::chrono::duration<double>(seconds);
    auto client = [&](int c) {
        std::mt19937 rng(17 + c);
        std::uniform_real_distribution<double> jitter(0.8, 1.2);
        std::uint64_t base = start;
        for (int k = 0; std::chrono::steady_clock::now() < until; ++k) {
            const double value = (c == 0 ? 1.0 : 50.0) + 0.01 * k;
            const EditAnswer a = edit(c, pids[c], value, base);
            {
                std::lock_guard<std::mutex> lock(m);
                ++run.edits[c];
                if (a.status == 200) run.acked.push_back({c, pids[c], value, base, a.revision});
                else if (a.status == 412) ++run.refusals[c];
                else ++run.errors;
            }
            if (a.status == 200 || a.status == 412) base = a.revision;
            std::this_thread::sleep_for(std::chrono::duration<double>(jitter(rng) / rate));
        }
    };
    std::thread a(client, 0), b(client, 1);
    a.join();
    b.join();
    std::sort(run.acked.begin(), run.acked.end(),
              [](const auto& x, const auto& y) { return x.revision < y.revision; });
    std::map<std::string, const TwoClientRun::Acked*> last;
    for (const auto& e : run.acked) {
        auto prev = last.find(e.pid);
        if (prev != last.end() && prev->second->client != e.client && e.base < prev->second->revision)
            ++run.lost; // overwrote an acknowledged edit it had not seen
        last[e.pid] = &e;
    }
    const nlohmann::json doc = finalDoc();
    for (const auto& [pid, e] : last) {
        double h = -1.0;
        for (const auto& p : doc["placements"])
            if (p["id"] == pid) h = p.value("h", 1.0);
        if (std::abs(h - e->value) > 1e-9) ++run.lost; // the last acknowledged value is gone
    }
    return run;
}

} // namespace dermis::test
