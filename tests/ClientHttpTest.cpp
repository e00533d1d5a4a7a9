// ClientHttpTest — the `dermis` command-line client (client/, issue #14) as a child process against
// dermis-server as a real process on 127.0.0.1 (a GL context through $DERMIS_TEST_GL). It checks:
//   * every subcommand: health, info, model upload|list|show|rm (content-addressed: the same id
//     twice), pattern upload|list|rm, environment upload|list|rm, scene create|list|get|put|export|apply|rm|history|revert,
//     pose set (joints, clip, time, --morph), placement add|set|rm|mirror, frame (--key-light too), maps,
//     lint, watch, render, check;
//   * exit codes and messages: bad arguments → 2, server errors → 1 with
//     "dermis: error: <message> (<field>)", an unreachable server → 3;
//   * render --scene-file sends the scene file's environment (.hdr beside it) by content address:
//     the same frames as with the environment uploaded and named by id, not the studio's;
//   * render --resume after the client is killed (SIGKILL) mid-range writes exactly the remaining
//     frames, byte-identical to an uninterrupted run, and leaves the finished ones untouched;
//     Ctrl-C (SIGINT) stops with 130 and no partial file;
//   * check passes on the committed references (tests/check), fails with a diff image and a JUnit
//     failure when a placement is moved, and --update fixes it;
//   * the progress line ('\r', frames/s) appears under a pseudo-terminal (script from util-linux)
//     and not when stdout is a file.
#include "BuildPaths.hpp"
#include "TestFiles.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

using namespace dermis::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

const std::string kClient = dermis::build::clientExe();
const std::string kSource = dermis::build::sourceDir();
const std::string kRiggedFigure =
    std::string(dermis::build::testModelsDir()) + "/RiggedFigure/RiggedFigure.glb";

std::string backend() {
    const char* env = std::getenv("DERMIS_TEST_GL");
    return env && *env ? env : "auto";
}

std::string quote(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), {});
}

/// dermis-server serving a fresh data folder on a free port; killed on destruction.
class ServerProcess {
public:
    /// `token`: the server's --token ("" = none).
    explicit ServerProcess(const std::string& dir, const std::string& token = "") : log_(dir + "/server.log") {
        fs::create_directories(dir + "/data");
        pid_ = ::fork();
        if (pid_ == 0) {
            ::prctl(PR_SET_PDEATHSIG, SIGKILL); // never outlives the test, even a crashed one
            const int fd = ::open(log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            ::dup2(fd, 1);
            ::dup2(fd, 2);
            const std::string data = dir + "/data", gl = backend();
            ::unsetenv("DERMIS_TOKEN");
            if (token.empty())
                ::execl(dermis::build::serverExe(), dermis::build::serverExe(), "serve", "--port",
                        "0", "--data", data.c_str(), "--gl", gl.c_str(),
                        static_cast<char*>(nullptr));
            else
                ::execl(dermis::build::serverExe(), dermis::build::serverExe(), "serve", "--port",
                        "0", "--data", data.c_str(), "--gl", gl.c_str(), "--token", token.c_str(),
                        static_cast<char*>(nullptr));
            ::_exit(127);
        }
        for (int i = 0; i < 600 && port_ == 0; ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
            const std::string text = slurp(log_);
            const auto at = text.find("serving http://127.0.0.1:");
            if (at != std::string::npos) port_ = std::atoi(text.c_str() + at + 25);
        }
    }
    ~ServerProcess() {
        if (pid_ > 0) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
    }
    int port() const { return port_; }
    std::string log() const { return slurp(log_); }

private:
    pid_t pid_ = -1;
    int port_ = 0;
    std::string log_;
};

struct ClientRun {
    int code = -1;
    std::string out, err;
    json js() const { return json::parse(out, nullptr, false); }
    std::string firstLine() const { return out.substr(0, out.find('\n')); }
};

std::ostream& operator<<(std::ostream& os, const ClientRun& r) {
    return os << "exit " << r.code << "\n--- stdout\n" << r.out << "--- stderr\n" << r.err;
}

class ClientHttpTest : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = new TempDir();
        server_ = new ServerProcess(dir_->str());
    }
    static void TearDownTestSuite() {
        delete server_;
        delete dir_;
        server_ = nullptr;
        dir_ = nullptr;
    }
    void SetUp() override { ASSERT_GT(server_->port(), 0) << server_->log(); }

    static std::string url() { return "http://127.0.0.1:" + std::to_string(server_->port()); }

    /// The shell command running the client with `args` (the server through DERMIS_SERVER).
    static std::string command(const std::vector<std::string>& args) {
        std::string cmd = "env -u DERMIS_TOKEN DERMIS_SERVER=" + url() + " " + quote(kClient);
        for (const auto& a : args) cmd += " " + quote(a);
        return cmd;
    }
    /// Runs the client to completion; stdout and stderr kept apart (stdout is a file, not a tty).
    static ClientRun dermis(const std::vector<std::string>& args) {
        static int n = 0;
        const std::string out = *dir_ / ("out" + std::to_string(n) + ".txt"), err = *dir_ / ("err" + std::to_string(n) + ".txt");
        ++n;
        ClientRun r;
        const int status = std::system((command(args) + " >" + quote(out) + " 2>" + quote(err)).c_str());
        r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        r.out = slurp(out);
        r.err = slurp(err);
        return r;
    }
    static std::string newScene() {
        ClientRun r = dermis({"scene", "create", "--default-patterns"});
        EXPECT_EQ(r.code, 0) << r;
        return r.firstLine();
    }

    static TempDir* dir_;
    static ServerProcess* server_;
};

TempDir* ClientHttpTest::dir_ = nullptr;
ServerProcess* ClientHttpTest::server_ = nullptr;

std::vector<std::string> filesIn(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

/// The value of `key` in a KEY / VALUE table ("" when no line starts with the key).
std::string keyValue(const std::string& out, const std::string& key) {
    std::istringstream lines(out);
    for (std::string line; std::getline(lines, line);) {
        if (line.rfind(key + " ", 0) != 0) continue;
        const std::size_t at = line.find_first_not_of(' ', key.size());
        return at == std::string::npos ? "" : line.substr(at);
    }
    return "";
}

TEST_F(ClientHttpTest, HealthInfoModelsAndPatterns) {
    ClientRun health = dermis({"health"});
    EXPECT_EQ(health.code, 0) << health;
    EXPECT_EQ(health.out, "ok\n");
    ClientRun info = dermis({"--json", "info"});
    ASSERT_EQ(info.code, 0) << info;
    EXPECT_EQ(info.js()["name"], "dermis-server");
    ClientRun infoTable = dermis({"info"});
    EXPECT_NE(infoTable.out.find("limits.max_batch_frames"), std::string::npos) << infoTable;

    ClientRun list = dermis({"model", "list"});
    ASSERT_EQ(list.code, 0) << list;
    EXPECT_EQ(list.out.rfind("ID", 0), 0u) << list;
    EXPECT_NE(list.out.find("builtin:default"), std::string::npos) << list;
    ClientRun show = dermis({"model", "show", "builtin:default"});
    ASSERT_EQ(show.code, 0) << show;
    EXPECT_NE(show.out.find("elbow_curl"), std::string::npos) << show;
    // The UV diagnosis: unique UVs, and the density of the joints that drive triangles.
    EXPECT_EQ(keyValue(show.out, "uv_usable"), "yes") << show;
    EXPECT_EQ(keyValue(show.out, "uv_overlap"), "0.00%") << show;
    EXPECT_EQ(keyValue(show.out, "uv_missing"), "0 triangles") << show;
    EXPECT_NE(show.out.find("TEXELS/UNIT @1024"), std::string::npos) << show;
    EXPECT_EQ(show.out.find("SHARES TEXELS WITH"), std::string::npos) << show;

    // Content-addressed: the same bytes twice give the same id.
    ClientRun up1 = dermis({"model", "upload", kRiggedFigure, "--name", "fig"});
    ClientRun up2 = dermis({"--json", "model", "upload", kRiggedFigure});
    ASSERT_EQ(up1.code, 0) << up1;
    ASSERT_EQ(up2.code, 0) << up2;
    const std::string id = up1.firstLine();
    EXPECT_EQ(id.rfind("m_", 0), 0u) << up1;
    EXPECT_EQ(up2.js()["id"], id);
    EXPECT_EQ(up2.js()["name"], "fig");
    EXPECT_NE(dermis({"model", "list"}).out.find(id), std::string::npos);
    ClientRun figure = dermis({"model", "show", id});
    ASSERT_EQ(figure.code, 0) << figure;
    EXPECT_EQ(keyValue(figure.out, "uv_usable"), "no") << figure;
    EXPECT_EQ(keyValue(figure.out, "uv_missing"), "256 triangles") << figure;
    ClientRun rm = dermis({"model", "rm", id});
    EXPECT_EQ(rm.code, 0) << rm;
    ClientRun rm2 = dermis({"model", "rm", id});
    EXPECT_EQ(rm2.code, 1) << rm2;
    EXPECT_EQ(rm2.err, "dermis: error: dermis::Service: id: no model \"" + id + "\" (id)\n") << rm2;

    ClientRun pup = dermis({"pattern", "upload", kSource + "/patterns/crease.png", "--name", "my crease"});
    ASSERT_EQ(pup.code, 0) << pup;
    const std::string pid = pup.firstLine();
    EXPECT_EQ(pid.rfind("p_", 0), 0u) << pup;
    ClientRun plist = dermis({"pattern", "list"});
    EXPECT_NE(plist.out.find(pid), std::string::npos) << plist;
    EXPECT_NE(plist.out.find("my crease"), std::string::npos) << plist;
    EXPECT_EQ(dermis({"pattern", "rm", pid}).code, 0);
    EXPECT_EQ(dermis({"--json", "pattern", "list"}).js()["patterns"].dump().find(pid), std::string::npos);

    const float sky[3] = {0.8f, 0.7f, 0.6f};
    writeText(*dir_ / "dusk.hdr", radianceHdr(32, 16, sky, sky));
    ClientRun eup = dermis({"environment", "upload", *dir_ / "dusk.hdr"});
    ASSERT_EQ(eup.code, 0) << eup;
    const std::string eid = eup.firstLine();
    EXPECT_EQ(eid.rfind("e_", 0), 0u) << eup;
    ClientRun elist = dermis({"environment", "list"});
    EXPECT_NE(elist.out.find(eid), std::string::npos) << elist;
    EXPECT_NE(elist.out.find("dusk"), std::string::npos) << elist;
    EXPECT_NE(elist.out.find("builtin:studio"), std::string::npos) << elist;
    EXPECT_EQ(dermis({"environment", "rm", eid}).code, 0);
    EXPECT_EQ(dermis({"--json", "environment", "list"}).js()["environments"].dump().find(eid), std::string::npos);
}

TEST_F(ClientHttpTest, GltfWithItsFilesUploadsAsMultipart) {
    const auto [gltf, bin] = triangleGltf("tri.bin");
    writeText(*dir_ / "tri.gltf", gltf);
    writeText(*dir_ / "tri.bin", bin);
    ClientRun up = dermis({"--json", "model", "upload", *dir_ / "tri.gltf", *dir_ / "tri.bin"});
    ASSERT_EQ(up.code, 0) << up;
    EXPECT_EQ(up.js()["triangles"], 1);
    EXPECT_EQ(up.js()["name"], "tri");
    ClientRun again = dermis({"model", "upload", *dir_ / "tri.gltf", *dir_ / "tri.bin"});
    EXPECT_EQ(again.firstLine(), up.js()["id"]) << again;
    ClientRun missing = dermis({"model", "upload", *dir_ / "tri.gltf"});
    EXPECT_EQ(missing.code, 1) << missing;
    EXPECT_EQ(dermis({"model", "rm", up.js()["id"]}).code, 0);
}

TEST_F(ClientHttpTest, TokenFromTheOptionOrTheEnvironment) {
    TempDir dir;
    ServerProcess guarded(dir.str(), "s3cret");
    ASSERT_GT(guarded.port(), 0) << guarded.log();
    const std::string server = "http://127.0.0.1:" + std::to_string(guarded.port());
    ClientRun health = dermis({"--server", server, "health"});
    EXPECT_EQ(health.code, 0) << health << "(/health needs no token)";
    ClientRun without = dermis({"--server", server, "model", "list"});
    EXPECT_EQ(without.code, 1) << without;
    EXPECT_NE(without.err.find("dermis: error: "), std::string::npos) << without;
    ClientRun wrong = dermis({"--server", server, "--token", "nope", "model", "list"});
    EXPECT_EQ(wrong.code, 1) << wrong;
    ClientRun right = dermis({"--server", server, "--token", "s3cret", "model", "list"});
    EXPECT_EQ(right.code, 0) << right;
    const int env = std::system(("DERMIS_TOKEN=s3cret " + quote(kClient) + " --server " + server + " model list >/dev/null").c_str());
    EXPECT_TRUE(WIFEXITED(env) && WEXITSTATUS(env) == 0);
}

TEST_F(ClientHttpTest, ScenesPosesPlacementsAndHistory) {
    const std::string sid = newScene();
    ASSERT_EQ(sid.rfind("s_", 0), 0u) << sid;
    EXPECT_NE(dermis({"scene", "list"}).out.find(sid), std::string::npos);
    ClientRun get = dermis({"scene", "get", sid});
    ASSERT_EQ(get.code, 0) << get;
    EXPECT_EQ(get.js()["format"], "dermis.scene/1");

    ClientRun pose = dermis({"pose", "set", sid, "--clip", "elbow_curl", "--time", "0.5", "forearm.l=0,0,30", "hand.l=0,0,0,1"});
    ASSERT_EQ(pose.code, 0) << pose;
    EXPECT_EQ(pose.out, sid + " r2\n");
    json doc = dermis({"scene", "get", sid}).js();
    EXPECT_EQ(doc["pose"]["animation"], "elbow_curl");
    EXPECT_DOUBLE_EQ(doc["pose"]["time"].get<double>(), 0.5);
    EXPECT_EQ(doc["pose"]["joints"]["forearm.l"]["axis_angles"]["z"], 30.0) << doc["pose"];
    EXPECT_EQ(doc["pose"]["joints"]["hand.l"]["rotation"], json({0.0, 0.0, 0.0, 1.0})) << doc["pose"];
    // --morph reaches pose.morphs: the default character has no morph targets, so the server
    // refuses the name (404) and the client reports it with the field; a bad weight is a usage error.
    ClientRun morph = dermis({"pose", "set", sid, "--morph", "smile=0.5"});
    EXPECT_EQ(morph.code, 1) << morph;
    EXPECT_NE(morph.err.find("(/pose/morphs/smile)"), std::string::npos) << morph;
    EXPECT_EQ(dermis({"pose", "set", sid, "--morph", "smile=lots"}).code, 2);

    EXPECT_EQ(dermis({"placement", "set", sid, "elbow_l", "h=1.5", "label=left elbow"}).out, sid + " r3\n");
    EXPECT_EQ(dermis({"placement", "add", sid, "id=extra", "pattern=crease", "center=0.289,0.70", "scale=0.05,0.05", "joint=forearm.l",
                      "axis=x", "theta_max=120"})
                  .out,
              sid + " r4\n");
    // (elbow_l's twin is in the default set already: mirroring it would be a 409.)
    ClientRun mirror = dermis({"placement", "mirror", sid, "extra"});
    EXPECT_EQ(mirror.code, 0) << mirror;
    EXPECT_EQ(dermis({"placement", "rm", sid, "extra"}).out, sid + " r6\n");
    doc = dermis({"scene", "get", sid}).js();
    json elbow;
    for (const auto& p : doc["placements"])
        if (p["id"] == "elbow_l") elbow = p;
    EXPECT_EQ(elbow["h"], 1.5);
    EXPECT_EQ(elbow["label"], "left elbow");
    EXPECT_EQ(doc["placements"].size(), 19u) << "18 + extra's mirror twin";
    EXPECT_EQ(doc["placements"].back()["id"], "extra_r") << "named after its joint's side";
    EXPECT_EQ(doc["placements"].back()["joint"], "forearm.r");

    ClientRun history = dermis({"--json", "scene", "history", sid});
    ASSERT_EQ(history.code, 0) << history;
    EXPECT_EQ(history.js()["revision"], 6);
    EXPECT_EQ(history.js()["revisions"][0]["op"], "delete placement extra");
    EXPECT_NE(dermis({"scene", "history", sid}).out.find("mirror placement extra"), std::string::npos);
    EXPECT_EQ(dermis({"scene", "revert", sid, "1"}).out, sid + " r7\n");
    EXPECT_EQ(dermis({"scene", "get", sid}).js()["placements"].size(), 18u);

    // export → put → apply of an unchanged document makes no revision; a change does.
    const std::string file = *dir_ / "exported.scene.json";
    ASSERT_EQ(dermis({"scene", "export", sid, "-o", file}).code, 0);
    EXPECT_EQ(json::parse(slurp(file)), dermis({"scene", "get", sid}).js());
    EXPECT_EQ(dermis({"scene", "put", sid, file, "--if-revision", "7"}).out, sid + " r8\n");
    ClientRun stale = dermis({"scene", "put", sid, file, "--if-revision", "7"});
    EXPECT_EQ(stale.code, 1) << stale;
    EXPECT_EQ(dermis({"scene", "apply", file, "--id", sid}).code, 0);
    EXPECT_EQ(dermis({"--json", "scene", "get", sid}).js()["revision"], 8) << "unchanged: no new revision";
    json changed = json::parse(slurp(file));
    changed["pose"]["time"] = 1.0;
    const std::string file2 = *dir_ / "changed.scene.json";
    writeText(file2, changed.dump());
    EXPECT_EQ(dermis({"scene", "apply", file2, "--id", sid}).out, sid + "\n");
    EXPECT_EQ(dermis({"--json", "scene", "get", sid}).js()["revision"], 9);
    ClientRun created = dermis({"scene", "apply", file2});
    ASSERT_EQ(created.code, 0) << created;
    EXPECT_NE(created.firstLine(), sid);
    EXPECT_EQ(dermis({"scene", "rm", created.firstLine(), sid}).code, 0);
    EXPECT_EQ(dermis({"scene", "get", sid}).code, 1);
}

TEST_F(ClientHttpTest, ProposeTransferAndMirrorUpdate) {
    // An empty scene of the default character: propose lists, --apply adds them in one revision.
    const std::string file = *dir_ / "empty.scene.json";
    writeText(file, R"({"format": "dermis.scene/1", "model": "builtin:default", "placements": []})");
    ClientRun made = dermis({"scene", "create", file});
    ASSERT_EQ(made.code, 0) << made;
    const std::string sid = made.firstLine();
    ClientRun listed = dermis({"scene", "propose", sid});
    ASSERT_EQ(listed.code, 0) << listed;
    EXPECT_NE(listed.out.find("left elbow crease"), std::string::npos) << listed;
    EXPECT_NE(listed.out.find("right knee crease"), std::string::npos) << listed;
    const std::size_t count = dermis({"--json", "scene", "propose", sid}).js()["proposals"].size();
    ClientRun applied = dermis({"scene", "propose", sid, "--apply"});
    ASSERT_EQ(applied.code, 0) << applied;
    EXPECT_NE(applied.out.find(sid + " r2 (added " + std::to_string(count) + ")"), std::string::npos) << applied;
    EXPECT_EQ(dermis({"scene", "get", sid}).js()["placements"].size(), count);
    EXPECT_EQ(dermis({"scene", "propose", sid, "--apply"}).code, 1) << "all there already: 409";
    // The twin is there: mirror refuses, --update brings it up to date in place.
    EXPECT_EQ(dermis({"placement", "mirror", sid, "elbow_crease_l"}).code, 1);
    EXPECT_EQ(dermis({"placement", "mirror", sid, "elbow_crease_l", "--update"}).out, sid + " r3\n");
    // Transfer: a dry run changes nothing; then the default set comes over in one revision.
    const std::string from = newScene();
    ClientRun dry = dermis({"scene", "transfer", sid, "--from", from, "--dry-run"});
    ASSERT_EQ(dry.code, 0) << dry;
    EXPECT_NE(dry.out.find("elbow_l"), std::string::npos) << dry;
    EXPECT_EQ(dermis({"--json", "scene", "get", sid}).js()["revision"], 3);
    ClientRun moved = dermis({"scene", "transfer", sid, "--from", from, "--map", "neck_01=neck_02"});
    ASSERT_EQ(moved.code, 0) << moved;
    EXPECT_NE(moved.out.find(sid + " r4"), std::string::npos) << moved;
    const json doc = dermis({"scene", "get", sid}).js();
    EXPECT_EQ(doc["placements"].size(), count + 18);
    for (const auto& p : doc["placements"])
        if (p["id"] == "neck") EXPECT_EQ(p["joint"], "neck_02") << "--map is used first";
    EXPECT_EQ(dermis({"scene", "transfer", sid, "--from", from, "--map", "bad"}).code, 2);
}

TEST_F(ClientHttpTest, FramesMapsLintAndWatch) {
    const std::string sid = newScene();
    const std::string png = *dir_ / "frames/one.png", jpg = *dir_ / "frames/one.jpg";
    ClientRun frame = dermis({"frame", sid, "-o", png, "--width", "64", "--height", "48", "--yaw", "30"});
    ASSERT_EQ(frame.code, 0) << frame;
    const std::string bytes = slurp(png);
    ASSERT_GT(bytes.size(), 24u);
    EXPECT_EQ(bytes.substr(1, 3), "PNG");
    auto be32 = [&](std::size_t at) {
        return (unsigned(static_cast<unsigned char>(bytes[at])) << 24) | (unsigned(static_cast<unsigned char>(bytes[at + 1])) << 16) |
               (unsigned(static_cast<unsigned char>(bytes[at + 2])) << 8) | unsigned(static_cast<unsigned char>(bytes[at + 3]));
    };
    EXPECT_EQ(be32(16), 64u);
    EXPECT_EQ(be32(20), 48u);
    ASSERT_EQ(dermis({"frame", sid, "-o", jpg, "--width", "64", "--height", "64"}).code, 0);
    EXPECT_EQ(static_cast<unsigned char>(slurp(jpg)[0]), 0xFF);
    EXPECT_FALSE(fs::exists(png + ".dermis-part"));
    // --key-light on adds the default key light to a pbr frame; off is the frame without it.
    const auto pbrFrame = [&](const std::string& name, std::vector<std::string> extra) {
        std::vector<std::string> args = {"frame", sid, "-o", *dir_ / ("frames/" + name), "--width", "64",
                                         "--height", "64", "--shading", "pbr"};
        args.insert(args.end(), extra.begin(), extra.end());
        ClientRun r = dermis(args);
        EXPECT_EQ(r.code, 0) << r;
        return slurp(*dir_ / ("frames/" + name));
    };
    const std::string lit = pbrFrame("lit.png", {"--key-light", "on"}), plain = pbrFrame("plain.png", {});
    EXPECT_NE(lit, plain);
    EXPECT_EQ(pbrFrame("off.png", {"--key-light", "off"}), plain);
    EXPECT_EQ(dermis({"frame", sid, "-o", png, "--key-light", "maybe"}).code, 2);
    ClientRun maps = dermis({"maps", sid, "bump", "-o", *dir_ / "frames/bump.png"});
    ASSERT_EQ(maps.code, 0) << maps;
    EXPECT_EQ(slurp(*dir_ / "frames/bump.png").substr(1, 3), "PNG");
    ASSERT_EQ(dermis({"maps", sid, "displacement", "-o", *dir_ / "frames/disp.f32"}).code, 0);
    EXPECT_EQ(fs::file_size(*dir_ / "frames/disp.f32") % 4, 0u);

    ClientRun clean = dermis({"lint", sid});
    EXPECT_EQ(clean.out, "no findings\n") << clean; // the shipped default scene lints clean
    // A knee crease driven by the elbow: no_influence, shown as a table.
    ASSERT_EQ(dermis({"placement", "set", sid, "knee_l", "joint=forearm.l"}).code, 0);
    ClientRun lint = dermis({"lint", sid});
    EXPECT_EQ(lint.code, 0) << lint;
    EXPECT_NE(lint.out.find("no_influence"), std::string::npos) << lint;
    EXPECT_NE(lint.out.find("SEVERITY"), std::string::npos) << lint;
    ClientRun lintJson = dermis({"--json", "lint", sid});
    EXPECT_TRUE(lintJson.js().is_array()) << lintJson;

    // watch: hello, then the change made while it listens, as JSON lines.
    const std::string out = *dir_ / "watch.txt";
    std::thread watcher([&] { std::system((command({"watch", sid, "--count", "2"}) + " >" + quote(out)).c_str()); });
    for (int i = 0; i < 100 && slurp(out).find("hello") == std::string::npos; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    EXPECT_EQ(dermis({"pose", "set", sid, "--time", "0.25"}).code, 0);
    watcher.join();
    std::istringstream lines(slurp(out));
    std::string line;
    std::vector<json> events;
    while (std::getline(lines, line)) events.push_back(json::parse(line, nullptr, false));
    ASSERT_EQ(events.size(), 2u) << slurp(out);
    EXPECT_EQ(events[0]["type"], "hello");
    EXPECT_EQ(events[1]["revision"], 3); // after the knee edit above
}

TEST_F(ClientHttpTest, BadArgumentsServerErrorsAndNoServer) {
    for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
             {},
             {"nonsense"},
             {"frame"},
             {"model", "show"},
             {"render", "s_0000000000000000", "--frames", "2:1:1", "--out", "x_%04d.png"},
             {"render", "s_0000000000000000", "--frames", "0:1:0.5", "--out", "x.gif"},
             {"render", "s_0000000000000000", "--frames", "0:1:0.5", "--out", "x.png"},
             {"pose", "set", "s_0000000000000000", "forearm.l=1,2"},
             {"--timeout", "-1", "health"},
             {"--server", "ftp://x", "health"}}) {
        ClientRun r = dermis(args);
        EXPECT_EQ(r.code, 2) << testing::PrintToString(args) << "\n" << r;
        EXPECT_EQ(r.err.rfind("dermis: error: ", 0), 0u) << r;
    }
    ClientRun bad = dermis({"pose", "set", "s_0000000000000000", "forearm.l=1,2"});
    EXPECT_EQ(bad.err, "dermis: error: joint forearm.l: expected x,y,z degrees or a quaternion x,y,z,w, got \"1,2\" (forearm.l=1,2)\n");

    ClientRun missing = dermis({"scene", "get", "s_0000000000000000"});
    EXPECT_EQ(missing.code, 1) << missing;
    EXPECT_EQ(missing.err, "dermis: error: dermis::Service: id: no scene \"s_0000000000000000\" (id)\n");
    const std::string sid = newScene();
    ClientRun invalid = dermis({"placement", "set", sid, "elbow_l", "h=-5"});
    EXPECT_EQ(invalid.code, 1) << invalid;
    EXPECT_NE(invalid.err.find("(/placements/"), std::string::npos) << invalid;
    ClientRun noFrames = dermis({"frame", sid, "-o", *dir_ / "huge.png", "--width", "100000"});
    EXPECT_EQ(noFrames.code, 1) << noFrames;
    EXPECT_FALSE(fs::exists(*dir_ / "huge.png"));

    ClientRun down = dermis({"--server", "http://127.0.0.1:1", "--retries", "0", "health"});
    EXPECT_EQ(down.code, 3) << down;
    EXPECT_EQ(down.err, "dermis: error: cannot connect to http://127.0.0.1:1: connection refused or host unreachable (--server)\n");
}

// A farm's scene file names its image-based light by file, as dermis-server render --scene reads
// it: the client sends it by content address like the model and patterns (issue #26).
TEST_F(ClientHttpTest, SceneFileEnvironmentIsSentByContent) {
    const float sky[3] = {1.6f, 0.5f, 0.1f}, ground[3] = {0.05f, 0.1f, 0.4f};
    fs::create_directories(*dir_ / "shot");
    writeText(*dir_ / "shot/sky.hdr", radianceHdr(64, 32, sky, ground));
    const auto sceneWith = [&](const std::string& name, const std::string& environment) {
        const json doc = {{"format", "dermis.scene/1"},
                          {"model", "builtin:default"},
                          {"render", {{"size", {64, 64}}, {"shading", "pbr"}, {"environment", environment}}}};
        writeText(*dir_ / ("shot/" + name), doc.dump());
        return *dir_ / ("shot/" + name);
    };
    const auto renderTo = [&](const std::string& scene, const std::string& dir) {
        return dermis({"--json", "render", "--scene-file", scene, "--frames", "0:0.04:0.02", "-o",
                       *dir_ / (dir + "/f_%04d.png")});
    };
    ClientRun byFile = renderTo(sceneWith("file.scene.json", "sky.hdr"), "file");
    ASSERT_EQ(byFile.code, 0) << byFile;
    EXPECT_GE(byFile.js()["content_sent"].get<int>(), 1) << byFile;

    ClientRun up = dermis({"environment", "upload", *dir_ / "shot/sky.hdr"});
    ASSERT_EQ(up.code, 0) << up;
    ClientRun byId = renderTo(sceneWith("id.scene.json", up.firstLine()), "id");
    ASSERT_EQ(byId.code, 0) << byId;
    ClientRun studio = renderTo(sceneWith("studio.scene.json", "builtin:studio"), "studio");
    ASSERT_EQ(studio.code, 0) << studio;
    for (const char* f : {"f_0000.png", "f_0001.png"}) {
        const std::string a = slurp(*dir_ / ("file/" + std::string(f)));
        ASSERT_GT(a.size(), 100u) << f;
        EXPECT_EQ(a, slurp(*dir_ / ("id/" + std::string(f)))) << f << ": by content and by id differ";
        EXPECT_NE(a, slurp(*dir_ / ("studio/" + std::string(f)))) << f << ": the environment changed nothing";
    }
}

TEST_F(ClientHttpTest, RenderResumeAfterKillWritesExactlyTheRest) {
    const std::string sid = newScene();
    const std::vector<std::string> range = {"--frames", "0:2.5:0.025", "--size", "192x192"}; // 101 frames
    auto renderTo = [&](const std::string& dir, std::vector<std::string> extra) {
        std::vector<std::string> args = {"render", sid, "--out", dir + "/frame_%04d.png"};
        args.insert(args.end(), range.begin(), range.end());
        args.insert(args.end(), extra.begin(), extra.end());
        return args;
    };
    const std::string full = *dir_ / "full", part = *dir_ / "part";
    ClientRun whole = dermis(renderTo(full, {}));
    ASSERT_EQ(whole.code, 0) << whole;
    ASSERT_EQ(filesIn(full).size(), 101u);
    EXPECT_NE(whole.out.find("frame 0 " + full + "/frame_0000.png"), std::string::npos) << "a log line per frame when piped";
    EXPECT_EQ(whole.out.find('\r'), std::string::npos) << "no progress line when stdout is not a terminal";

    // Killed (SIGKILL) once a few frames are there.
    const pid_t pid = ::fork();
    if (pid == 0) {
        const std::string cmd = command(renderTo(part, {})) + " >/dev/null 2>&1";
        ::execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    // Complete frames only: a frame being written is a ".dermis-part" temporary beside them.
    auto completeIn = [&](const std::string& dir) {
        std::size_t n = 0;
        for (const auto& name : filesIn(dir)) n += name.find(".dermis-part") == std::string::npos;
        return n;
    };
    for (int i = 0; i < 10000; ++i) { // up to 20 s on a loaded machine
        if (fs::exists(part) && completeIn(part) >= 5) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    std::map<std::string, ino_t> before;
    for (const auto& name : filesIn(part)) {
        if (name.find(".dermis-part") != std::string::npos) continue;
        struct stat st {};
        ::stat((part + "/" + name).c_str(), &st);
        before[name] = st.st_ino;
        EXPECT_EQ(slurp(part + "/" + name), slurp(full + "/" + name)) << name << ": a file that exists is complete";
    }
    ASSERT_GE(before.size(), 5u);
    ASSERT_LT(before.size(), 101u) << "the client must be killed mid-range";
    std::cout << "killed after " << before.size() << " of 101 frames\n";

    // Resumed with three requests in flight at once (small batches): the same files.
    ClientRun resumed = dermis(renderTo(part, {"--resume", "--parallel", "3", "--batch", "7"}));
    ASSERT_EQ(resumed.code, 0) << resumed;
    const std::size_t rest = 101 - before.size();
    EXPECT_NE(resumed.out.find("rendered " + std::to_string(rest) + " frames of 101 (" + std::to_string(before.size()) + " skipped, 0 failed)"),
              std::string::npos)
        << resumed;
    EXPECT_EQ(filesIn(part), filesIn(full)) << "exactly the frames, no partial files";
    for (const auto& name : filesIn(full)) EXPECT_EQ(slurp(part + "/" + name), slurp(full + "/" + name)) << name;
    for (const auto& [name, inode] : before) {
        struct stat st {};
        ::stat((part + "/" + name).c_str(), &st);
        EXPECT_EQ(st.st_ino, inode) << name << " was rendered again";
    }

    // Ctrl-C: exit 130, the finished frames complete, no partial file.
    const std::string intr = *dir_ / "intr";
    const pid_t child = ::fork();
    if (child == 0) {
        const std::string cmd = command(renderTo(intr, {})) + " >/dev/null 2>&1";
        ::execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    for (int i = 0; i < 10000; ++i) {
        if (fs::exists(intr) && completeIn(intr) >= 3) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ::kill(child, SIGINT);
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 130);
    for (const auto& name : filesIn(intr)) {
        EXPECT_EQ(name.find(".dermis-part"), std::string::npos) << name;
        EXPECT_EQ(slurp(intr + "/" + name), slurp(full + "/" + name)) << name;
    }
    EXPECT_LT(filesIn(intr).size(), 101u);
}

TEST_F(ClientHttpTest, ProgressLineOnlyOnATerminal) {
    const std::string sid = newScene();
    const std::string out = *dir_ / "tty.txt";
    const std::string cmd = command({"render", sid, "--frames", "0:1:0.1", "--size", "64x64", "--out", *dir_ / "tty/f_%04d.jpg"});
    ASSERT_EQ(std::system(("script -qec " + quote(cmd) + " /dev/null >" + quote(out)).c_str()), 0) << slurp(out);
    const std::string text = slurp(out);
    EXPECT_NE(text.find("\r11/11 frames"), std::string::npos) << text;
    EXPECT_NE(text.find("frames/s  ETA"), std::string::npos) << text;
    EXPECT_EQ(text.find("frame 0 "), std::string::npos) << "no log lines on a terminal";
    EXPECT_EQ(filesIn(*dir_ / "tty").size(), 11u);
    // Piped: log lines, no '\r'.
    ClientRun piped = dermis({"render", sid, "--frames", "0:1:0.1", "--size", "64x64", "--out", *dir_ / "piped/f_%04d.jpg"});
    ASSERT_EQ(piped.code, 0) << piped;
    EXPECT_EQ(piped.out.find('\r'), std::string::npos);
    EXPECT_NE(piped.out.find("frame 10 "), std::string::npos) << piped;
}

TEST_F(ClientHttpTest, CheckPassesFailsWhenAPlacementMovesAndUpdates) {
    const std::string cases = kSource + "/tests/check/cases.json", refs = kSource + "/tests/check/refs";
    const std::string junit = *dir_ / "check/ok.xml";
    ClientRun ok = dermis({"check", cases, "--refs", refs, "--junit", junit, "--out", *dir_ / "check/ok"});
    ASSERT_EQ(ok.code, 0) << ok;
    EXPECT_NE(ok.out.find("4 passed, 0 failed"), std::string::npos) << ok;
    EXPECT_NE(slurp(junit).find("tests=\"4\" failures=\"0\""), std::string::npos) << slurp(junit);
    EXPECT_FALSE(fs::exists(*dir_ / "check/ok/diff"));

    // The left elbow's placement moved: the elbow case fails with a diff image and a JUnit failure.
    const std::string work = *dir_ / "check/moved";
    fs::create_directories(work);
    fs::copy(refs, work + "/refs");
    json scene = json::parse(slurp(kSource + "/models/default.scene.json"));
    for (auto& p : scene["placements"])
        if (p["id"] == "elbow_l") p["center"] = {0.2899, 0.62};
    writeText(work + "/moved.scene.json", scene.dump());
    json checks = json::parse(slurp(cases));
    checks["defaults"]["scene"] = "moved.scene.json";
    writeText(work + "/cases.json", checks.dump());
    ClientRun moved = dermis({"check", work + "/cases.json", "--refs", work + "/refs", "--junit", work + "/report.xml", "--out", work + "/out"});
    EXPECT_EQ(moved.code, 4) << moved;
    EXPECT_NE(moved.out.find("FAIL elbow_curl.png"), std::string::npos) << moved;
    EXPECT_NE(moved.out.find("PASS stand.png"), std::string::npos) << moved;
    const std::string report = slurp(work + "/report.xml");
    EXPECT_NE(report.find("failures=\"1\""), std::string::npos) << report;
    EXPECT_NE(report.find("<failure message="), std::string::npos) << report;
    ASSERT_TRUE(fs::exists(work + "/out/diff/elbow_curl.png"));
    EXPECT_EQ(slurp(work + "/out/diff/elbow_curl.png").substr(1, 3), "PNG");
    EXPECT_TRUE(fs::exists(work + "/out/actual/elbow_curl.png"));

    ClientRun update = dermis({"check", work + "/cases.json", "--refs", work + "/refs", "--update", "--out", work + "/out2"});
    EXPECT_EQ(update.code, 0) << update;
    EXPECT_NE(update.out.find("UPDATED elbow_curl.png"), std::string::npos) << update;
    EXPECT_EQ(slurp(work + "/refs/stand.png"), slurp(refs + "/stand.png")) << "matching references stay";
    ClientRun again = dermis({"check", work + "/cases.json", "--refs", work + "/refs", "--out", work + "/out3"});
    EXPECT_EQ(again.code, 0) << again;

    // A missing reference fails (and names --update); a malformed checks file is a usage error.
    fs::remove(work + "/refs/squat_1.png");
    ClientRun noRef = dermis({"check", work + "/cases.json", "--refs", work + "/refs", "--out", work + "/out4"});
    EXPECT_EQ(noRef.code, 4) << noRef;
    EXPECT_NE(noRef.out.find("run with --update"), std::string::npos) << noRef;
    writeText(work + "/bad.json", R"({"cases": [{"time": 0}]})");
    ClientRun badFile = dermis({"check", work + "/bad.json", "--refs", work + "/refs"});
    EXPECT_EQ(badFile.code, 2) << badFile;
    EXPECT_NE(badFile.err.find("(/cases/0/name)"), std::string::npos) << badFile;
}

} // namespace
