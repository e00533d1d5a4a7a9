// health, info, lint, watch: reads that need no scene edits.
#include "commands.hpp"
#include "http_client.hpp"
#include "output.hpp"

#include <fstream>
#include <iostream>
#include <iterator>

namespace dermis::cli {

nlohmann::json readJsonFile(const std::string& path, const std::string& field) {
    std::string text;
    if (path == "-") {
        text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
    } else {
        text = readFileOrThrow(path, field);
    }
    auto j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded() || !j.is_object()) throw usageError(path + " is not a JSON object", field);
    return j;
}

std::string scenePath(const std::string& id) { return "/scenes/" + httplib::detail::encode_query_param(id); }

namespace {

struct SystemOptions {
    std::string scene;
    bool strict = false;
    int count = 0;
};

} // namespace

void addSystemCommands(CLI::App& app, Context& ctx) {
    auto o = std::make_shared<SystemOptions>();
    CLI::App* health = app.add_subcommand("health", "Is the server up? (GET /health; no token needed)");
    health->callback([&ctx] {
        ctx.action = [&ctx] {
            auto j = ctx.http().getJson("/health");
            if (ctx.global.json) printJson(j);
            else std::cout << j.value("status", "?") << "\n";
            return kExitOk;
        };
    });

    CLI::App* info = app.add_subcommand("info", "Server name, version, GL backend and limits (GET /info)");
    info->callback([&ctx] {
        ctx.action = [&ctx] {
            auto j = ctx.http().getJson("/info");
            if (ctx.global.json) {
                printJson(j);
                return kExitOk;
            }
            std::vector<std::vector<std::string>> rows = {
                {"server", ctx.http().server()},
                {"name", cell(j.value("name", nlohmann::json()))},
                {"version", cell(j.value("version", nlohmann::json()))},
                {"backend", cell(j.value("backend", nlohmann::json()))},
                {"device", cell(j.value("device", nlohmann::json()))},
                {"renderer", j.contains("gl") ? cell(j["gl"].value("renderer", nlohmann::json())) : "-"},
                {"render queue", cell(j.value("render_queue", nlohmann::json()))}};
            if (j.contains("limits") && j["limits"].is_object())
                for (const auto& [k, v] : j["limits"].items())
                    rows.push_back({"limits." + k, cell(v)});
            printTable({"KEY", "VALUE"}, rows);
            return kExitOk;
        };
    });

    auto* lint = app.add_subcommand("lint", "What may be wrong with a scene (GET /scenes/{id}/lint)");
    lint->add_option("scene", o->scene, "Scene id")->required();
    lint->add_flag("--strict", o->strict, "Exit 1 when there is a warning");
    lint->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            auto j = ctx.http().getJson(scenePath(o->scene) + "/lint");
            bool warned = false;
            std::vector<std::vector<std::string>> rows;
            for (const auto& f : j) {
                warned = warned || f.value("severity", "") == "warning";
                rows.push_back({cell(f["severity"]), cell(f["code"]), cell(f["placement"]), cell(f["message"])});
            }
            if (ctx.global.json) printJson(j);
            else if (rows.empty()) std::cout << "no findings\n";
            else printTable({"SEVERITY", "CODE", "PLACEMENT", "MESSAGE"}, rows);
            return o->strict && warned ? kExitServerSaidNo : kExitOk;
        };
    });

    auto* watch = app.add_subcommand("watch", "Print a scene's events as JSON lines as they happen (server-sent events)");
    watch->add_option("scene", o->scene, "Scene id")->required();
    watch->add_option("--count", o->count, "Stop after this many events (the hello event counts; 0 = until the scene is deleted or Ctrl-C)")
        ->check(CLI::NonNegativeNumber);
    watch->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            std::string buffer;
            int seen = 0;
            bool done = false;
            ctx.http().stream(
                "GET", scenePath(o->scene) + "/events", "", "", [](int, const httplib::Headers&) { return true; },
                [&](const char* data, std::size_t n) {
                    if (g_interrupted) return false;
                    buffer.append(data, n);
                    std::size_t end;
                    while ((end = buffer.find("\n\n")) != std::string::npos) {
                        const std::string event = buffer.substr(0, end);
                        buffer.erase(0, end + 2);
                        std::size_t at = 0;
                        while (at < event.size()) {
                            std::size_t eol = event.find('\n', at);
                            if (eol == std::string::npos) eol = event.size();
                            const std::string line = event.substr(at, eol - at);
                            at = eol + 1;
                            if (line.rfind("data:", 0) != 0) continue; // event:, comments (pings)
                            std::string payload = line.substr(5);
                            if (!payload.empty() && payload[0] == ' ') payload.erase(0, 1);
                            std::cout << payload << "\n" << std::flush;
                            ++seen;
                            auto j = nlohmann::json::parse(payload, nullptr, false);
                            if (j.is_object() && j.value("type", "") == "deleted") done = true;
                        }
                        if (done || (o->count > 0 && seen >= o->count)) return false;
                    }
                    return true;
                },
                false); // an event stream runs until stopped: no --deadline (only --max-time)
            return g_interrupted ? kExitInterrupted : kExitOk;
        };
    });
}

} // namespace dermis::cli
