// dermis (client) — the HTTP client wrapper over cpp-httplib: one keep-alive connection to the
// server's /api/v1, bearer token, timeouts, retries of idempotent requests, and the mapping of
// answers to exit codes:
//   * no connection (refused, DNS, timeout, broken stream) → CliError exit 3
//     "cannot connect to <server>: <reason>";
//   * an error answer (status ≥ 400) → CliError exit 1 with the server's error message and field
//     ({"error": {"code", "message", "field"}}), or "HTTP <status>" when the body is not that.
// Retried (--retries times, backoff 0.25 s · 2^k, or the server's Retry-After up to 5 s): GET,
// PUT, DELETE and content-addressed uploads (`retry` true), on no connection or 503 only.
// Not thread-safe: one Http per thread.
#pragma once

#include "context.hpp"

#include <httplib.h>
#include <nlohmann/json.hpp>

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
    /// is read whole and thrown (exit 1) without calling onData. Not retried. Returns false when
    /// a callback stopped it; throws exit 3 when the connection failed or broke.
    bool stream(const std::string& method, const std::string& path, const std::string& body,
                const std::string& contentType,
                const std::function<bool(int status, const httplib::Headers&)>& onHeaders,
                const std::function<bool(const char*, std::size_t)>& onData);

    /// The full path for a route: prefix + "/api/v1" + `path`.
    std::string url(const std::string& path) const { return prefix_ + path; }
    const std::string& server() const { return server_; }

private:
    Reply perform(const httplib::Request& req, bool retry);
    [[noreturn]] void throwTransport(httplib::Error error) const;

    GlobalOptions options_;
    std::string server_, prefix_;
    std::unique_ptr<httplib::Client> client_;
};

/// The CliError for an error answer: the server's {"error": {message, field}} → exit 1.
CliError serverError(int status, const std::string& body);

} // namespace dermis::cli
