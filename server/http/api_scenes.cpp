// Dermis HTTP shell — scene routes: documents (list, create, get, replace, delete), placements
// (add, reorder, patch, remove, mirror, propose, transfer), the pose (replace, merge), history (revisions, a revision's
// document, revert) and presence. Every edit answers {"id", "revision", "scene"} with
// `ETag: "r<revision>"`, honours `If-Match` (412 stale_revision with the current revision) and
// records `X-Dermis-Client`; a failed edit changes nothing (the Service validates first).
#include "api_internal.hpp"

namespace dermis::api_detail {

namespace {

using EditFn = std::function<Result<json>(Service&, const Req&, const json&, const EditContext&)>;

/// A route whose JSON body goes to one Service edit: `status`, its document and its ETag on
/// success, the document error otherwise.
Handler jsonEdit(int status, EditFn edit) {
    return [status, edit = std::move(edit)](Api::Impl& a, const Req& req, Res& res) {
        EditContext ctx;
        if (!editContext(req, res, ctx)) return;
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = edit(a.svc, req, body, ctx);
        if (!r) return sendDocError(res, r.error());
        setEtag(res, *r);
        sendJson(res, status, *r);
    };
}


void installDocumentRoutes(RouteTable& t) {
    t.add("GET", "/scenes",
          [](Api::Impl& a, const Req&, Res& res) { sendJson(res, 200, a.svc.listScenes()); });
    t.add("POST", "/scenes", [](Api::Impl& a, const Req& req, Res& res) {
        EditContext ctx;
        if (!editContext(req, res, ctx)) return;
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = a.svc.createScene(body, ctx);
        if (!r) return sendDocError(res, r.error());
        res.set_header("Location", kPrefix + "/scenes/" + (*r)["id"].get<std::string>());
        setEtag(res, *r);
        sendJson(res, 201, *r);
    });
    t.add("GET", "/scenes/{id}", [](Api::Impl& a, const Req& req, Res& res) {
        std::optional<std::uint64_t> revision;
        if (!revisionParam(req, res, "revision", revision)) return;
        if (revision) { // the stored text as it is (Service::getSceneRevisionText)
            auto text = a.svc.getSceneRevisionText(req.matches[1], *revision);
            if (!text) return sendError(res, text.error());
            res.set_header("ETag", sceneEtag(*revision));
            res.status = 200;
            res.set_content(std::move(*text), "application/json");
            return;
        }
        auto r = a.svc.getScene(req.matches[1]);
        if (!r) return sendError(res, r.error());
        setEtag(res, *r);
        sendJson(res, 200, *r);
    });
    t.add("PUT", "/scenes/{id}",
          jsonEdit(200, [](Service& s, const Req& req, const json& body, const EditContext& ctx) {
              return s.replaceScene(req.matches[1], body, ctx);
          }));
    t.add("DELETE", "/scenes/{id}", [](Api::Impl& a, const Req& req, Res& res) {
        EditContext ctx;
        if (!editContext(req, res, ctx)) return;
        auto r = a.svc.deleteScene(req.matches[1], ctx);
        if (!r) return sendError(res, r.error());
        res.status = 204;
    });
}

void installPlacementRoutes(RouteTable& t) {
    t.add("POST", "/scenes/{id}/placements",
          jsonEdit(201, [](Service& s, const Req& req, const json& body, const EditContext& ctx) {
              return s.addPlacement(req.matches[1], body, ctx);
          }));
    t.add("PUT", "/scenes/{id}/placements",
          jsonEdit(200, [](Service& s, const Req& req, const json& body, const EditContext& ctx) {
              return s.reorderPlacements(req.matches[1], body, ctx);
          }));
    t.add("PATCH", "/scenes/{id}/placements/{pid}",
          jsonEdit(200, [](Service& s, const Req& req, const json& body, const EditContext& ctx) {
              return s.patchPlacement(req.matches[1], req.matches[2], body, ctx);
          }));
    t.add("DELETE", "/scenes/{id}/placements/{pid}", [](Api::Impl& a, const Req& req, Res& res) {
        EditContext ctx;
        if (!editContext(req, res, ctx)) return;
        auto r = a.svc.deletePlacement(req.matches[1], req.matches[2], ctx);
        if (!r) return sendDocError(res, r.error());
        setEtag(res, *r);
        sendJson(res, 200, *r);
    });
    t.add("POST", "/scenes/{id}/placements/{pid}/mirror", [](Api::Impl& a, const Req& req, Res& res) {
        EditContext ctx;
        if (!editContext(req, res, ctx)) return;
        std::optional<bool> update;
        if (!boolParam(req, res, "update", update)) return;
        auto r = a.svc.mirrorPlacement(req.matches[1], req.matches[2], ctx, update.value_or(false));
        if (!r) return sendDocError(res, r.error());
        setEtag(res, *r);
        sendJson(res, update.value_or(false) ? 200 : 201, *r);
    });
    // SPEC §8: a pattern set proposed for the character (?apply=true adds it in one revision),
    // and another scene's placements carried over onto it.
    t.add("POST", "/scenes/{id}/propose", [](Api::Impl& a, const Req& req, Res& res) {
        EditContext ctx;
        if (!editContext(req, res, ctx)) return;
        std::optional<bool> apply;
        if (!boolParam(req, res, "apply", apply)) return;
        auto r = a.svc.propose(req.matches[1], apply.value_or(false), ctx);
        if (!r) return sendDocError(res, r.error());
        if (apply.value_or(false)) setEtag(res, *r);
        sendJson(res, apply.value_or(false) ? 201 : 200, *r);
    });
    t.add("POST", "/scenes/{id}/transfer", [](Api::Impl& a, const Req& req, Res& res) {
        EditContext ctx;
        if (!editContext(req, res, ctx)) return;
        std::optional<bool> apply;
        if (!boolParam(req, res, "apply", apply)) return;
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = a.svc.transfer(req.matches[1], body, apply.value_or(true), ctx);
        if (!r) return sendDocError(res, r.error());
        if (apply.value_or(true)) setEtag(res, *r);
        sendJson(res, apply.value_or(true) ? 201 : 200, *r);
    });
    t.add("PUT", "/scenes/{id}/pose",
          jsonEdit(200, [](Service& s, const Req& req, const json& body, const EditContext& ctx) {
              return s.putPose(req.matches[1], body, ctx);
          }));
    t.add("PATCH", "/scenes/{id}/pose",
          jsonEdit(200, [](Service& s, const Req& req, const json& body, const EditContext& ctx) {
              return s.patchPose(req.matches[1], body, ctx);
          }));
}

void installHistoryRoutes(RouteTable& t) {
    t.add("GET", "/scenes/{id}/revisions", [](Api::Impl& a, const Req& req, Res& res) {
        std::optional<int> limit;
        std::optional<std::uint64_t> before;
        if (!intParam(req, res, "limit", limit) || !revisionParam(req, res, "before", before)) return;
        if (limit && (*limit < 1 || *limit > 1000))
            return sendError(res, 422, "invalid_argument", "dermis::Api: limit: must be in [1, 1000]",
                             "limit");
        auto r = a.svc.listRevisions(req.matches[1], static_cast<std::size_t>(limit.value_or(50)),
                                     before);
        if (!r) return sendError(res, r.error());
        setEtag(res, *r);
        sendJson(res, 200, *r);
    });
    t.add("POST", "/scenes/{id}/revert",
          jsonEdit(200, [](Service& s, const Req& req, const json& body,
                           const EditContext& ctx) -> Result<json> {
              const auto rev = body.is_object() ? body.find("revision") : body.end();
              if (!body.is_object() || rev == body.end() || !rev->is_number_unsigned() ||
                  rev->get<std::uint64_t>() == 0)
                  return makeError(ErrorCode::InvalidArgument, "dermis::Api", "/revision",
                                   "the body must be {\"revision\": N} with N >= 1");
              for (auto it = body.begin(); it != body.end(); ++it)
                  if (it.key() != "revision")
                      return makeError(ErrorCode::InvalidArgument, "dermis::Api", "/" + it.key(),
                                       "only \"revision\" may be given");
              return s.revert(req.matches[1], rev->get<std::uint64_t>(), ctx);
          }));
    t.add("POST", "/scenes/{id}/presence", [](Api::Impl& a, const Req& req, Res& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = a.svc.postPresence(req.matches[1], body, req.remote_addr);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
    t.add("GET", "/scenes/{id}/presence", [](Api::Impl& a, const Req& req, Res& res) {
        auto r = a.svc.listPresence(req.matches[1]);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
}

} // namespace

void installSceneRoutes(RouteTable& t) {
    installDocumentRoutes(t);
    installPlacementRoutes(t);
    installHistoryRoutes(t);
}

} // namespace dermis::api_detail
