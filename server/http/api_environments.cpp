// Dermis HTTP shell — environment routes (image-based light, `render.environment`): list,
// upload a Radiance .hdr or OpenEXR image, delete.
#include "api_internal.hpp"

namespace dermis::api_detail {

void installEnvironmentRoutes(RouteTable& t) {
    t.add("GET", "/environments",
          [](Api::Impl& a, const Req&, Res& res) { sendJson(res, 200, a.svc.listEnvironments()); });
    t.add("POST", "/environments", [](Api::Impl& a, const Req& req, Res& res) {
        if (!hasContentType(req, {"image/*", "application/octet-stream"}))
            return sendError(res, 415, "unsupported",
                             "dermis-server: body: expected an image Content-Type (image/vnd.radiance, "
                             "image/x-exr or application/octet-stream)",
                             "body");
        bool existing = false;
        auto r = a.svc.addEnvironment(bytesOf(req.body), req.get_param_value("name"), &existing);
        if (!r) {
            Error e = r.error();
            if (e.code == ErrorCode::Parse) return sendError(res, 415, "unsupported", e.message, "body");
            return sendError(res, e);
        }
        sendJson(res, existing ? 200 : 201, *r); // 200: these bytes were uploaded before
    });
    t.add("DELETE", "/environments/{id}", [](Api::Impl& a, const Req& req, Res& res) {
        auto r = a.svc.deleteEnvironment(req.matches[1]);
        if (!r) return sendError(res, r.error());
        res.status = 204;
    });
}

} // namespace dermis::api_detail
