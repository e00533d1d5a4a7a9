// POST /render streamed through MultipartReader.
#include "batch.hpp"

#include "multipart.hpp"

#include <memory>

namespace dermis::cli {

BatchOutcome renderBatch(Http& http, const nlohmann::json& scene, const nlohmann::json& frames,
                         const std::string& format, const std::string& view,
                         const std::function<bool(std::size_t, std::string)>& onFrame) {
    BatchOutcome out;
    nlohmann::json body = {{"scene", scene}, {"frames", frames}, {"format", format}};
    if (!view.empty() && view != "shaded") body["view"] = view;
    std::unique_ptr<MultipartReader> reader;
    std::string malformed;
    const bool completed = http.stream(
        "POST", "/render", body.dump(), "application/json",
        [&](int, const httplib::Headers& headers) {
            auto it = headers.find("Content-Type");
            const std::string boundary = it == headers.end() ? "" : MultipartReader::boundaryOf(it->second);
            if (boundary.empty()) {
                malformed = "the batch answer is not multipart";
                return false;
            }
            reader = std::make_unique<MultipartReader>(
                boundary, [&](const std::map<std::string, std::string>& h, std::string bytes) {
                    auto f = h.find("x-dermis-frame");
                    const long index = f == h.end() ? -1 : std::atol(f->second.c_str());
                    auto type = h.find("content-type");
                    if (type != h.end() && type->second.rfind("application/json", 0) == 0) {
                        out.failedFrame = index;
                        auto e = nlohmann::json::parse(bytes, nullptr, false);
                        if (e.is_object() && e.contains("error")) {
                            out.failure = e["error"].value("message", "render failed");
                            const std::string field = e["error"].value("field", "");
                            if (!field.empty()) out.failure += " (" + field + ")";
                        } else {
                            out.failure = "render failed";
                        }
                        return false;
                    }
                    if (index < 0 || static_cast<std::size_t>(index) >= frames.size()) {
                        malformed = "a part without a valid X-Dermis-Frame";
                        return false;
                    }
                    ++out.received;
                    if (!onFrame(static_cast<std::size_t>(index), std::move(bytes)) || g_interrupted) {
                        out.interrupted = true;
                        return false;
                    }
                    return true;
                });
            return true;
        },
        [&](const char* data, std::size_t n) {
            if (g_interrupted) {
                out.interrupted = true;
                return false;
            }
            reader->feed(data, n);
            if (!reader->error().empty()) malformed = reader->error();
            return malformed.empty() && !out.interrupted;
        });
    if (!malformed.empty()) throw CliError(kExitCannotConnect, malformed);
    if (g_interrupted) out.interrupted = true;
    if (completed && !out.interrupted && out.failedFrame < 0 && out.received < frames.size())
        throw CliError(kExitCannotConnect, "the batch answer ended after " + std::to_string(out.received) + " of " +
                                               std::to_string(frames.size()) + " frames");
    return out;
}

} // namespace dermis::cli
