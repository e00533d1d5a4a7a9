// Dermis HTTP shell — inspection routes (SPEC §6, CPU only): probe (why a texel has its height)
// activation (each placement's t over a clip, with flags), lint, pick (a frame pixel or a texture
// point), a placement's footprint outline in the texture view (SPEC §8) and drivers (each
// placement's θ and t now).
#include "api_internal.hpp"

#include <cmath>

namespace dermis::api_detail {

void installInspectRoutes(RouteTable& t) {
    t.add("GET", "/scenes/{id}/pick", [](Api::Impl& a, const Req& req, Res& res) {
        if (req.has_param("u") || req.has_param("v")) { // texture point (the texture view)
            std::optional<double> u, v;
            if (!numberParam(req, res, "u", u) || !numberParam(req, res, "v", v)) return;
            if (!u || !v)
                return sendError(res, 422, "invalid_argument", "dermis::Api: u and v are both required",
                                 !u ? "u" : "v");
            if (req.has_param("x") || req.has_param("y"))
                return sendError(res, 422, "invalid_argument",
                                 "dermis::Api: pick takes a frame pixel (x, y) or a texture point (u, v), not both", "u");
            auto r = a.svc.pickUv(req.matches[1], *u, *v);
            if (!r) return sendError(res, r.error());
            return sendJson(res, 200, *r);
        }
        FrameParams p;
        std::optional<double> x, y;
        if (!numberParam(req, res, "x", x) || !numberParam(req, res, "y", y) ||
            !intParam(req, res, "width", p.width) || !intParam(req, res, "height", p.height) ||
            !numberParam(req, res, "yaw", p.yaw) || !numberParam(req, res, "pitch", p.pitch) ||
            !numberParam(req, res, "distance", p.distance) || !numberParam(req, res, "time", p.time) ||
            !targetParam(req, res, p.target))
            return;
        if (!x || !y)
            return sendError(res, 422, "invalid_argument", "dermis::Api: x and y are required",
                             !x ? "x" : "y");
        auto r = a.svc.pick(req.matches[1], p, *x, *y);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
    t.add("GET", "/scenes/{id}/placements/{pid}/outline", [](Api::Impl& a, const Req& req, Res& res) {
        std::optional<double> u, v;
        std::optional<std::uint64_t> rev;
        if (!numberParam(req, res, "u", u) || !numberParam(req, res, "v", v) || !revisionParam(req, res, "revision", rev))
            return;
        if (u.has_value() != v.has_value())
            return sendError(res, 422, "invalid_argument", "dermis::Api: u and v go together (a texture point to hit test)",
                             !u ? "u" : "v");
        std::optional<std::array<double, 2>> at;
        if (u) at = std::array<double, 2>{*u, *v};
        auto r = a.svc.placementOutline(req.matches[1], req.matches[2], rev, at);
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
    t.add("GET", "/scenes/{id}/drivers", [](Api::Impl& a, const Req& req, Res& res) {
        FrameParams p;
        if (!intParam(req, res, "width", p.width) || !intParam(req, res, "height", p.height) ||
            !numberParam(req, res, "yaw", p.yaw) || !numberParam(req, res, "pitch", p.pitch) ||
            !numberParam(req, res, "distance", p.distance) || !numberParam(req, res, "time", p.time) ||
            !revisionParam(req, res, "revision", p.revision))
            return;
        auto r = a.svc.drivers(req.matches[1], p);
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
