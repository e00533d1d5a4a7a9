// Dermis HTTP shell — scene routes: documents (list, create, get, replace, delete), placements
// (add, reorder, patch, remove) and the pose (replace, merge). Every edit answers
// {"id", "revision", "scene"}; a failed edit changes nothing (the Service validates first).
#include "http/api_internal.hpp"

namespace dermis::api_detail {

namespace {

/// A route whose JSON body goes to one Service edit: `status` and its document on success, the
/// document error otherwise.
Handler jsonEdit(int status, std::function<Result<json>(Service&, const Req&, const json&)> edit) {
    return [status, edit = std::move(edit)](Api::Impl& a, const Req& req, Res& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = edit(a.svc, req, body);
        if (!r) return sendDocError(res, r.error());
        sendJson(res, status, *r);
    };
}

} // namespace

void installSceneRoutes(RouteTable& t) {
    t.add("GET", "/scenes",
          [](Api::Impl& a, const Req&, Res& res) { sendJson(res, 200, a.svc.listScenes()); });
    t.add("POST", "/scenes", [](Api::Impl& a, const Req& req, Res& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = a.svc.createScene(body);
        if (!r) return sendDocError(res, r.error());
        res.set_header("Location", kPrefix + "/scenes/" + (*r)["id"].get<std::string>());
        sendJson(res, 201, *r);
    });
    t.add("GET", "/scenes/{id}", [](Api::Impl& a, const Req& req, Res& res) {
        auto r = a.svc.getScene(req.matches[1]);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
    t.add("PUT", "/scenes/{id}", jsonEdit(200, [](Service& s, const Req& req, const json& body) {
              return s.replaceScene(req.matches[1], body);
          }));
    t.add("DELETE", "/scenes/{id}", [](Api::Impl& a, const Req& req, Res& res) {
        auto r = a.svc.deleteScene(req.matches[1]);
        if (!r) return sendError(res, r.error());
        res.status = 204;
    });

    // --- placements
    t.add("POST", "/scenes/{id}/placements",
          jsonEdit(201, [](Service& s, const Req& req, const json& body) {
              return s.addPlacement(req.matches[1], body);
          }));
    t.add("PUT", "/scenes/{id}/placements",
          jsonEdit(200, [](Service& s, const Req& req, const json& body) {
              return s.reorderPlacements(req.matches[1], body);
          }));
    t.add("PATCH", "/scenes/{id}/placements/{pid}",
          jsonEdit(200, [](Service& s, const Req& req, const json& body) {
              return s.patchPlacement(req.matches[1], req.matches[2], body);
          }));
    t.add("DELETE", "/scenes/{id}/placements/{pid}", [](Api::Impl& a, const Req& req, Res& res) {
        auto r = a.svc.deletePlacement(req.matches[1], req.matches[2]);
        if (!r) return sendDocError(res, r.error());
        sendJson(res, 200, *r);
    });

    // --- pose
    t.add("PUT", "/scenes/{id}/pose",
          jsonEdit(200, [](Service& s, const Req& req, const json& body) {
              return s.putPose(req.matches[1], body);
          }));
    t.add("PATCH", "/scenes/{id}/pose",
          jsonEdit(200, [](Service& s, const Req& req, const json& body) {
              return s.patchPose(req.matches[1], body);
          }));
}

} // namespace dermis::api_detail
