// Dermis HTTP shell — a scene's server-sent events: "hello", then one "change" per edit (": ping"
// comments every second while idle). Each open stream holds an HTTP worker thread, so at most
// half the workers stream at once, and one peer address at most half of those (more: 503 +
// Retry-After). A stream ends when the scene is
// deleted, the client goes away or the server stops. Credentials are checked when the stream
// opens (bearer token or session cookie); ending a session does not close its open streams.
#include "api_internal.hpp"

namespace dermis::api_detail {

void installEventRoutes(RouteTable& t) {
    t.add("GET", "/scenes/{id}/events", [](Api::Impl& a, const Req& req, Res& res) {
        const std::string id = req.matches[1];
        const std::string ip = req.remote_addr;
        if (const std::string why = a.takeStream(ip); !why.empty()) {
            res.set_header("Retry-After", "5");
            return sendError(res, 503, "unavailable", why, "");
        }
        auto sub = a.svc.subscribe(id);
        if (!sub) {
            a.giveStream(ip);
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
                // Server-sent-event framing (the service's events are typed: SceneEvent).
                const std::string text = "event: " + e->name + "\ndata: " + e->data + "\n\n";
                return sink.write(text.data(), text.size());
            },
            [api, id, ip, subscription](bool) { // runs once, when the response is destroyed
                api->svc.unsubscribe(id, subscription);
                api->giveStream(ip);
            });
    });
}

} // namespace dermis::api_detail

namespace dermis {

std::string Api::Impl::takeStream(const std::string& ip) {
    std::lock_guard<std::mutex> lock(streamsMutex);
    int& mine = streamsByAddress[ip];
    if (mine >= maxStreamsPerAddress()) {
        if (mine == 0) streamsByAddress.erase(ip);
        return "dermis-server: this address has " + std::to_string(maxStreamsPerAddress()) +
               " event streams open, the most one address may keep; close one or retry later";
    }
    if (streams.load() >= maxStreams()) {
        if (mine == 0) streamsByAddress.erase(ip);
        return "dermis-server: " + std::to_string(maxStreams()) +
               " event streams are open, the most this server keeps; retry later";
    }
    ++mine;
    ++streams;
    return "";
}

void Api::Impl::giveStream(const std::string& ip) {
    std::lock_guard<std::mutex> lock(streamsMutex);
    auto it = streamsByAddress.find(ip);
    if (it != streamsByAddress.end() && --it->second <= 0) streamsByAddress.erase(it);
    --streams;
}

} // namespace dermis
