// cpp-httplib client calls with retries, and answers mapped to CliError.
#include "http_client.hpp"

#include "frames.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <regex>
#include <thread>

namespace dermis::cli {

/// Stops the client's request in flight (Client::stop shuts its socket) when `seconds` pass
/// before the watchdog is destroyed; fired() says whether it did.
class Http::Watchdog {
public:
    Watchdog(httplib::Client& client, double seconds) : client_(client) {
        if (!(seconds > 0) || !std::isfinite(seconds)) return;
        thread_ = std::thread([this, seconds] {
            std::unique_lock<std::mutex> lock(mutex_);
            if (!wake_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return done_; })) {
                fired_ = true;
                client_.stop();
            }
        });
    }
    ~Watchdog() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            done_ = true;
        }
        wake_.notify_all();
        if (thread_.joinable()) thread_.join();
    }
    Watchdog(const Watchdog&) = delete;
    Watchdog& operator=(const Watchdog&) = delete;
    bool fired() const { return fired_; }

private:
    httplib::Client& client_;
    std::mutex mutex_;
    std::condition_variable wake_;
    bool done_ = false;
    std::atomic<bool> fired_{false};
    std::thread thread_;
};

namespace {

/// The CliError for a redirect: never followed.
CliError redirectError(int status, const httplib::Headers& headers, const std::string& what) {
    auto it = headers.find("Location");
    const std::string where = it == headers.end() ? std::string("nowhere") : "\"" + it->second.substr(0, 200) + "\"";
    CliError e(kExitServerSaidNo,
               "the server answered " + what + " with " + std::to_string(status) + ", a redirect to " + where +
                   ": not followed (is --server the address of dermis-server's API?)",
               "--server");
    e.httpStatus = status;
    return e;
}

CliError tooLargeError(const std::string& what) {
    return CliError(kExitCannotConnect,
                    "the answer to " + what + " is over " + std::to_string(kMaxAnswerBytes >> 20) +
                        " MiB: stopped reading it (an answer kept in memory is never that large)",
                    "--server");
}

} // namespace

FileKind fileKindOf(const std::string& format) {
    if (format == "jpeg") return FileKind::Jpeg;
    if (format == "exr") return FileKind::Exr;
    if (format == "f32") return FileKind::RawFloats;
    return FileKind::Png;
}

std::string Reply::header(const std::string& name) const {
    auto it = headers.find(name);
    return it == headers.end() ? std::string() : it->second;
}

std::string queryString(const std::vector<std::pair<std::string, std::string>>& params) {
    std::string out;
    for (const auto& [name, value] : params) {
        if (!out.empty()) out += '&';
        out += name + "=" + httplib::detail::encode_query_param(value);
    }
    return out;
}

CliError serverError(int status, const std::string& body) {
    const auto j = nlohmann::json::parse(body, nullptr, false);
    CliError out(kExitServerSaidNo, "HTTP " + std::to_string(status) + " from the server");
    if (j.is_object() && j.contains("error") && j["error"].is_object()) {
        const auto& e = j["error"];
        out = CliError(kExitServerSaidNo, e.value("message", "HTTP " + std::to_string(status)), e.value("field", ""));
    }
    out.httpStatus = status;
    out.answer = body;
    return out;
}

Http::Http(const GlobalOptions& options) : options_(options) {
    static const std::regex url(R"(^(http://[^/?#]+)(/[^?#]*)?$)");
    std::smatch m;
    if (!std::regex_match(options.server, m, url))
        throw usageError("expected http://host[:port][/prefix], got \"" + options.server + "\"", "--server");
    server_ = m[1];
    std::string prefix = m[2];
    while (!prefix.empty() && prefix.back() == '/') prefix.pop_back();
    prefix_ = prefix + "/api/v1";
    client_ = std::make_unique<httplib::Client>(server_);
    const auto secs = static_cast<time_t>(options.timeout);
    const auto usecs = static_cast<time_t>((options.timeout - static_cast<double>(secs)) * 1e6);
    client_->set_connection_timeout(secs, usecs);
    client_->set_read_timeout(secs, usecs);
    client_->set_write_timeout(secs, usecs);
    client_->set_keep_alive(true);
    client_->set_tcp_nodelay(true);
    if (!options.token.empty()) client_->set_bearer_token_auth(options.token);
}

double Http::requestSeconds(bool deadline) const {
    double seconds = deadline ? options_.deadline : 0.0;
    if (options_.maxTime > 0) {
        const double left = options_.maxTime - std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
        if (left <= 0)
            throw CliError(kExitCannotConnect, "the command ran past --max-time " + nlohmann::json(options_.maxTime).dump() + " s", "--max-time");
        seconds = seconds > 0 ? std::min(seconds, left) : left;
    }
    return seconds;
}

void Http::throwTransport(httplib::Error error, bool deadlinePassed) const {
    if (deadlinePassed) {
        const bool command = options_.maxTime > 0 &&
                             std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count() >= options_.maxTime;
        throw CliError(kExitCannotConnect,
                       command ? "the command ran past --max-time " + nlohmann::json(options_.maxTime).dump() + " s"
                               : "no complete answer from " + options_.server + " within --deadline " +
                                     nlohmann::json(options_.deadline).dump() + " s",
                       command ? "--max-time" : "--deadline");
    }
    std::string why;
    switch (error) {
    case httplib::Error::Connection: why = "connection refused or host unreachable"; break;
    case httplib::Error::ConnectionTimeout: why = "no connection within --timeout"; break;
    case httplib::Error::Read: why = "the connection broke or --timeout passed while reading"; break;
    case httplib::Error::Write: why = "the connection broke while sending"; break;
    case httplib::Error::Canceled: why = "canceled"; break;
    default: why = httplib::to_string(error); break;
    }
    throw CliError(kExitCannotConnect, "cannot connect to " + options_.server + ": " + why, "--server");
}

Reply Http::perform(const httplib::Request& req, bool retry) {
    const int attempts = retry ? std::max(0, options_.retries) + 1 : 1;
    for (int k = 0;; ++k) {
        httplib::Request r = req;
        httplib::Response res;
        httplib::Error error = httplib::Error::Success;
        // The answer is kept in memory: at most kMaxAnswerBytes of it.
        std::string body;
        bool tooLarge = false;
        r.content_receiver = [&](const char* data, std::size_t n, std::uint64_t, std::uint64_t) {
            if (body.size() + n > kMaxAnswerBytes) {
                tooLarge = true;
                return false;
            }
            body.append(data, n);
            return true;
        };
        bool ok, late;
        {
            Watchdog watchdog(*client_, requestSeconds(true));
            ok = client_->send(r, res, error);
            late = watchdog.fired();
        }
        if (tooLarge) throw tooLargeError(req.method + " " + req.path);
        const bool last = k + 1 >= attempts || g_interrupted || late;
        double wait = 0.25 * double(1 << std::min(k, 5));
        if (!ok || late) {
            if (last) throwTransport(error, late);
        } else if (res.status == 503 && !last) {
            if (res.has_header("Retry-After")) wait = std::min(5.0, std::atof(res.get_header_value("Retry-After").c_str()));
        } else {
            if (res.status >= 400) throw serverError(res.status, body);
            if (res.status >= 300) throw redirectError(res.status, res.headers, req.method + " " + req.path);
            return Reply{res.status, std::move(body), std::move(res.headers)};
        }
        std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    }
}

Reply Http::get(const std::string& path) {
    httplib::Request req;
    req.method = "GET";
    req.path = url(path);
    return perform(req, true);
}

nlohmann::json Http::getJson(const std::string& path) {
    Reply r = get(path);
    auto j = nlohmann::json::parse(r.body, nullptr, false);
    if (j.is_discarded()) throw CliError(kExitServerSaidNo, "the server's answer to GET " + path + " is not JSON");
    return j;
}

Reply Http::send(const std::string& method, const std::string& path, const std::string& body,
                 const std::string& contentType, bool retry, httplib::Headers extra) {
    httplib::Request req;
    req.method = method;
    req.path = url(path);
    req.headers = std::move(extra);
    if (!options_.client.empty()) req.headers.emplace("X-Dermis-Client", options_.client);
    if (!contentType.empty()) req.headers.emplace("Content-Type", contentType);
    req.body = body;
    return perform(req, retry);
}

nlohmann::json Http::sendJson(const std::string& method, const std::string& path,
                              const nlohmann::json& body, httplib::Headers extra) {
    const bool retry = method == "PUT" || method == "DELETE";
    Reply r = send(method, path, body.is_null() ? std::string() : body.dump(),
                   body.is_null() ? std::string() : "application/json", retry, std::move(extra));
    if (r.body.empty()) return nullptr;
    auto j = nlohmann::json::parse(r.body, nullptr, false);
    if (j.is_discarded()) throw CliError(kExitServerSaidNo, "the server's answer to " + method + " " + path + " is not JSON");
    return j;
}

Reply Http::postMultipart(const std::string& path, const httplib::MultipartFormDataItems& items) {
    const std::string boundary = "dermis-client-" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
    std::string body;
    for (const auto& item : items) {
        body += "--" + boundary + "\r\nContent-Disposition: form-data; name=\"" + item.name + "\"";
        if (!item.filename.empty()) body += "; filename=\"" + item.filename + "\"";
        body += "\r\nContent-Type: " + (item.content_type.empty() ? std::string("application/octet-stream") : item.content_type);
        body += "\r\n\r\n" + item.content + "\r\n";
    }
    body += "--" + boundary + "--\r\n";
    return send("POST", path, body, "multipart/form-data; boundary=" + boundary, true);
}

bool Http::stream(const std::string& method, const std::string& path, const std::string& body,
                  const std::string& contentType,
                  const std::function<bool(int, const httplib::Headers&)>& onHeaders,
                  const std::function<bool(const char*, std::size_t)>& onData, bool deadline) {
    httplib::Request req;
    req.method = method;
    req.path = url(path);
    if (!contentType.empty()) req.headers.emplace("Content-Type", contentType);
    if (!contentKey_.empty()) req.headers.emplace("X-Dermis-Content-Key", contentKey_);
    req.body = body;
    bool stopped = false, tooLarge = false;
    int status = 0;
    std::string errorBody;
    httplib::Headers redirectHeaders;
    req.response_handler = [&](const httplib::Response& res) {
        status = res.status;
        if (status >= 300 && status < 400) { // never followed, nor its body read
            redirectHeaders = res.headers;
            return false;
        }
        if (status >= 400) return true; // read the error body (up to kMaxAnswerBytes)
        if (!onHeaders(status, res.headers)) {
            stopped = true;
            return false;
        }
        return true;
    };
    req.content_receiver = [&](const char* data, std::size_t n, std::uint64_t, std::uint64_t) {
        if (status >= 400) {
            if (errorBody.size() + n > kMaxAnswerBytes) {
                tooLarge = true;
                return false;
            }
            errorBody.append(data, n);
            return true;
        }
        if (!onData(data, n)) {
            stopped = true;
            return false;
        }
        return true;
    };
    httplib::Response res;
    httplib::Error error = httplib::Error::Success;
    bool ok, late;
    {
        Watchdog watchdog(*client_, requestSeconds(deadline));
        ok = client_->send(req, res, error);
        late = watchdog.fired();
    }
    if (late) throwTransport(error, true);
    if (status >= 300 && status < 400) throw redirectError(status, redirectHeaders, method + " " + path);
    if (stopped) return false;
    if (tooLarge) throw tooLargeError(method + " " + path);
    if (status >= 400) throw serverError(status, errorBody);
    if (!ok) throwTransport(error);
    return true;
}

Reply Http::download(const std::string& path, const std::string& out, FileKind kind) {
    namespace fs = std::filesystem;
    static const char* const kTypes[] = {"image/png", "image/jpeg", "image/x-exr", "application/octet-stream"};
    const std::string wanted = kTypes[static_cast<int>(kind)];
    std::error_code ec;
    const fs::path parent = fs::path(out).parent_path();
    if (!parent.empty()) fs::create_directories(parent, ec);
    const std::string tmp = partialPathOf(out);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw usageError("cannot write " + tmp, out);
    // Whatever goes wrong, no file (and no part file) is left behind.
    struct Cleanup {
        int fd;
        std::string tmp;
        bool keep = false;
        ~Cleanup() {
            if (fd >= 0) ::close(fd);
            if (!keep) ::unlink(tmp.c_str());
        }
    } cleanup{fd, tmp};
    Reply reply;
    std::string head, why;
    std::size_t bytes = 0;
    bool writeFailed = false;
    const bool whole = stream(
        "GET", path, "", "",
        [&](int status, const httplib::Headers& headers) {
            reply.status = status;
            reply.headers = headers;
            auto it = headers.find("Content-Type");
            const std::string type = it == headers.end() ? "" : it->second.substr(0, it->second.find(';'));
            if (status != 200) why = "the server answered " + std::to_string(status) + " without the file";
            else if (type != wanted)
                why = "the server answered " + (type.empty() ? std::string("no Content-Type") : "\"" + type.substr(0, 80) + "\"") +
                      " where " + wanted + " was asked for";
            return why.empty();
        },
        [&](const char* data, std::size_t n) {
            if (head.size() < 8) head.append(data, std::min(n, 8 - head.size()));
            if (!writeAll(fd, data, n)) {
                writeFailed = true;
                return false;
            }
            bytes += n;
            return true;
        });
    if (writeFailed) throw usageError("cannot write " + tmp, out);
    if (!whole) throw CliError(kExitServerSaidNo, why.empty() ? "the answer to GET " + path + " was cut short" : why, "--server");
    static const std::string kPng("\x89PNG\r\n\x1a\n", 8), kJpeg("\xff\xd8\xff", 3), kExr("\x76\x2f\x31\x01", 4);
    const std::string* sig = kind == FileKind::Png ? &kPng : kind == FileKind::Jpeg ? &kJpeg : kind == FileKind::Exr ? &kExr : nullptr;
    const bool valid = sig ? head.compare(0, sig->size(), *sig) == 0 && bytes > sig->size() : bytes > 0 && bytes % 4 == 0;
    if (!valid)
        throw CliError(kExitServerSaidNo,
                       "the server's " + std::to_string(bytes) + "-byte answer is not a " +
                           (kind == FileKind::RawFloats ? std::string("whole number of floats") : wanted + " file") +
                           ": nothing written",
                       "--server");
    if (::close(fd) != 0) throw usageError("cannot write " + tmp, out);
    cleanup.fd = -1;
    if (::rename(tmp.c_str(), out.c_str()) != 0) throw usageError("cannot write " + out, out);
    cleanup.keep = true;
    reply.body.clear();
    reply.headers.emplace("X-Dermis-Bytes", std::to_string(bytes));
    return reply;
}

} // namespace dermis::cli
