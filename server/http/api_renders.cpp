// Dermis HTTP shell — render routes: a scene's frame, its height maps, its sweep (a contact sheet
// of a joint or clip swept in steps, or the steps as JSON), and the stateless batch (POST
// /render), whose frames stream as multipart/mixed parts as they finish (its scene may name
// content by address, the bytes sent along as multipart/form-data: SPEC §7). Renders go through
// the Service to the renderer's thread (a full queue answers 503 + Retry-After).
#include "api_internal.hpp"

#include <set>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <vector>

namespace dermis::api_detail {

/// `name` as `count` finite numbers separated by commas; false (422 sent, field `name`) otherwise.
static bool numbersParam(const Req& req, Res& res, const char* name, std::size_t minCount,
                         std::size_t maxCount, std::vector<double>& out, const char* what) {
    const std::string v = req.get_param_value(name);
    out.clear();
    std::size_t start = 0;
    bool ok = !v.empty();
    while (ok && start <= v.size() && out.size() <= maxCount) {
        const std::size_t comma = std::min(v.find(',', start), v.size());
        const std::string item = v.substr(start, comma - start);
        char* end = nullptr;
        const double d = std::strtod(item.c_str(), &end);
        ok = !item.empty() && *end == '\0' && std::isfinite(d);
        out.push_back(d);
        start = comma + 1;
    }
    if (!ok || out.size() < minCount || out.size() > maxCount) {
        sendError(res, 422, "invalid_argument", std::string("dermis::Api: ") + name + ": " + what, name);
        return false;
    }
    return true;
}

bool targetParam(const Req& req, Res& res, std::optional<std::array<double, 3>>& out) {
    if (!req.has_param("target")) return true;
    std::vector<double> xyz;
    if (!numbersParam(req, res, "target", 3, 3, xyz, "three finite numbers x,y,z (a world point)"))
        return false;
    out = std::array<double, 3>{xyz[0], xyz[1], xyz[2]};
    return true;
}

namespace {

/// Splits a comma-separated list of ids (empty items skipped).
std::vector<std::string> idList(const std::string& v) {
    std::vector<std::string> ids;
    std::size_t start = 0;
    while (start <= v.size()) {
        const std::size_t comma = std::min(v.find(',', start), v.size());
        if (comma > start) ids.push_back(v.substr(start, comma - start));
        start = comma + 1;
    }
    return ids;
}

/// An on/off parameter `name` of `req` (present): true for on, false for off; nullopt (and the
/// 422 sent, naming it) for anything else.
std::optional<bool> onOff(const Req& req, Res& res, const char* name) {
    const std::string v = req.get_param_value(name);
    if (v != "on" && v != "off") {
        sendError(res, 422, "invalid_argument", std::string("dermis::Api: ") + name + ": must be on or off", name);
        return std::nullopt;
    }
    return v == "on";
}

/// The frame query: size, camera, time, format, view and what to compare (patterns, only,
/// revision). False (and the 422 sent) when a parameter is malformed.
bool frameParams(const Req& req, Res& res, FrameParams& p) {
    if (req.has_param("format")) p.format = req.get_param_value("format");
    if (!intParam(req, res, "width", p.width) || !intParam(req, res, "height", p.height) ||
        !intParam(req, res, "msaa", p.msaa) || !numberParam(req, res, "yaw", p.yaw) ||
        !numberParam(req, res, "pitch", p.pitch) || !numberParam(req, res, "distance", p.distance) ||
        !numberParam(req, res, "time", p.time) || !numberParam(req, res, "exposure", p.exposure) ||
        !targetParam(req, res, p.target))
        return false;
    if (req.has_param("highlight")) {
        p.highlight = idList(req.get_param_value("highlight"));
        if (p.highlight.empty() || p.highlight.size() > kMaxHighlights) {
            sendError(res, 422, "invalid_argument",
                      "dermis::Api: highlight: 1 to " + std::to_string(kMaxHighlights) +
                          " comma-separated placement ids", "highlight");
            return false;
        }
    }
    if (req.has_param("hover")) {
        p.hover = req.get_param_value("hover");
        if (p.hover.empty()) {
            sendError(res, 422, "invalid_argument", "dermis::Api: hover: a placement id", "hover");
            return false;
        }
    }
    if (req.has_param("brush")) {
        std::vector<double> b;
        const char* what = "u,v,size_u,size_v[,rotation]: a footprint's UV centre (each in [-16, 16]), "
                           "size (each in (0, 16]) and rotation (degrees, |r| <= 3600)";
        if (!numbersParam(req, res, "brush", 4, 5, b, what)) return false;
        b.resize(5, 0.0);
        if (std::abs(b[0]) > kMaxPlacementCenter || std::abs(b[1]) > kMaxPlacementCenter ||
            !(b[2] > 0.0 && b[2] <= kMaxPlacementScale) || !(b[3] > 0.0 && b[3] <= kMaxPlacementScale) ||
            std::abs(b[4]) > kMaxTurnAngle) {
            sendError(res, 422, "invalid_argument", std::string("dermis::Api: brush: ") + what, "brush");
            return false;
        }
        p.brush = std::array<double, 5>{b[0], b[1], b[2], b[3], b[4]};
    }
    if (req.has_param("surface_brush")) {
        std::vector<double> b;
        const char* what = "x,y,z,nx,ny,nz,diameter: a surface point (bind space, each in [-1e6, 1e6]), "
                           "its normal (not zero) and the brush's diameter (model units, in (0, 10000])";
        if (!numbersParam(req, res, "surface_brush", 7, 7, b, what)) return false;
        const double nl = std::sqrt(b[3] * b[3] + b[4] * b[4] + b[5] * b[5]);
        if (std::abs(b[0]) > kMaxAnchorCoordinate || std::abs(b[1]) > kMaxAnchorCoordinate ||
            std::abs(b[2]) > kMaxAnchorCoordinate || !(nl > 1e-12) || !std::isfinite(nl) ||
            !(b[6] > 0.0 && b[6] <= kMaxSurfaceSize)) {
            sendError(res, 422, "invalid_argument", std::string("dermis::Api: surface_brush: ") + what,
                      "surface_brush");
            return false;
        }
        p.surfaceBrush = std::array<double, 7>{b[0], b[1], b[2], b[3], b[4], b[5], b[6]};
    }
    if (req.has_param("aa")) {
        const auto aa = antiAliasingFromString(req.get_param_value("aa"));
        if (!aa) {
            sendError(res, 422, "invalid_argument", "dermis::Api: aa: must be auto, msaa, post or none", "aa");
            return false;
        }
        p.aa = *aa;
    }
    if (req.has_param("shading")) {
        const auto shading = shadingFromString(req.get_param_value("shading"));
        if (!shading) {
            sendError(res, 422, "invalid_argument", "dermis::Api: shading: must be legacy, pbr or skin", "shading");
            return false;
        }
        p.shading = *shading;
    }
    if (req.has_param("tone_mapping")) {
        const auto tm = toneMappingFromString(req.get_param_value("tone_mapping"));
        if (!tm) {
            sendError(res, 422, "invalid_argument", "dermis::Api: tone_mapping: must be neutral, aces or none",
                      "tone_mapping");
            return false;
        }
        p.toneMapping = *tm;
    }
    if (req.has_param("key_light")) {
        const auto on = onOff(req, res, "key_light");
        if (!on) return false;
        p.keyLight = *on;
    }
    if (req.has_param("view")) {
        const auto view = frameViewFromString(req.get_param_value("view"));
        if (!view) {
            sendError(res, 422, "invalid_argument",
                      "dermis::Api: view: must be shaded, bump, displacement, normal, basecolor or lighting",
                      "view");
            return false;
        }
        p.view = *view;
    }
    if (req.has_param("patterns")) {
        const auto on = onOff(req, res, "patterns");
        if (!on) return false;
        p.patternsOff = !*on;
    }
    if (req.has_param("only")) {
        const std::string v = req.get_param_value("only");
        std::size_t start = 0;
        while (start <= v.size()) {
            const std::size_t comma = std::min(v.find(',', start), v.size());
            if (comma > start) p.only.push_back(v.substr(start, comma - start));
            start = comma + 1;
        }
        if (p.only.empty() || p.only.size() > 1000) {
            sendError(res, 422, "invalid_argument", "dermis::Api: only: a comma-separated list of placement ids", "only");
            return false;
        }
    }
    if (req.has_param("preview")) {
        const std::string v = req.get_param_value("preview");
        json patch = json::parse(v, nullptr, false);
        if (v.size() > 16384 || patch.is_discarded() || !patch.is_object() || patch.size() > 100) {
            sendError(res, 422, "invalid_argument",
                      "dermis::Api: preview: a JSON object (at most 16 KB) of placement id -> patch", "preview");
            return false;
        }
        p.preview = std::move(patch);
    }
    if (!revisionParam(req, res, "revision", p.revision)) return false;
    return true;
}

/// A frame answer: the image, the camera the renderer used (X-Dermis-Camera-Distance,
/// X-Dermis-Camera-Target: "x,y,z"), which the editor needs to pan and zoom from an "auto" camera,
/// and `Server-Timing: render;dur=<ms>`, the server's time from `t0` (the route's start) to the
/// encoded frame, with which the editor paces the frames it keeps in flight over a slow link.
void sendFrame(Res& res, EncodedImage&& img, std::chrono::steady_clock::time_point t0) {
    const auto camera = img.camera;
    sendImage(res, std::move(img));
    char dur[64];
    std::snprintf(dur, sizeof dur, "render;dur=%.1f",
                  std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    res.set_header("Server-Timing", dur);
    if (!camera) return;
    char buf[160];
    std::snprintf(buf, sizeof buf, "%.9g", (*camera)[0]);
    res.set_header("X-Dermis-Camera-Distance", buf);
    std::snprintf(buf, sizeof buf, "%.9g,%.9g,%.9g", (*camera)[1], (*camera)[2], (*camera)[3]);
    res.set_header("X-Dermis-Camera-Target", buf);
}

/// The sweep query: placement, clip, steps, size, format (png | json) and the frame's camera,
/// msaa, time and compare parameters (width/height are refused: cells are size × size). False
/// (and the 422 sent) when a parameter is malformed.
bool sweepParams(const Req& req, Res& res, SweepParams& s) {
    if (!frameParams(req, res, s.frame)) return false;
    if (req.has_param("width") || req.has_param("height")) {
        sendError(res, 422, "invalid_argument",
                  "dermis::Api: width/height: a sweep's cells are size x size: use size",
                  req.has_param("width") ? "width" : "height");
        return false;
    }
    if (s.frame.format != "png" && s.frame.format != "json") {
        sendError(res, 422, "invalid_argument", "dermis::Api: format: must be png or json", "format");
        return false;
    }
    std::optional<int> steps, size;
    if (!intParam(req, res, "steps", steps) || !intParam(req, res, "size", size)) return false;
    if (steps) s.steps = *steps;
    if (size) s.size = *size;
    if (req.has_param("placement")) s.placement = req.get_param_value("placement");
    if (req.has_param("clip")) s.clip = req.get_param_value("clip");
    if ((req.has_param("placement") && s.placement.empty()) || (req.has_param("clip") && s.clip.empty())) {
        const char* field = req.has_param("placement") && s.placement.empty() ? "placement" : "clip";
        sendError(res, 422, "invalid_argument", std::string("dermis::Api: ") + field + ": must not be empty", field);
        return false;
    }
    return true;
}

} // namespace

namespace {

/// The parameters of a POST frame: its JSON body's members, each as the query parameter of the
/// same name would give it (strings as they are, numbers and objects as JSON, arrays of numbers
/// comma-separated), so that one parser (frameParams) reads both. False (and 422 sent) for
/// anything else than an object of known members.
bool framePostParams(const Req& req, Res& res, Req& out) {
    static const std::set<std::string> known = {"format", "width", "height", "msaa", "aa", "yaw", "pitch",
                                                "distance", "time", "target", "highlight", "hover",
                                                "brush", "surface_brush", "view", "patterns", "only",
                                                "shading", "exposure", "tone_mapping", "key_light",
                                                "preview", "revision"};
    json body;
    if (!jsonBody(req, res, body)) return false;
    if (!body.is_object()) {
        sendError(res, 422, "invalid_argument", "dermis::Api: body: a JSON object of frame parameters", "");
        return false;
    }
    out.params.clear();
    for (auto it = body.begin(); it != body.end(); ++it) {
        if (!known.count(it.key())) {
            sendError(res, 422, "invalid_argument", "dermis::Api: /" + it.key() + ": not a frame parameter", "/" + it.key());
            return false;
        }
        const json& v = it.value();
        std::string text;
        if (v.is_string()) text = v.get<std::string>();
        else if (v.is_array()) {
            for (const json& x : v) {
                if (!x.is_number() && !x.is_string()) {
                    sendError(res, 422, "invalid_argument", "dermis::Api: /" + it.key() + ": numbers or ids", "/" + it.key());
                    return false;
                }
                text += (text.empty() ? "" : ",") + (x.is_string() ? x.get<std::string>() : x.dump());
            }
        } else text = v.dump();
        out.params.emplace(it.key(), std::move(text));
    }
    return true;
}

} // namespace

void installRenderRoutes(RouteTable& t) {
    t.add("GET", "/scenes/{id}/frame", [](Api::Impl& a, const Req& req, Res& res) {
        const auto t0 = std::chrono::steady_clock::now();
        FrameParams p;
        if (!frameParams(req, res, p)) return;
        auto r = a.svc.frame(req.matches[1], p);
        if (!r) return sendError(res, r.error());
        sendFrame(res, std::move(*r), t0);
    });
    // The same frame with its parameters in a JSON body: a preview (up to 16 KB) need not fit the
    // 8 KB request line. Nothing is stored.
    t.add("POST", "/scenes/{id}/frame", [](Api::Impl& a, const Req& req, Res& res) {
        const auto t0 = std::chrono::steady_clock::now();
        Req q;
        if (!framePostParams(req, res, q)) return;
        FrameParams p;
        if (!frameParams(q, res, p)) return;
        auto r = a.svc.frame(req.matches[1], p);
        if (!r) return sendError(res, r.error());
        sendFrame(res, std::move(*r), t0);
    });
    t.add("GET", "/scenes/{id}/frame-diff", [](Api::Impl& a, const Req& req, Res& res) {
        FrameParams p;
        if (!frameParams(req, res, p)) return;
        if (!req.has_param("against"))
            return sendError(res, 422, "invalid_argument", "dermis::Api: against: off or a revision number is required", "against");
        const auto t0 = std::chrono::steady_clock::now();
        auto r = a.svc.frameDiff(req.matches[1], p, req.get_param_value("against"));
        if (!r) return sendError(res, r.error());
        sendFrame(res, std::move(*r), t0);
    });
    t.add("GET", "/scenes/{id}/sweep", [](Api::Impl& a, const Req& req, Res& res) {
        SweepParams p;
        if (!sweepParams(req, res, p)) return;
        if (p.frame.format == "json") {
            auto r = a.svc.sweepSteps(req.matches[1], p);
            if (!r) return sendError(res, r.error());
            return sendJson(res, 200, *r);
        }
        auto r = a.svc.sweep(req.matches[1], p);
        if (!r) return sendError(res, r.error());
        sendImage(res, std::move(*r));
    });
    t.add("GET", "/scenes/{id}/focus", [](Api::Impl& a, const Req& req, Res& res) {
        FrameParams p;
        if (!frameParams(req, res, p)) return;
        if (!req.has_param("placement"))
            return sendError(res, 422, "invalid_argument", "dermis::Api: placement is required", "placement");
        auto r = a.svc.focus(req.matches[1], req.get_param_value("placement"), p);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
    t.add("GET", "/scenes/{id}/turntable", [](Api::Impl& a, const Req& req, Res& res) {
        TurntableParams p;
        if (!frameParams(req, res, p.frame)) return;
        if (req.has_param("width") || req.has_param("height"))
            return sendError(res, 422, "invalid_argument",
                             "dermis::Api: width/height: a turntable's frames are size x size: use size",
                             req.has_param("width") ? "width" : "height");
        if (req.has_param("format") && p.frame.format != "webp")
            return sendError(res, 422, "invalid_argument", "dermis::Api: format: a turntable is webp", "format");
        p.frame.format = "webp";
        std::optional<int> frames, size;
        std::optional<double> fps;
        if (!intParam(req, res, "frames", frames) || !intParam(req, res, "size", size) ||
            !numberParam(req, res, "fps", fps))
            return;
        if (frames) p.frames = *frames;
        if (size) p.size = *size;
        if (fps) p.fps = *fps;
        if (!req.has_param("placement"))
            return sendError(res, 422, "invalid_argument", "dermis::Api: placement is required", "placement");
        p.placement = req.get_param_value("placement");
        auto r = a.svc.turntable(req.matches[1], p);
        if (!r) return sendError(res, r.error());
        sendImage(res, std::move(*r));
        res.set_header("Content-Disposition", "inline; filename=\"turntable-" + p.placement + ".webp\"");
    });
    t.add("GET", "/scenes/{id}/heightmaps/{map}", [](Api::Impl& a, const Req& req, Res& res) {
        const std::string map = req.matches[2];
        const std::string format = req.has_param("format") ? req.get_param_value("format")
                                                           : (map == "normal" ? "png" : "png16");
        auto r = a.svc.heightmap(req.matches[1], map, format);
        if (!r) return sendError(res, r.error());
        sendImage(res, std::move(*r));
    });

    // --- stateless batch: frames streamed as multipart/mixed parts as they finish
    t.add("POST", "/render", [](Api::Impl& a, const Req& req, Res& res) {
        json body;
        std::map<std::string, std::vector<std::uint8_t>> content;
        if (req.is_multipart_form_data()) {
            // A batch with its content (SPEC §7): part "request" is the JSON batch, every other
            // part is named by the content address of its bytes.
            if (!req.has_file("request"))
                return sendError(res, 422, "invalid_argument",
                                 "dermis::Api: request: a multipart batch needs a part \"request\" with the JSON batch",
                                 "request");
            for (const auto& [name, part] : req.files) {
                if (name == "request") continue;
                if (!content.emplace(name, bytesOf(part.content)).second)
                    return sendError(res, 422, "invalid_argument", "dermis::Api: " + name + ": given twice",
                                     name.substr(0, 80));
            }
            if (!jsonText(req.get_file_value("request").content, "request", res, body)) return;
        } else if (!jsonBody(req, res, body)) {
            return;
        }
        auto job = a.svc.batch(body, content);
        if (!job) return sendDocError(res, job.error());
        auto shared = std::make_shared<Service::BatchJob>(std::move(*job));
        const std::string boundary = "dermis-frame-boundary";
        res.set_header("X-Dermis-Frames", std::to_string(shared->frames));
        res.set_chunked_content_provider(
            "multipart/mixed; boundary=" + boundary,
            [shared, boundary, next = std::make_shared<std::size_t>(0)](std::size_t,
                                                                        httplib::DataSink& sink) {
                const std::size_t k = (*next)++;
                if (k >= shared->frames) {
                    const std::string end = "--" + boundary + "--\r\n";
                    sink.write(end.data(), end.size());
                    sink.done();
                    return true;
                }
                auto img = shared->render(k);
                std::string part = "--" + boundary + "\r\n";
                if (!img) {
                    const json err = {{"error",
                                       {{"code", errorCodeName(img.error().code)},
                                        {"message", img.error().message},
                                        {"field", img.error().field}}}};
                    part +=
                        "Content-Type: application/json\r\nX-Dermis-Frame: " + std::to_string(k) +
                        "\r\n\r\n" + err.dump() + "\r\n--" + boundary + "--\r\n";
                    sink.write(part.data(), part.size());
                    sink.done();
                    return true;
                }
                part += "Content-Type: " + img->contentType +
                        "\r\nX-Dermis-Frame: " + std::to_string(k) +
                        "\r\nX-Dermis-Backend: " + img->backend +
                        "\r\nContent-Length: " + std::to_string(img->bytes.size()) + "\r\n\r\n";
                part.append(img->bytes.begin(), img->bytes.end());
                part += "\r\n";
                return sink.write(part.data(), part.size());
            });
    });
}

} // namespace dermis::api_detail
