// Dermis HTTP shell — the `/api/v1` routes over cpp-httplib, in front of a Service.
//
// One error policy: every failure answers {"error": {"code", "message", "field"}} with the status
// of its ErrorCode (mapped in one place, api.cpp statusOf): 400 malformed JSON or undecodable
// bytes or JSON nested deeper than 64 levels, 401 missing/wrong credentials, 404 unknown ids or
// routes, 405 known path with another method, 409 conflicts, 413 over a limit, 415 wrong
// content type or file type, 422 invalid values, 503 full render queue (with Retry-After).
// HTTP threads never touch GL: renders go through the Service to the renderer's thread.
// TCP_NODELAY is on (keep-alive requests otherwise stall ~26 ms on the delayed ACK).
//
// Credentials (when ApiOptions::token is set): every route but the open ones (/health and
// POST/DELETE /session) needs the bearer token, or the cookie of a browser session that
// POST /session opened with that token (sessions live in the Api, in memory: a restart forgets
// them). Layout: api.cpp holds the shared plumbing (errors, body parsing, the route table, auth,
// registration); each route family lives in its own api_<family>.cpp (see api_internal.hpp).
#pragma once

#include "service/service.hpp"

#include <memory>
#include <string>
#include <vector>

namespace dermis {

struct ApiOptions {
    std::string bind = "127.0.0.1";
    int port = 8080;       ///< 0 = any free port
    std::string token;     ///< every route but the open ones needs it (or a session); empty = none
    std::string webDir;    ///< static files served at / (the editor); empty = none
    int threads = 32;      ///< event streams open at once: threads / 2 (each holds a thread)
    /// Event streams one peer address may hold at once; 0: half the streams (so one client can
    /// never take them all). Behind a proxy every stream comes from its address: raise it there.
    int maxStreamsPerAddress = 0;
    /// Connections (docs/reliability.md): one thread each, at most maxConnections at once and
    /// maxConnectionsPerAddress per peer address; a request head must arrive within headSeconds.
    int maxConnections = 1024;
    int maxConnectionsPerAddress = 256;
    int headSeconds = 10;
    /// Bodies of JSON routes: at most this (and at most the upload limit); uploads (POST /models,
    /// POST /patterns, POST /environments, a multipart POST /render) at most
    /// ServerLimits::maxUploadBytes. Enforced while the body streams.
    std::size_t maxJsonBytes = 8u << 20;
    int maxSessions = 256; ///< browser sessions kept at once; the oldest is forgotten beyond
    int sessionMaxAgeSeconds = 12 * 3600; ///< a session's lifetime (and its cookie's Max-Age)
    /// Failed sign-ins (a wrong bearer token or session cookie, a wrong token on POST /session)
    /// an address may make before it must wait between attempts (docs/reliability.md).
    int authFreeFailures = 10;
};

/// A route of the API: method and OpenAPI path template ("/scenes/{id}"); `open` routes need no
/// credentials (OpenAPI `security: []`).
struct Route {
    std::string method, path;
    bool open = false;
};

class Api {
public:
    Api(Service& service, ApiOptions options);
    ~Api();
    /// Binds the socket; returns the port (useful with port 0). Fails (Io) when it cannot bind.
    Result<int> bind();
    /// Serves until stop(); call after bind().
    void run();
    /// Stops serving (from any thread) and closes event streams.
    void stop();

    /// Every route served under /api/v1 (generated from the table the routes are registered
    /// from), for the OpenAPI coverage test.
    static const std::vector<Route>& routes();

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

/// The OpenAPI 3 description served at /api/v1/openapi.yaml (embedded at build time).
std::string_view openapiYaml();
/// The JSON Schema of dermis.scene/1 (server/http/schemas/scene.json, embedded at build time).
std::string_view sceneSchemaJson();

} // namespace dermis
