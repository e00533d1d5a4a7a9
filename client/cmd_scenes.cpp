// scene create|list|get|put|export|apply|rm|history|revert|propose|transfer, pose set, placement
// add|set|rm|mirror.
// Edits print "<scene id> r<revision>" (or the server's answer with --json); --if-revision sends
// If-Match so a stale edit is refused (412, exit 1).
#include "commands.hpp"
#include "frames.hpp"
#include "http_client.hpp"
#include "output.hpp"

#include <iostream>
#include <sstream>

namespace dermis::cli {

namespace {

struct SceneOptions {
    std::string id, file, pid, out, model = "builtin:default", clip;
    std::vector<std::string> ids, fields, joints, morphs;
    bool defaultPatterns = false, replace = false, apply = false, dryRun = false, update = false;
    std::string from;
    std::vector<std::string> jointMap;
    int revision = 0, ifRevision = 0, limit = 50;
    double time = -1;
};

httplib::Headers ifMatch(int revision) {
    if (revision <= 0) return {};
    return {{"If-Match", "\"r" + std::to_string(revision) + "\""}};
}

void printEdit(const Context& ctx, const nlohmann::json& answer) {
    if (ctx.global.json) printJson(answer);
    else std::cout << answer.value("id", "") << " r" << answer.value("revision", 0) << "\n";
}

/// "a,b,c" of numbers → [a, b, c]; false when some piece is not a number.
bool numberList(const std::string& text, nlohmann::json& out) {
    out = nlohmann::json::array();
    std::stringstream in(text);
    std::string piece;
    while (std::getline(in, piece, ',')) {
        char* end = nullptr;
        const double v = std::strtod(piece.c_str(), &end);
        if (piece.empty() || *end != '\0') return false;
        out.push_back(v);
    }
    return !out.empty();
}

/// KEY=VALUE pairs → a JSON object: VALUE as JSON when it parses (1.5, true, null, "s", [..]),
/// else comma-separated numbers as an array, else a string.
nlohmann::json fieldsObject(const std::vector<std::string>& fields) {
    nlohmann::json obj = nlohmann::json::object();
    for (const auto& f : fields) {
        const auto eq = f.find('=');
        if (eq == std::string::npos || eq == 0) throw usageError("expected KEY=VALUE, got \"" + f + "\"", f);
        const std::string key = f.substr(0, eq), value = f.substr(eq + 1);
        auto j = nlohmann::json::parse(value, nullptr, false);
        nlohmann::json list;
        if (!j.is_discarded()) obj[key] = j;
        else if (value.find(',') != std::string::npos && numberList(value, list)) obj[key] = list;
        else obj[key] = value;
    }
    return obj;
}

/// JOINT=x,y,z (axis angles in degrees), JOINT=x,y,z,w (a quaternion) or JOINT=none (remove).
nlohmann::json jointsObject(const std::vector<std::string>& joints) {
    nlohmann::json obj = nlohmann::json::object();
    for (const auto& j : joints) {
        const auto eq = j.find('=');
        if (eq == std::string::npos || eq == 0) throw usageError("expected JOINT=x,y,z or JOINT=x,y,z,w, got \"" + j + "\"", j);
        const std::string name = j.substr(0, eq), value = j.substr(eq + 1);
        nlohmann::json v;
        if (value == "none" || value == "null") {
            obj[name] = nullptr;
        } else if (numberList(value, v) && v.size() == 3) {
            obj[name] = {{"axis_angles", {{"x", v[0]}, {"y", v[1]}, {"z", v[2]}}}};
        } else if (v.is_array() && v.size() == 4) {
            obj[name] = {{"rotation", v}};
        } else {
            throw usageError("joint " + name + ": expected x,y,z degrees or a quaternion x,y,z,w, got \"" + value + "\"", j);
        }
    }
    return obj;
}

/// NAME=W (a morph target's weight) or NAME=none (remove), each --morph once.
nlohmann::json morphsObject(const std::vector<std::string>& morphs) {
    nlohmann::json obj = nlohmann::json::object();
    for (const auto& m : morphs) {
        const auto eq = m.find('=');
        if (eq == std::string::npos || eq == 0) throw usageError("expected NAME=WEIGHT, got \"" + m + "\"", "--morph");
        const std::string name = m.substr(0, eq), value = m.substr(eq + 1);
        nlohmann::json v;
        if (value == "none" || value == "null") obj[name] = nullptr;
        else if (numberList(value, v) && v.size() == 1) obj[name] = v[0];
        else throw usageError("morph " + name + ": expected a number, got \"" + value + "\"", "--morph");
    }
    return obj;
}

} // namespace

void addSceneCommands(CLI::App& app, Context& ctx) {
    auto o = std::make_shared<SceneOptions>();
    CLI::App* scene = app.add_subcommand("scene", "Scene documents: create, list, get, put, export, apply, rm, history, revert, propose, transfer");
    scene->require_subcommand(1);

    CLI::App* create = scene->add_subcommand("create", "Create a scene from a dermis.scene/1 document (or the default character with its patterns); prints the id");
    create->add_option("file", o->file, "Scene document (- = stdin)");
    create->add_flag("--default-patterns", o->defaultPatterns, "The default character with its pattern set (no file needed)");
    create->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            nlohmann::json doc;
            if (!o->file.empty()) doc = readJsonFile(o->file, "file");
            else if (!o->defaultPatterns) throw usageError("give a scene document or --default-patterns", "file");
            if (o->defaultPatterns) doc["default_patterns"] = true;
            auto answer = ctx.http().sendJson("POST", "/scenes", doc);
            if (ctx.global.json) printJson(answer);
            else std::cout << answer.value("id", "") << "\n";
            return kExitOk;
        };
    });
    CLI::App* list = scene->add_subcommand("list", "List scenes");
    list->callback([&ctx] {
        ctx.action = [&ctx] {
            auto j = ctx.http().getJson("/scenes");
            if (ctx.global.json) {
                printJson(j);
                return kExitOk;
            }
            std::vector<std::vector<std::string>> rows;
            for (const auto& s : j["scenes"])
                rows.push_back({cell(s["id"]), cell(s["revision"]), cell(s["model"]), cell(s["placements"])});
            printTable({"ID", "REVISION", "MODEL", "PLACEMENTS"}, rows);
            return kExitOk;
        };
    });
    CLI::App* get = scene->add_subcommand("get", "Print a scene's document (--json: with id and revision)");
    get->add_option("id", o->id, "Scene id")->required();
    get->add_option("--revision", o->revision, "The document as it was at this revision")->check(CLI::PositiveNumber);
    get->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            std::string path = scenePath(o->id);
            if (o->revision > 0) path += "?revision=" + std::to_string(o->revision);
            auto j = ctx.http().getJson(path);
            printJson(ctx.global.json ? j : j["scene"]);
            return kExitOk;
        };
    });
    CLI::App* exp = scene->add_subcommand("export", "Write a scene's document to a file (or stdout)");
    exp->add_option("id", o->id, "Scene id")->required();
    exp->add_option("-o,--out", o->out, "Output file (default stdout)");
    exp->add_option("--revision", o->revision, "The document as it was at this revision")->check(CLI::PositiveNumber);
    exp->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            std::string path = scenePath(o->id);
            if (o->revision > 0) path += "?revision=" + std::to_string(o->revision);
            const std::string text = ctx.http().getJson(path)["scene"].dump(2) + "\n";
            if (o->out.empty()) std::cout << text;
            else writeFileAtomically(o->out, text);
            return kExitOk;
        };
    });
    CLI::App* put = scene->add_subcommand("put", "Replace a scene's document");
    put->add_option("id", o->id, "Scene id")->required();
    put->add_option("file", o->file, "Scene document (- = stdin)")->required();
    put->add_option("--if-revision", o->ifRevision, "Only if the scene is at this revision (If-Match)")->check(CLI::PositiveNumber);
    put->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            printEdit(ctx, ctx.http().sendJson("PUT", scenePath(o->id), readJsonFile(o->file, "file"), ifMatch(o->ifRevision)));
            return kExitOk;
        };
    });
    CLI::App* apply = scene->add_subcommand("apply", "Create a scene from a document, or merge it into scene --id (a new revision only when something changes); prints the id");
    apply->add_option("file", o->file, "Scene document (- = stdin)")->required();
    apply->add_option("--id", o->id, "The scene to replace (created when not given)");
    apply->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            nlohmann::json doc = readJsonFile(o->file, "file");
            nlohmann::json answer;
            if (o->id.empty()) {
                answer = ctx.http().sendJson("POST", "/scenes", doc);
            } else {
                // The file is merged into the scene's document (JSON merge patch: members it
                // leaves out keep their values, arrays such as placements are replaced whole);
                // a PUT only when that changes something, so an unchanged apply makes no revision.
                auto current = ctx.http().getJson(scenePath(o->id));
                nlohmann::json merged = current["scene"];
                merged.merge_patch(doc);
                if (merged == current["scene"]) answer = current;
                else answer = ctx.http().sendJson("PUT", scenePath(o->id), merged, ifMatch(current.value("revision", 0)));
            }
            if (ctx.global.json) printJson(answer);
            else std::cout << answer.value("id", "") << "\n";
            return kExitOk;
        };
    });
    CLI::App* rm = scene->add_subcommand("rm", "Delete scenes");
    rm->add_option("ids", o->ids, "Scene ids")->required();
    rm->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            for (const auto& id : o->ids) {
                ctx.http().send("DELETE", scenePath(id), "", "", true);
                if (!ctx.global.json) std::cout << "deleted " << id << "\n";
            }
            return kExitOk;
        };
    });
    CLI::App* history = scene->add_subcommand("history", "A scene's revisions, newest first");
    history->add_option("id", o->id, "Scene id")->required();
    history->add_option("--limit", o->limit, "At most this many (default 50)")->check(CLI::Range(1, 1000));
    history->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            auto j = ctx.http().getJson(scenePath(o->id) + "/revisions?limit=" + std::to_string(o->limit));
            if (ctx.global.json) {
                printJson(j);
                return kExitOk;
            }
            std::vector<std::vector<std::string>> rows;
            for (const auto& r : j["revisions"])
                rows.push_back({cell(r["revision"]), cell(r["time"]), r.value("client", "").empty() ? "-" : cell(r["client"]), cell(r["op"])});
            printTable({"REVISION", "TIME", "CLIENT", "OP"}, rows);
            return kExitOk;
        };
    });
    CLI::App* revert = scene->add_subcommand("revert", "Make a new revision equal to an earlier one (undo/redo)");
    revert->add_option("id", o->id, "Scene id")->required();
    revert->add_option("revision", o->revision, "The revision to go back to")->required()->check(CLI::PositiveNumber);
    revert->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            printEdit(ctx, ctx.http().sendJson("POST", scenePath(o->id) + "/revert", {{"revision", o->revision}}));
            return kExitOk;
        };
    });

    // --- SPEC §8: proposals and transfer
    CLI::App* propose = scene->add_subcommand("propose", "A pattern set for the scene's character from its range of motion (creases, bone ends, bulges; twins paired); --apply adds it in one revision");
    propose->add_option("id", o->id, "Scene id")->required();
    propose->add_flag("--apply", o->apply, "Add the proposals not in the scene yet (one revision)");
    propose->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            const auto j = ctx.http().sendJson("POST", scenePath(o->id) + "/propose" + (o->apply ? "?apply=true" : ""),
                                               nlohmann::json::object(), ifMatch(o->ifRevision));
            if (ctx.global.json) {
                printJson(j);
                return kExitOk;
            }
            std::vector<std::vector<std::string>> rows;
            for (const auto& p : j["proposals"]) {
                const auto& pl = p["placement"];
                std::ostringstream theta;
                theta << pl["theta_min"].get<double>() << ".." << pl["theta_max"].get<double>();
                rows.push_back({cell(pl["id"]), cell(p["kind"]), cell(pl["label"]), cell(pl["joint"]), theta.str(),
                                cell(p["score"]), p["existing"].is_null() ? "-" : cell(p["existing"])});
            }
            printTable({"ID", "KIND", "LABEL", "JOINT", "THETA", "SCORE", "IN SCENE AS"}, rows);
            if (o->apply) std::cout << j.value("id", "") << " r" << j.value("revision", 0) << " (added " << j["applied"].size() << ")\n";
            return kExitOk;
        };
    });
    propose->add_option("--if-revision", o->ifRevision, "Refuse unless the scene is at this revision (If-Match)");
    CLI::App* transfer = scene->add_subcommand("transfer", "Carry another scene's placements onto this scene's character (joints matched across naming conventions, anchors re-projected); one revision");
    transfer->add_option("id", o->id, "Scene id (the character to carry onto)")->required();
    transfer->add_option("--from", o->from, "The scene whose placements to carry over")->required();
    transfer->add_option("--map", o->jointMap, "SOURCE_JOINT=THIS_JOINT: a joint match to use first (repeatable)");
    transfer->add_flag("--dry-run", o->dryRun, "Show what would be carried over and what not; change nothing");
    transfer->add_option("--if-revision", o->ifRevision, "Refuse unless the scene is at this revision (If-Match)");
    transfer->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            nlohmann::json body = {{"from", o->from}};
            if (!o->jointMap.empty()) {
                body["joint_map"] = nlohmann::json::object();
                for (const auto& m : o->jointMap) {
                    const auto eq = m.find('=');
                    if (eq == std::string::npos || eq == 0 || eq + 1 == m.size())
                        throw usageError("expected SOURCE_JOINT=THIS_JOINT, got \"" + m + "\"", m);
                    body["joint_map"][m.substr(0, eq)] = m.substr(eq + 1);
                }
            }
            const auto j = ctx.http().sendJson("POST", scenePath(o->id) + "/transfer" + (o->dryRun ? "?apply=false" : ""),
                                               body, ifMatch(o->ifRevision));
            if (ctx.global.json) {
                printJson(j);
                return kExitOk;
            }
            std::vector<std::vector<std::string>> rows;
            for (const auto& t : j["transferred"])
                rows.push_back({cell(t["from"]), cell(t["placement"]["id"]), cell(t["placement"]["joint"])});
            printTable({"FROM", "PLACEMENT", "JOINT"}, rows);
            for (const auto& u : j["unmapped"])
                std::cout << "not carried over: " << u.value("placement", "") << " (" << u.value("reason", "") << ")\n";
            if (!o->dryRun) std::cout << j.value("id", "") << " r" << j.value("revision", 0) << "\n";
            return kExitOk;
        };
    });

    // --- pose
    CLI::App* pose = app.add_subcommand("pose", "A scene's pose");
    pose->require_subcommand(1);
    CLI::App* set = pose->add_subcommand("set", "Set the clip, time, joint rotations and morph weights (merged into the pose)");
    set->add_option("id", o->id, "Scene id")->required();
    set->add_option("joints", o->joints, "JOINT=x,y,z (axis angles, degrees), JOINT=x,y,z,w (quaternion), JOINT=none (remove)");
    set->add_option("--clip", o->clip, "Animation clip (none = no clip)");
    set->add_option("--time", o->time, "Seconds into the clip")->check(CLI::NonNegativeNumber);
    set->add_option("--morph", o->morphs, "NAME=WEIGHT: a morph target's weight (NAME=none removes it; repeatable)");
    set->add_flag("--replace", o->replace, "Replace the whole pose instead of merging");
    set->add_option("--if-revision", o->ifRevision, "Only if the scene is at this revision (If-Match)")->check(CLI::PositiveNumber);
    set->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            nlohmann::json body = nlohmann::json::object();
            if (!o->clip.empty()) body["animation"] = o->clip == "none" ? nlohmann::json() : nlohmann::json(o->clip);
            if (o->time >= 0) body["time"] = o->time;
            if (!o->joints.empty()) body["joints"] = jointsObject(o->joints);
            if (!o->morphs.empty()) body["morphs"] = morphsObject(o->morphs);
            if (body.empty()) throw usageError("nothing to set: give joints, --clip, --time or --morph", "joints");
            if (o->replace) {
                for (auto it = body.begin(); it != body.end();)
                    it = it->is_null() ? body.erase(it) : std::next(it);
                for (const char* member : {"joints", "morphs"})
                    if (body.contains(member))
                        for (auto it = body[member].begin(); it != body[member].end();)
                            it = it->is_null() ? body[member].erase(it) : std::next(it);
            }
            printEdit(ctx, ctx.http().sendJson(o->replace ? "PUT" : "PATCH", scenePath(o->id) + "/pose", body, ifMatch(o->ifRevision)));
            return kExitOk;
        };
    });

    // --- placements
    CLI::App* placement = app.add_subcommand("placement", "A scene's pattern placements: add, set, rm, mirror");
    placement->require_subcommand(1);
    CLI::App* add = placement->add_subcommand("add", "Add a placement: KEY=VALUE fields (pattern=crease center=0.29,0.74 scale=0.06,0.04 joint=forearm.l axis=x theta_max=130) or --file");
    add->add_option("id", o->id, "Scene id")->required();
    add->add_option("fields", o->fields, "KEY=VALUE (VALUE as JSON, or comma-separated numbers, or text)");
    add->add_option("--file", o->file, "The placement as a JSON file (fields given beside it override)");
    add->add_option("--if-revision", o->ifRevision, "Only if the scene is at this revision (If-Match)")->check(CLI::PositiveNumber);
    add->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            nlohmann::json body = o->file.empty() ? nlohmann::json::object() : readJsonFile(o->file, "--file");
            body.update(fieldsObject(o->fields));
            if (body.empty()) throw usageError("give KEY=VALUE fields or --file", "fields");
            printEdit(ctx, ctx.http().sendJson("POST", scenePath(o->id) + "/placements", body, ifMatch(o->ifRevision)));
            return kExitOk;
        };
    });
    CLI::App* pset = placement->add_subcommand("set", "Change a placement's fields (JSON merge patch: KEY=null removes)");
    pset->add_option("id", o->id, "Scene id")->required();
    pset->add_option("placement", o->pid, "Placement id")->required();
    pset->add_option("fields", o->fields, "KEY=VALUE")->required();
    pset->add_option("--if-revision", o->ifRevision, "Only if the scene is at this revision (If-Match)")->check(CLI::PositiveNumber);
    pset->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            printEdit(ctx, ctx.http().sendJson("PATCH", scenePath(o->id) + "/placements/" + httplib::detail::encode_query_param(o->pid),
                                               fieldsObject(o->fields), ifMatch(o->ifRevision)));
            return kExitOk;
        };
    });
    CLI::App* prm = placement->add_subcommand("rm", "Remove a placement");
    prm->add_option("id", o->id, "Scene id")->required();
    prm->add_option("placement", o->pid, "Placement id")->required();
    prm->add_option("--if-revision", o->ifRevision, "Only if the scene is at this revision (If-Match)")->check(CLI::PositiveNumber);
    prm->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            printEdit(ctx, ctx.http().sendJson("DELETE", scenePath(o->id) + "/placements/" + httplib::detail::encode_query_param(o->pid),
                                               nullptr, ifMatch(o->ifRevision)));
            return kExitOk;
        };
    });
    CLI::App* mirror = placement->add_subcommand("mirror", "Add the mirror twin of a placement (left ↔ right)");
    mirror->add_option("id", o->id, "Scene id")->required();
    mirror->add_option("placement", o->pid, "Placement id")->required();
    mirror->add_flag("--update", o->update, "Where the twin is in the scene already, bring it up to date in place (else: refused, 409)");
    mirror->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            printEdit(ctx, ctx.http().sendJson("POST", scenePath(o->id) + "/placements/" + httplib::detail::encode_query_param(o->pid) + "/mirror" + (o->update ? "?update=true" : ""), nullptr));
            return kExitOk;
        };
    });
}

} // namespace dermis::cli
