// Dermis HTTP shell — inspection routes (SPEC §6, CPU only): probe (why a texel has its height)
// activation (each placement's t over a clip, with flags) and lint.
#include "http/api_internal.hpp"

namespace dermis::api_detail {

void installInspectRoutes(RouteTable& t) {
    t.add("GET", "/scenes/{id}/pick", [](Api::Impl& a, const Req& req, Res& res) {
        FrameParams p;
        std::optional<double> x, y;
        if (!numberParam(req, res, "x", x) || !numberParam(req, res, "y", y) ||
            !intParam(req, res, "width", p.width) || !intParam(req, res, "height", p.height) ||
            !numberParam(req, res, "yaw", p.yaw) || !numberParam(req, res, "pitch", p.pitch) ||
            !numberParam(req, res, "distance", p.distance) || !numberParam(req, res, "time", p.time))
            return;
        if (!x || !y)
            return sendError(res, 422, "invalid_argument", "dermis::Api: x and y are required",
                             !x ? "x" : "y");
        auto r = a.svc.pick(req.matches[1], p, *x, *y);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
    t.add("GET", "/scenes/{id}/probe", [](Api::Impl& a, const Req& req, Res& res) {
        std::optional<double> u, v, time;
        if (!numberParam(req, res, "u", u) || !numberParam(req, res, "v", v) ||
            !numberParam(req, res, "time", time))
            return;
        if (!u || !v)
            return sendError(res, 422, "invalid_argument", "dermis::Api: u and v are required",
                             !u ? "u" : "v");
        auto r = a.svc.probe(req.matches[1], *u, *v, time);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
    t.add("GET", "/scenes/{id}/activation", [](Api::Impl& a, const Req& req, Res& res) {
        std::optional<double> fps;
        if (!numberParam(req, res, "fps", fps)) return;
        if (!req.has_param("clip"))
            return sendError(res, 422, "invalid_argument", "dermis::Api: clip is required", "clip");
        auto r = a.svc.activation(req.matches[1], req.get_param_value("clip"), fps.value_or(30.0));
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
    t.add("GET", "/scenes/{id}/lint", [](Api::Impl& a, const Req& req, Res& res) {
        auto r = a.svc.lint(req.matches[1]);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
}

} // namespace dermis::api_detail
