// dermis check: golden-frame regression checks. Every case of the checks file is rendered through
// the batch route (PNG), compared with its reference image under --refs (compareImages: per-pixel
// threshold, allowed fraction), and reported: a progress line or log lines, diff images and the
// actual frames of failures under --out (diff/, actual/), a JUnit XML report with --junit.
// --update writes the reference of every case that is missing or differs (and then passes).
// Exit 0 when every case matches, 4 when some differ or failed to render.
#include "batch.hpp"
#include "check_cases.hpp"
#include "commands.hpp"
#include "frames.hpp"
#include "image_compare.hpp"
#include "output.hpp"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

namespace dermis::cli {

namespace {

struct CheckOptions {
    std::string cases, refs, junit, out = "dermis-check";
    double threshold = -1, fraction = -1;
    bool update = false;
};

struct FrameResult {
    std::string caseName, reference, message; // message: "" = passed
    bool updated = false;
    double seconds = 0;
};

std::string xmlEscape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        default: out += c;
        }
    }
    return out;
}

void writeJunit(const std::string& path, const std::string& suite, const std::vector<FrameResult>& results, double seconds) {
    std::size_t failures = 0;
    for (const auto& r : results) failures += r.message.empty() ? 0 : 1;
    std::ostringstream x;
    char time[32];
    std::snprintf(time, sizeof time, "%.3f", seconds);
    x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<testsuites name=\"dermis check\" tests=\"" << results.size() << "\" failures=\"" << failures << "\" time=\"" << time << "\">\n"
      << "  <testsuite name=\"" << xmlEscape(suite) << "\" tests=\"" << results.size() << "\" failures=\"" << failures
      << "\" errors=\"0\" skipped=\"0\" time=\"" << time << "\">\n";
    for (const auto& r : results) {
        std::snprintf(time, sizeof time, "%.3f", r.seconds);
        x << "    <testcase classname=\"" << xmlEscape(suite + "." + r.caseName) << "\" name=\"" << xmlEscape(r.reference)
          << "\" time=\"" << time << "\"";
        if (r.message.empty()) {
            x << "/>\n";
        } else {
            x << ">\n      <failure message=\"" << xmlEscape(r.message) << "\" type=\"ImageDifference\">" << xmlEscape(r.message)
              << "</failure>\n    </testcase>\n";
        }
    }
    x << "  </testsuite>\n</testsuites>\n";
    writeFileAtomically(path, x.str());
}

std::string fixed3(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f", v);
    return buf;
}

std::string percent(double f) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f%%", f * 100.0);
    return buf;
}

} // namespace

void addCheckCommand(CLI::App& app, Context& ctx) {
    auto o = std::make_shared<CheckOptions>();
    CLI::App* check = app.add_subcommand("check", "Render the cases of a checks file and compare them with reference images (golden-frame regression tests)");
    check->add_option("cases", o->cases, "Checks file (JSON; see client/README.md)")->required()->check(CLI::ExistingFile);
    check->add_option("--refs", o->refs, "Folder of the reference images")->required();
    check->add_flag("--update", o->update, "Write the references of cases that are missing or differ");
    check->add_option("--junit", o->junit, "Write a JUnit XML report here");
    check->add_option("--out", o->out, "Folder for diff/ and actual/ images of failures (default dermis-check)");
    check->add_option("--threshold", o->threshold, "A pixel differs when a channel differs by more than this (0…1; overrides the file)")
        ->check(CLI::Range(0.0, 1.0));
    check->add_option("--fraction", o->fraction, "Allowed fraction of differing pixels (0…1; overrides the file)")->check(CLI::Range(0.0, 1.0));
    check->callback([&ctx, o] {
        ctx.action = [&ctx, o] {
            std::vector<CheckCase> cases = parseChecks(o->cases);
            std::size_t total = 0;
            for (const auto& c : cases) total += c.frames.size();
            Progress progress("frames", total, stdoutIsTerminal() && !ctx.global.json);
            std::vector<FrameResult> results;
            std::map<std::string, nlohmann::json> documents; // file or id → document
            std::map<std::string, ContentFiles> contents;     // scene file → its files by address
            bool interrupted = false;
            for (const CheckCase& c : cases) {
                if (interrupted) break;
                nlohmann::json scene;
                if (!c.sceneDoc.is_null()) scene = c.sceneDoc;
                else if (!c.sceneId.empty()) {
                    if (!documents.count(c.sceneId)) documents[c.sceneId] = ctx.http().getJson(scenePath(c.sceneId))["scene"];
                    scene = documents[c.sceneId];
                } else {
                    if (!documents.count(c.sceneFile)) {
                        // Its model and pattern files go by content address (any server can render it).
                        documents[c.sceneFile] = readJsonFile(c.sceneFile, "/cases/" + c.name + "/scene");
                        contents[c.sceneFile] = addressContent(documents[c.sceneFile], c.sceneFile);
                    }
                    scene = documents[c.sceneFile];
                }
                if (!c.size.is_null()) scene["render"]["size"] = c.size;
                if (!c.camera.is_null()) scene["render"]["camera"].update(c.camera);
                const double threshold = o->threshold >= 0 ? o->threshold : c.threshold;
                const double fraction = o->fraction >= 0 ? o->fraction : c.fraction;
                nlohmann::json frames = nlohmann::json::array();
                for (const auto& f : c.frames) {
                    nlohmann::json req = f.request;
                    if (req.contains("time") && req["time"].is_null())
                        req = scene.contains("pose") ? nlohmann::json{{"pose", scene["pose"]}} : nlohmann::json{{"time", 0.0}};
                    frames.push_back(req);
                }
                auto started = std::chrono::steady_clock::now();
                std::vector<bool> seen(c.frames.size(), false);
                auto judge = [&](std::size_t k, const std::string& bytes) {
                    FrameResult r{c.name, c.frames[k].reference, "", false, 0};
                    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
                    started = std::chrono::steady_clock::now();
                    const std::string refPath = (std::filesystem::path(o->refs) / r.reference).string();
                    Rgba8 actual, reference;
                    std::string error;
                    if (!decodeImage(bytes, actual, error)) {
                        r.message = "the server's frame does not decode: " + error;
                    } else if (!std::filesystem::exists(refPath)) {
                        r.message = "no reference image " + refPath + " (run with --update to write it)";
                    } else if (!decodeImage(readFileOrThrow(refPath, "--refs"), reference, error)) {
                        r.message = "the reference " + refPath + " does not decode: " + error;
                    } else {
                        Comparison cmp = compareImages(actual, reference, threshold, fraction);
                        if (!cmp.sizeMatches) {
                            r.message = "size " + std::to_string(actual.width) + "x" + std::to_string(actual.height) +
                                        " differs from the reference's " + std::to_string(reference.width) + "x" +
                                        std::to_string(reference.height);
                        } else if (!cmp.pass) {
                            const std::string diffPath = (std::filesystem::path(o->out) / "diff" / r.reference).string();
                            std::string png;
                            if (encodePng(cmp.diff, png, error)) writeFileAtomically(diffPath, png);
                            r.message = percent(cmp.fraction) + " of the pixels differ by more than " + nlohmann::json(threshold).dump() +
                                        " (allowed " + percent(fraction) + ", largest difference " + fixed3(cmp.maxDifference) +
                                        "); diff image " + diffPath;
                        }
                    }
                    if (!r.message.empty()) {
                        if (o->update && actual.width > 0) {
                            writeFileAtomically(refPath, bytes);
                            r.updated = true;
                            r.message.clear();
                        } else {
                            writeFileAtomically((std::filesystem::path(o->out) / "actual" / r.reference).string(), bytes);
                        }
                    }
                    const std::string verdict = r.updated ? "UPDATED" : r.message.empty() ? "PASS" : "FAIL";
                    if (!ctx.global.json) progress.step(verdict + " " + r.reference + (r.message.empty() ? "" : ": " + r.message), !r.message.empty());
                    results.push_back(std::move(r));
                };
                BatchOutcome outcome = renderBatch(ctx.http(), scene, frames, "png", c.view, [&](std::size_t k, std::string bytes) {
                    seen[k] = true;
                    judge(k, bytes);
                    return true;
                }, c.sceneFile.empty() ? nullptr : &contents[c.sceneFile]);
                interrupted = outcome.interrupted;
                if (outcome.broken) outcome.failure = outcome.brokenWhy;
                if (!interrupted)
                    for (std::size_t k = 0; k < c.frames.size(); ++k)
                        if (!seen[k]) {
                            FrameResult r{c.name, c.frames[k].reference, "render failed: " + (outcome.failure.empty() ? std::string("no frame") : outcome.failure), false, 0};
                            if (!ctx.global.json) progress.step("FAIL " + r.reference + ": " + r.message, true);
                            results.push_back(std::move(r));
                        }
            }
            progress.finish();
            std::size_t failed = 0, updated = 0;
            for (const auto& r : results) {
                failed += r.message.empty() ? 0 : 1;
                updated += r.updated ? 1 : 0;
            }
            if (!o->junit.empty())
                writeJunit(o->junit, std::filesystem::path(o->cases).stem().string(), results, progress.seconds());
            if (ctx.global.json) {
                nlohmann::json list = nlohmann::json::array();
                for (const auto& r : results)
                    list.push_back({{"case", r.caseName}, {"reference", r.reference}, {"passed", r.message.empty()}, {"updated", r.updated},
                                    {"message", r.message}});
                printJson({{"frames", results.size()}, {"failed", failed}, {"updated", updated}, {"results", list}});
            } else {
                std::cout << results.size() - failed << " passed, " << failed << " failed" << (updated ? ", " + std::to_string(updated) + " references updated" : "")
                          << "\n";
            }
            if (interrupted) {
                std::cerr << "dermis: interrupted\n";
                return kExitInterrupted;
            }
            return failed ? kExitFramesFailed : kExitOk;
        };
    });
}

} // namespace dermis::cli
