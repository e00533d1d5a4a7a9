// Dermis HTTP shell — system routes: liveness (open), server info with the configured limits
// (the Service's, plus the HTTP layer's own session limits), the OpenAPI document and the JSON
// Schema of dermis.scene/1.
#include "api_internal.hpp"

namespace dermis::api_detail {

void installSystemRoutes(RouteTable& t) {
    t.addOpen("GET", "/health", [](Api::Impl&, const Req&, Res& res) {
        sendJson(res, 200, {{"status", "ok"}});
    });
    t.add("GET", "/info", [](Api::Impl& a, const Req&, Res& res) {
        json info = a.svc.info();
        info["limits"]["max_sessions"] = std::max(1, a.opt.maxSessions);
        info["limits"]["session_max_age_seconds"] = std::max(1, a.opt.sessionMaxAgeSeconds);
        sendJson(res, 200, info);
    });
    t.add("GET", "/openapi.yaml", [](Api::Impl&, const Req&, Res& res) {
        res.set_content(std::string(openapiYaml()), "application/yaml");
    });
    t.add("GET", "/schemas/scene.json", [](Api::Impl&, const Req&, Res& res) {
        res.set_content(std::string(sceneSchemaJson()), "application/schema+json");
    });
}

} // namespace dermis::api_detail
