// dermis (client) — the HTTP client wrapper over cpp-httplib: one keep-alive connection to the
// server's /api/v1, bearer token, timeouts, retries of idempotent requests, and the mapping of
// answers to exit codes:
//   * no connection (refused, DNS, timeout, broken stream) → CliError exit 3
//     "cannot connect to <server>: <reason>";
//   * an error answer (status ≥ 400) → CliError exit 1 with the server's error message and field
//     ({"error": {"code", "message", "field"}}), or "HTTP <status>" when the body is not that.
// Retried (--retries times, backoff 0.25 s · 2^k, or the server's Retry-After up to 5 s): GET,
// PUT, DELETE and content-addressed uploads (`retry` true), on no connection or 503 only.
// Bounded (issue #27): every request must be answered whole within --deadline (a watchdog stops
// it, exit 3: `--timeout` alone is per read, and a byte a second never ends), and the command
// within --max-time when set; answers kept in memory (JSON) stop at kMaxAnswerBytes (exit 3);
// frames and maps stream to their file (download). A redirect (3xx) is never followed: exit 1,
// naming where it pointed.
// Not thread-safe: one Http per thread.
#pragma once

#include "context.hpp"

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace dermis::cli {

struct Reply {
    int status = 0;
    std::string body;
    httplib::Headers headers;
    std::string header(const std::string& name) const;
};

/// The most bytes of an answer kept in memory (JSON answers, error bodies): 64 MiB.
inline constexpr std::size_t kMaxAnswerBytes = std::size_t(64) << 20;

/// What a download may be: content types accepted and the file's signature check.
enum class FileKind { Png, Jpeg, Exr, RawFloats };

/// The kind of a frame or map file by its format name (png, png16, jpeg, exr, f32).
FileKind fileKindOf(const std::string& format);

/// "a=1&b=x%20y" from (name, value) pairs, values percent-encoded; "" for none.
std::string queryString(const std::vector<std::pair<std::string, std::string>>& params);

class Http {
public:
    /// Fails (CliError exit 2, field "--server") when the server URL is not http://host[:port][/prefix].
    explicit Http(const GlobalOptions& options);

    /// GET `path` (under /api/v1, with its query) — retried. Error answers throw (exit 1).
    Reply get(const std::string& path);
    nlohmann::json getJson(const std::string& path);
    /// A request with a body. `retry`: safe to send twice (PUT, DELETE, content-addressed uploads).
    /// Error answers throw (exit 1).
    Reply send(const std::string& method, const std::string& path, const std::string& body,
               const std::string& contentType, bool retry, httplib::Headers extra = {});
    nlohmann::json sendJson(const std::string& method, const std::string& path,
                            const nlohmann::json& body, httplib::Headers extra = {});
    /// A multipart/form-data POST (model uploads of a .gltf with its files) — retried.
    Reply postMultipart(const std::string& path, const httplib::MultipartFormDataItems& items);

    /// A streamed request: `onHeaders` sees the status and headers first (return false to stop);
    /// then `onData` each piece of the body as it arrives (return false to stop). An error status
    /// is read (up to kMaxAnswerBytes) and thrown (exit 1), a redirect too, without calling
    /// onData. Not retried. Returns false when a callback stopped it; throws exit 3 when the
    /// connection failed or broke, or --deadline passed (`deadline` false: an event stream, which
    /// --max-time alone bounds).
    bool stream(const std::string& method, const std::string& path, const std::string& body,
                const std::string& contentType,
                const std::function<bool(int status, const httplib::Headers&)>& onHeaders,
                const std::function<bool(const char*, std::size_t)>& onData, bool deadline = true);

    /// GETs `path` into file `out`, streamed (never whole in memory), through "<out>.dermis-part"
    /// renamed into place only when the answer is a 200 of `kind`'s content type whose bytes
    /// start with its signature (PNG, JPEG, OpenEXR; raw floats: a whole number of floats) and
    /// arrived whole. Anything else leaves no file: a redirect or an error answer → exit 1, a
    /// wrong content type or signature → exit 1 naming what came, a broken connection or
    /// --deadline → exit 3. Not retried. Returns the answer's status, headers and byte count.
    Reply download(const std::string& path, const std::string& out, FileKind kind);

    /// Sent as `X-Dermis-Content-Key` with every streamed request (batches) from now on: a proxy
    /// in front of replicas routes the same key to the same replica (docker/nginx-replicas.conf),
    /// so content sent after a 409 missing_content lands where it was asked for. "" sends none.
    void setContentKey(std::string key) { contentKey_ = std::move(key); }

    /// The full path for a route: prefix + "/api/v1" + `path`.
    std::string url(const std::string& path) const { return prefix_ + path; }
    const std::string& server() const { return server_; }

    class Watchdog;

private:
    Reply perform(const httplib::Request& req, bool retry);
    [[noreturn]] void throwTransport(httplib::Error error, bool deadlinePassed = false) const;
    /// Seconds the next request may take: --deadline, less when --max-time ends sooner.
    double requestSeconds(bool deadline) const;

    GlobalOptions options_;
    std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
    std::string server_, prefix_;
    std::string contentKey_;
    std::unique_ptr<httplib::Client> client_;
};

/// The CliError for an error answer: the server's {"error": {message, field}} → exit 1.
CliError serverError(int status, const std::string& body);

} // namespace dermis::cli
