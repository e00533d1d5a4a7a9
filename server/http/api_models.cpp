// Dermis HTTP shell — model routes: list, upload (.glb body, or a .gltf with its external files
// as multipart parts), details, delete, UV layout (JSON or PNG), base-colour texture (PNG).
#include "api_internal.hpp"

namespace dermis::api_detail {

void installModelRoutes(RouteTable& t) {
    t.add("GET", "/models",
          [](Api::Impl& a, const Req&, Res& res) { sendJson(res, 200, a.svc.listModels()); });
    t.add("POST", "/models", [](Api::Impl& a, const Req& req, Res& res) {
        if (req.is_multipart_form_data()) {
            // A .gltf and its external files: part "gltf" (or the part whose file name ends in
            // .gltf) and one part per buffer/image, named by its file name (the URI in the .gltf).
            std::vector<UploadFile> files;
            std::string gltfName;
            for (const auto& [field, part] : req.files) {
                const std::string name = part.filename.empty() ? field : part.filename;
                files.push_back({name, bytesOf(part.content)});
                const bool isGltf =
                    name.size() > 5 && name.compare(name.size() - 5, 5, ".gltf") == 0;
                if (field == "gltf" || (gltfName.empty() && isGltf)) gltfName = name;
            }
            bool existing = false;
            auto r = a.svc.addModelFiles(files, gltfName, req.get_param_value("name"), &existing);
            if (!r) {
                Error e = r.error();
                if (e.field.empty() && !gltfName.empty()) e.field = "files/" + gltfName; // the .gltf's part
                return sendError(res, e);
            }
            return sendJson(res, existing ? 200 : 201, *r); // 200: these bytes were uploaded before
        }
        if (!hasContentType(req, {"model/gltf-binary", "application/octet-stream"}))
            return sendError(res, 415, "unsupported",
                             "dermis-server: body: expected Content-Type model/gltf-binary, or "
                             "multipart/form-data with a .gltf and its files",
                             "body");
        bool existing = false;
        auto r = a.svc.addModel(bytesOf(req.body), req.get_param_value("name"), &existing);
        if (!r) {
            Error e = r.error();
            if (e.field.empty() && e.code == ErrorCode::Parse)
                e.field = "body"; // undecodable bytes
            return sendError(res, e);
        }
        sendJson(res, existing ? 200 : 201, *r); // 200: these bytes were uploaded before
    });
    t.add("GET", "/models/{id}", [](Api::Impl& a, const Req& req, Res& res) {
        auto r = a.svc.getModel(req.matches[1]);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
    t.add("DELETE", "/models/{id}", [](Api::Impl& a, const Req& req, Res& res) {
        auto r = a.svc.deleteModel(req.matches[1]);
        if (!r) return sendError(res, r.error());
        res.status = 204;
    });
    t.add("GET", "/models/{id}/uv-layout", [](Api::Impl& a, const Req& req, Res& res) {
        const std::string format = req.has_param("format") ? req.get_param_value("format") : "json";
        const auto mode = uvLayoutModeFromString(req.has_param("layout") ? req.get_param_value("layout") : "auto");
        if (!mode)
            return sendError(res, 422, "invalid_argument",
                             "dermis-server: layout: must be auto, model or generated", "layout");
        if (format == "json") {
            auto r = a.svc.uvLayout(req.matches[1], *mode);
            if (!r) return sendError(res, r.error());
            return sendJson(res, 200, *r);
        }
        if (format != "png")
            return sendError(res, 422, "invalid_argument",
                             "dermis-server: format: must be png or json", "format");
        std::optional<int> size;
        if (!intParam(req, res, "size", size)) return;
        auto r = a.svc.uvLayoutPng(req.matches[1], size.value_or(1024), *mode);
        if (!r) return sendError(res, r.error());
        sendImage(res, std::move(*r));
    });
    t.add("GET", "/models/{id}/texture", [](Api::Impl& a, const Req& req, Res& res) {
        std::optional<int> size;
        if (!intParam(req, res, "size", size)) return;
        auto r = a.svc.modelTexture(req.matches[1], size);
        if (!r) {
            // A model without a texture is a 404 of its own kind, so the editor can tell it from
            // an unknown model.
            if (r.error().code == ErrorCode::NotFound && r.error().field == "texture")
                return sendError(res, 404, "no_texture", r.error().message, "texture");
            return sendError(res, r.error());
        }
        sendImage(res, std::move(*r));
    });
}

} // namespace dermis::api_detail
