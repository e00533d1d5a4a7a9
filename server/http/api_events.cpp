// Dermis HTTP shell — a scene's server-sent events: "hello", then one "change" per edit (": ping"
// comments every second while idle). Each open stream holds an HTTP worker thread, so at most
// half the workers stream at once (more: 503 + Retry-After). A stream ends when the scene is
// deleted, the client goes away or the server stops. Credentials are checked when the stream
// opens (bearer token or session cookie); ending a session does not close its open streams.
#include "http/api_internal.hpp"

namespace dermis::api_detail {

void installEventRoutes(RouteTable& t) {
    t.add("GET", "/scenes/{id}/events", [](Api::Impl& a, const Req& req, Res& res) {
        const std::string id = req.matches[1];
        if (a.streams.fetch_add(1) >= a.maxStreams()) {
            a.streams.fetch_sub(1);
            return sendError(res, 503, "unavailable",
                             "dermis-server: " + std::to_string(a.maxStreams()) +
                                 " event streams are open, the most this server keeps; retry later",
                             "");
        }
        auto sub = a.svc.subscribe(id);
        if (!sub) {
            a.streams.fetch_sub(1);
            return sendError(res, sub.error());
        }
        res.set_header("Cache-Control", "no-cache");
        auto subscription = *sub;
        Api::Impl* api = &a;
        res.set_chunked_content_provider(
            "text/event-stream",
            [api, subscription](std::size_t, httplib::DataSink& sink) {
                if (api->stopping) return false;
                auto e = subscription->next(1000);
                if (!e) {
                    if (subscription->closed()) {
                        sink.done();
                        return true;
                    }
                    static const std::string ping = ": ping\n\n";
                    return sink.write(ping.data(), ping.size());
                }
                return sink.write(e->data(), e->size());
            },
            [api, id, subscription](bool) { // runs once, when the response is destroyed
                api->svc.unsubscribe(id, subscription);
                api->streams.fetch_sub(1);
            });
    });
}

} // namespace dermis::api_detail
