// cpp-httplib client calls with retries, and answers mapped to CliError.
#include "http_client.hpp"

#include <chrono>
#include <cstdlib>
#include <regex>
#include <thread>

namespace dermis::cli {

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

void Http::throwTransport(httplib::Error error) const {
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
        const bool ok = client_->send(r, res, error);
        const bool last = k + 1 >= attempts || g_interrupted;
        double wait = 0.25 * double(1 << std::min(k, 5));
        if (!ok) {
            if (last) throwTransport(error);
        } else if (res.status == 503 && !last) {
            if (res.has_header("Retry-After")) wait = std::min(5.0, std::atof(res.get_header_value("Retry-After").c_str()));
        } else {
            if (res.status >= 400) throw serverError(res.status, res.body);
            return Reply{res.status, std::move(res.body), std::move(res.headers)};
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
                  const std::function<bool(const char*, std::size_t)>& onData) {
    httplib::Request req;
    req.method = method;
    req.path = url(path);
    if (!contentType.empty()) req.headers.emplace("Content-Type", contentType);
    req.body = body;
    bool stopped = false;
    int status = 0;
    std::string errorBody;
    req.response_handler = [&](const httplib::Response& res) {
        status = res.status;
        if (status >= 400) return true; // read the error body whole
        if (!onHeaders(status, res.headers)) {
            stopped = true;
            return false;
        }
        return true;
    };
    req.content_receiver = [&](const char* data, std::size_t n, std::uint64_t, std::uint64_t) {
        if (status >= 400) {
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
    const bool ok = client_->send(req, res, error);
    if (stopped) return false;
    if (status >= 400) throw serverError(status, errorBody);
    if (!ok) throwTransport(error);
    return true;
}

} // namespace dermis::cli
