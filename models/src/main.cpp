// dermis-charactergen — writes the built-in default character (SPEC §4 "Default"):
//   dermis-charactergen --out DIR [--preview PREFIX] [--quiet]
// DIR receives default.glb (binary glTF 2.0: one skinned mesh of 4,300 triangles, 51 joints,
// a UV atlas and 7 clips) and default.charts.json (the UV charts and pattern landmarks).
// Output is bit-identical from run to run. --preview also writes check images (CPU raster):
// PREFIX-poses.png (rest pose and clip poses), PREFIX-bends.png (close-ups of 90°+ bends),
// PREFIX-charts.png (charts on the body), PREFIX-uv.png (the UV layout) and PREFIX-weights.png
// (weights of a few joints).
// Exit status: 0 on success, 1 when a check fails or a file cannot be written, 2 on bad usage.
#include "character.hpp"
#include "gltf_out.hpp"
#include "preview.hpp"

#include "core/rig.hpp"
#include "io/atomic_file.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <system_error>

namespace {

using namespace dermis::chargen;
namespace fs = std::filesystem;

/// Writes `bytes` to `path` whole (atomic_file.hpp: never a partial file).
bool writeFileAtomic(const fs::path& path, const std::string& bytes) {
    return dermis::writeFileAtomically(path.string(),
                                       std::vector<std::uint8_t>(bytes.begin(), bytes.end()))
        .ok();
}

glm::vec3 chartColor(int c) {
    static const glm::vec3 palette[] = {
        {0.90f, 0.35f, 0.35f}, {0.35f, 0.75f, 0.40f}, {0.35f, 0.50f, 0.90f}, {0.95f, 0.75f, 0.30f},
        {0.75f, 0.40f, 0.85f}, {0.30f, 0.80f, 0.80f}, {0.95f, 0.55f, 0.20f}, {0.60f, 0.85f, 0.30f},
        {0.90f, 0.45f, 0.70f}, {0.45f, 0.35f, 0.75f}, {0.80f, 0.80f, 0.80f}, {0.55f, 0.70f, 0.95f},
        {0.70f, 0.55f, 0.35f}, {0.95f, 0.90f, 0.45f}, {0.40f, 0.60f, 0.50f}, {0.85f, 0.25f, 0.55f}};
    return palette[static_cast<std::size_t>(c) % (sizeof(palette) / sizeof(palette[0]))];
}

void posed(const dermis::Model& m, int clip, float time, std::vector<glm::vec3>& p,
           std::vector<glm::vec3>& n) {
    const dermis::LocalPose pose =
        clip >= 0 ? dermis::sampleClip(m, clip, time) : dermis::restPose(m);
    const auto skinned = dermis::skin(m, dermis::worldMatrices(m, pose));
    p = skinned[0].positions;
    n = skinned[0].normals;
}

std::vector<glm::uvec3> triangles(const dermis::Model& m) {
    std::vector<glm::uvec3> t;
    const auto& idx = m.parts[0].indices;
    for (std::size_t i = 0; i + 2 < idx.size(); i += 3)
        t.emplace_back(idx[i], idx[i + 1], idx[i + 2]);
    return t;
}

bool writePreviews(const Character& ch, const std::string& prefix) {
    const dermis::Model& m = ch.model;
    const auto tris = triangles(m);
    std::vector<glm::vec3> p, n;
    bool ok = true;

    // Poses: rest (front, side, back) and one frame of every clip.
    struct Shot {
        const char* clip;
        float time;
        float yaw;
    };
    const Shot shots[] = {{"", 0, 0},
                          {"", 0, 90},
                          {"", 0, 180},
                          {"", 0, 30},
                          {"elbow_curl", 1.0f, 30},
                          {"squat", 1.25f, 60},
                          {"torso_bend", 0.75f, 90},
                          {"torso_bend", 2.25f, 90},
                          {"torso_twist", 0.5f, 20},
                          {"neck_turn", 0.375f, 20},
                          {"neck_turn", 1.875f, 70},
                          {"arm_raise", 0.75f, 0},
                          {"arm_raise", 2.0f, 60},
                          {"walk", 0.0f, 70},
                          {"walk", 0.3f, 70},
                          {"elbow_curl", 1.0f, 100}};
    const int cols = 4, w = 450, h = 560;
    RgbImage poses(cols * w, 4 * h, glm::vec3(0.18f));
    for (int i = 0; i < 16; ++i) {
        const int clip = shots[i].clip[0] ? m.findClip(shots[i].clip) : -1;
        posed(m, clip, shots[i].time, p, n);
        ViewSpec v;
        v.x0 = (i % cols) * w;
        v.y0 = (i / cols) * h;
        v.width = w;
        v.height = h;
        v.yawDeg = shots[i].yaw;
        v.pitchDeg = 8;
        v.centre = glm::vec3(0, 0.9f, 0);
        v.pixelsPerMetre = 290;
        renderMesh(poses, v, p, n, tris, {});
    }
    ok = writePng(prefix + "-poses.png", poses) && ok;

    // Close-ups of bends: 90° elbow, 90° knee, 90° hip, arm raised, torso twist, wrist.
    struct Bend {
        const char* joint;
        glm::vec3 deg;
        glm::vec3 centre;
        float yaw, pitch, ppm;
    };
    const Bend bends[] = {{"forearm.l", {90, 0, 0}, {0.40f, 1.22f, 0.08f}, 90, 0, 1300},
                          {"forearm.l", {135, 0, 0}, {0.40f, 1.22f, 0.06f}, 90, 0, 1300},
                          {"shin.l", {90, 0, 0}, {0.1f, 0.47f, -0.12f}, 90, 0, 1000},
                          {"thigh.l", {90, 0, 0}, {0.1f, 0.82f, 0.16f}, 90, 0, 800},
                          {"upper_arm.l", {0, 0, 90}, {0.25f, 1.45f, 0}, 0, 0, 900},
                          {"spine_02", {0, 40, 0}, {0, 1.15f, 0}, 0, 60, 650},
                          {"hand.l", {60, 0, 0}, {0.62f, 1.04f, 0.03f}, 0, 0, 1600},
                          {"neck_01", {40, 0, 0}, {0, 1.53f, 0.04f}, 90, 0, 1100},
                          // Rest-pose details: head front and side, hand, foot.
                          {"root", {0, 0, 0}, {0, 1.64f, 0}, 0, 0, 1800},
                          {"root", {0, 0, 0}, {0, 1.64f, 0}, 90, 0, 1800},
                          {"root", {0, 0, 0}, {0.66f, 1.0f, 0}, 0, 0, 1800},
                          {"root", {0, 0, 0}, {0.1f, 0.06f, 0.06f}, 60, 20, 1500}};
    RgbImage close(4 * 450, 3 * 450, glm::vec3(0.18f));
    for (int i = 0; i < 12; ++i) {
        dermis::LocalPose pose = dermis::restPose(m);
        const int j = m.findJoint(bends[i].joint);
        pose.rotation[static_cast<std::size_t>(j)] =
            dermis::axisAnglesRotation(pose.rotation[static_cast<std::size_t>(j)], bends[i].deg.x,
                                       bends[i].deg.y, bends[i].deg.z);
        const auto sk = dermis::skin(m, dermis::worldMatrices(m, pose));
        ViewSpec v;
        v.x0 = (i % 4) * 450;
        v.y0 = (i / 4) * 450;
        v.width = v.height = 450;
        v.yawDeg = bends[i].yaw;
        v.pitchDeg = bends[i].pitch;
        v.centre = bends[i].centre;
        v.pixelsPerMetre = bends[i].ppm;
        v.wireframe = true;
        renderMesh(close, v, sk[0].positions, sk[0].normals, tris, {});
    }
    ok = writePng(prefix + "-bends.png", close) && ok;

    // Charts on the body and the UV layout.
    posed(m, -1, 0, p, n);
    std::vector<glm::vec3> vc(p.size(), glm::vec3(0.7f));
    std::vector<glm::vec3> tc(tris.size());
    for (std::size_t t = 0; t < tris.size(); ++t) {
        tc[t] = chartColor(ch.atlas.triChart[t]);
        for (int c = 0; c < 3; ++c)
            vc[tris[t][c]] = tc[t];
    }
    RgbImage charts(4 * 500, 1000, glm::vec3(0.18f));
    const float yaws[4] = {0, 90, 180, 270};
    for (int i = 0; i < 4; ++i) {
        ViewSpec v;
        v.x0 = i * 500;
        v.width = 500;
        v.height = 1000;
        v.yawDeg = yaws[i];
        v.centre = glm::vec3(0, 0.88f, 0);
        v.pixelsPerMetre = 520;
        v.wireframe = true;
        renderMesh(charts, v, p, n, tris, vc);
    }
    ok = writePng(prefix + "-charts.png", charts) && ok;
    RgbImage uv(1024, 1024, glm::vec3(0));
    renderUv(uv, 0, 0, 1024, m.parts[0].uvs, tris, tc);
    ok = writePng(prefix + "-uv.png", uv) && ok;

    // Weights of a few joints (red = 1), rest pose and a bent pose.
    const char* joints[] = {"forearm.l", "upper_arm_twist.l", "shin.l", "thigh.l", "spine_02",
                            "head",      "clavicle.l",        "pelvis"};
    RgbImage wimg(4 * 450, 2 * 560, glm::vec3(0.18f));
    for (int i = 0; i < 8; ++i) {
        const int j = m.findJoint(joints[i]);
        std::vector<glm::vec3> col(p.size());
        for (std::size_t v = 0; v < p.size(); ++v) {
            float wv = 0;
            for (int k = 0; k < 4; ++k)
                if (m.parts[0].joints[v][k] == j) wv += m.parts[0].weights[v][k];
            col[v] = glm::mix(glm::vec3(0.25f, 0.3f, 0.8f), glm::vec3(1.0f, 0.25f, 0.15f), wv);
        }
        ViewSpec v;
        v.x0 = (i % 4) * 450;
        v.y0 = (i / 4) * 560;
        v.width = 450;
        v.height = 560;
        v.yawDeg = i == 2 ? 90 : 20;
        v.centre = glm::vec3(0, 0.9f, 0);
        v.pixelsPerMetre = 290;
        renderMesh(wimg, v, p, n, tris, col);
    }
    ok = writePng(prefix + "-weights.png", wimg) && ok;
    return ok;
}

} // namespace

int main(int argc, char** argv) {
    std::string outDir, preview;
    bool quiet = false;
    CLI::App app{"Writes the built-in default character: default.glb and default.charts.json"};
    app.add_option("--out", outDir, "Output folder (created if needed)")->required();
    app.add_option("--preview", preview,
                   "Also write PREFIX-poses.png, PREFIX-bends.png, PREFIX-charts.png, "
                   "PREFIX-uv.png and PREFIX-weights.png (CPU-rendered check images)");
    app.add_flag("--quiet", quiet, "No progress on stderr");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }

    Character ch;
    std::string error;
    if (!buildCharacter(ch, error, quiet ? nullptr : stderr)) {
        std::cerr << "dermis-charactergen: " << error << "\n";
        return 1;
    }
    const std::vector<std::uint8_t> glb = encodeGlb(ch.model);
    if (glb.empty()) {
        std::cerr << "dermis-charactergen: glTF encoding failed\n";
        return 1;
    }
    std::error_code ec;
    fs::create_directories(outDir, ec);
    const fs::path dir(outDir);
    if (!writeFileAtomic(dir / "default.glb", std::string(glb.begin(), glb.end())) ||
        !writeFileAtomic(dir / "default.charts.json", chartsJson(ch, "default.glb"))) {
        std::cerr << "dermis-charactergen: cannot write into " << outDir << "\n";
        return 1;
    }
    if (!quiet)
        std::cerr << "wrote " << (dir / "default.glb").string() << " (" << glb.size()
                  << " bytes) and " << (dir / "default.charts.json").string() << "\n";
    if (!preview.empty() && !writePreviews(ch, preview)) return 1;
    return 0;
}
