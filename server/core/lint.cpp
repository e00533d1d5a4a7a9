// Scene lint. See lint.hpp.
#include "lint.hpp"

#include <cmath>
#include <set>
#include <sstream>

namespace dermis {

std::string_view toString(LintSeverity s) {
    return s == LintSeverity::Info ? "info" : "warning";
}

namespace {

constexpr int kGrid = 12;
constexpr float kFlat = 0.02f;

Footprint footprintOf(const Placement& p) {
    Footprint f;
    f.center = {p.center[0], p.center[1]};
    f.scale = {p.scale[0], p.scale[1]};
    f.rotationDeg = p.rotation;
    return f;
}

/// The UV points of a placement where its pattern is not flat.
std::vector<glm::dvec2> samples(const Placement& p, const PatternImages& images) {
    const Footprint f = footprintOf(p);
    const auto it = images.find(p.pattern);
    const HeightImage* img = it != images.end() && it->second ? &it->second->pixels : nullptr;
    std::vector<glm::dvec2> out;
    for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) {
            const glm::dvec2 s((i + 0.5) / kGrid, (j + 0.5) / kGrid);
            if (img && std::abs(sampleBilinear(*img, s.x, s.y)) <= kFlat) continue;
            out.push_back(f.toUV(s));
        }
    return out;
}

bool covers(const Placement& p, const PatternImages& images, glm::dvec2 uv) {
    const glm::dvec2 s = footprintOf(p).toPattern(uv);
    if (s.x < 0.0 || s.x > 1.0 || s.y < 0.0 || s.y > 1.0) return false;
    const auto it = images.find(p.pattern);
    if (it == images.end() || !it->second) return true;
    return std::abs(sampleBilinear(it->second->pixels, s.x, s.y)) > kFlat;
}

std::string percent(std::size_t part, std::size_t whole) {
    const double ratio = static_cast<double>(part) / static_cast<double>(std::max<std::size_t>(whole, 1));
    return std::to_string(static_cast<int>(std::lround(100.0 * ratio))) + "%";
}

/// Per placement: does any clip sample give t > 0? (true when the model has no clips: nothing
/// to judge by).
std::vector<bool> reachable(const Scene& scene, const Model& model) {
    std::vector<bool> out(scene.placements.size(), model.clips.empty());
    for (const Clip& clip : model.clips) {
        Pose pose;
        pose.animation = clip.name;
        const int steps = static_cast<int>(std::floor(clip.duration * 30.0)) + 1;
        for (int k = 0; k <= steps; ++k) {
            auto local = evaluatePose(model, pose, std::min<double>(clip.duration, k / 30.0));
            if (!local) break;
            for (std::size_t i = 0; i < scene.placements.size(); ++i) {
                if (out[i]) continue;
                const Placement& p = scene.placements[i];
                auto theta = placementAngle(model, *local, p, i);
                if (theta && normalizedT(*theta, p.thetaMin, p.thetaMax) > 0.0) out[i] = true;
            }
        }
    }
    return out;
}

} // namespace

std::vector<LintFinding> lintScene(const Scene& scene, const Model& model, const UvLookup& lookup,
                                   const PatternImages& images) {
    std::vector<LintFinding> out;
    if (!scene.placements.empty() && !model.hasUVs()) {
        out.push_back({"no_uvs", LintSeverity::Warning, -1,
                       "the model has no TEXCOORD_0: no placement can show"});
        return out;
    }
    const std::vector<bool> reach = reachable(scene, model);
    std::vector<std::vector<glm::dvec2>> points(scene.placements.size());
    for (std::size_t i = 0; i < scene.placements.size(); ++i)
        if (scene.placements[i].enabled) points[i] = samples(scene.placements[i], images);

    for (std::size_t i = 0; i < scene.placements.size(); ++i) {
        const Placement& p = scene.placements[i];
        if (!p.enabled) continue;
        const int idx = static_cast<int>(i);
        std::size_t off = 0;
        std::set<int> charts;
        float influence = 0.0f;
        const int joint = findPosable(model, p.joint);
        for (glm::dvec2 uv : points[i]) {
            const auto hit = lookup.find(uv);
            if (!hit) {
                ++off;
                continue;
            }
            charts.insert(hit->chart);
            if (joint >= 0) influence = std::max(influence, lookup.weightOf(*hit, joint));
        }
        const std::size_t n = points[i].size();
        if (off > 0)
            out.push_back({"off_chart", LintSeverity::Warning, idx,
                           percent(off, n) + " of the footprint's pattern lies outside the UV charts: "
                                             "that part of the pattern is lost"});
        if (charts.size() > 1)
            out.push_back({"across_seam", LintSeverity::Warning, idx,
                           "the footprint spans " + std::to_string(charts.size()) +
                               " UV charts: the pattern is cut at the seam"});
        if (!reach[i])
            out.push_back({"unreachable_range", LintSeverity::Warning, idx,
                           "no clip of the model brings joint '" + p.joint + "' into [" +
                               std::to_string(p.thetaMin) + ", " + std::to_string(p.thetaMax) +
                               "] degrees about its axis: the pattern never shows in a clip"});
        if (joint >= 0 && n > off && influence < 0.01f)
            out.push_back({"no_influence", LintSeverity::Warning, idx,
                           "joint '" + p.joint + "' has no skin weight under the footprint: "
                           "the skin it wrinkles does not follow that joint"});
        for (std::size_t j = i + 1; j < scene.placements.size(); ++j) {
            const Placement& q = scene.placements[j];
            if (!q.enabled || q.target != p.target) continue;
            std::size_t shared = 0;
            for (glm::dvec2 uv : points[i])
                if (covers(q, images, uv)) ++shared;
            if (shared > 0)
                out.push_back({"overlap", LintSeverity::Warning, idx,
                               "overlaps placement '" + q.id + "' on the " +
                                   std::string(toString(p.target)) + " map (" +
                                   percent(shared, n) + " of this footprint): heights add up"});
        }
    }
    return out;
}

} // namespace dermis
