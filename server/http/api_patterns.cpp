// Dermis HTTP shell — pattern routes: the manifest, custom image uploads, previews, delete.
#include "api_internal.hpp"

namespace dermis::api_detail {

void installPatternRoutes(RouteTable& t) {
    t.add("GET", "/patterns",
          [](Api::Impl& a, const Req&, Res& res) { sendJson(res, 200, a.svc.listPatterns()); });
    t.add("POST", "/patterns", [](Api::Impl& a, const Req& req, Res& res) {
        if (!hasContentType(req, {"image/*", "application/octet-stream"}))
            return sendError(res, 415, "unsupported",
                             "dermis-server: body: expected an image Content-Type", "body");
        bool existing = false;
        auto r = a.svc.addPattern(bytesOf(req.body), req.get_param_value("name"), &existing);
        if (!r) {
            Error e = r.error();
            if (e.code == ErrorCode::Parse)
                return sendError(res, 415, "unsupported", e.message, "body");
            return sendError(res, e);
        }
        sendJson(res, existing ? 200 : 201, *r); // 200: these bytes were uploaded before
    });
    t.add("GET", "/patterns/{id}/image", [](Api::Impl& a, const Req& req, Res& res) {
        std::optional<int> size;
        if (!intParam(req, res, "size", size)) return;
        auto r = a.svc.patternImage(req.matches[1], size.value_or(256));
        if (!r) return sendError(res, r.error());
        sendImage(res, std::move(*r));
    });
    t.add("DELETE", "/patterns/{id}", [](Api::Impl& a, const Req& req, Res& res) {
        auto r = a.svc.deletePattern(req.matches[1]);
        if (!r) return sendError(res, r.error());
        res.status = 204;
    });
}

} // namespace dermis::api_detail
