// POST /render streamed through MultipartReader; content sent along on 409 missing_content.
#include "batch.hpp"

#include "multipart.hpp"

#include <chrono>
#include <memory>

namespace dermis::cli {

namespace {

/// One POST /render; parts handed to onFrame and counted in `out`. Throws like Http::stream, and
/// exit 3 when the answer ends short.
void renderBatchOnce(Http& http, const std::string& text, const std::string& contentType, const nlohmann::json& frames,
                     const std::function<bool(std::size_t, std::string)>& onFrame, BatchOutcome& out);

} // namespace

BatchOutcome renderBatch(Http& http, const nlohmann::json& scene, const nlohmann::json& frames,
                         const std::string& format, const std::string& view,
                         const std::function<bool(std::size_t, std::string)>& onFrame,
                         const ContentFiles* content) {
    BatchOutcome out;
    nlohmann::json body = {{"scene", scene}, {"frames", frames}, {"format", format}};
    if (!view.empty() && view != "shaded") body["view"] = view;
    std::string text = body.dump(), contentType = "application/json";
    for (int attempt = 0;; ++attempt) {
        try {
            renderBatchOnce(http, text, contentType, frames, onFrame, out);
            return out;
        } catch (const CliError& e) {
            const auto answer = e.httpStatus == 409 ? nlohmann::json::parse(e.answer, nullptr, false) : nlohmann::json();
            const bool missing = answer.is_object() && answer.contains("missing") && answer["missing"].is_array() &&
                                 answer["error"].is_object() && answer["error"].value("code", "") == "missing_content";
            if (missing && content && attempt < 2) {
                // This server lacks content the scene names by address: send it along.
                const auto addresses = answer["missing"].get<std::vector<std::string>>();
                const std::string boundary =
                    "dermis-content-" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
                text = contentBody(body, addresses, *content, boundary);
                contentType = "multipart/form-data; boundary=" + boundary;
                out.contentSent += addresses.size();
                continue;
            }
            if (e.code == kExitCannotConnect || e.httpStatus == 502 || e.httpStatus == 503 || e.httpStatus == 504) {
                out.broken = true;
                out.brokenWhy = e.what();
                return out;
            }
            throw;
        }
    }
}

namespace {

void renderBatchOnce(Http& http, const std::string& text, const std::string& contentType, const nlohmann::json& frames,
                     const std::function<bool(std::size_t, std::string)>& onFrame, BatchOutcome& out) {
    std::unique_ptr<MultipartReader> reader;
    std::string malformed;
    const bool completed = http.stream(
        "POST", "/render", text, contentType,
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
}

} // namespace

} // namespace dermis::cli
