// Lint findings about the model's own UVs. See lint_uv.hpp.
#include "lint_uv.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

namespace dermis {

namespace {

/// The most placements no_uvs names, and regions uv_overlap names (the rest are counted).
constexpr std::size_t kNames = 5;
constexpr std::size_t kRegionNames = 4;

std::string percentOf(std::size_t part, std::size_t whole) {
    const double ratio = static_cast<double>(part) / static_cast<double>(std::max<std::size_t>(whole, 1));
    return std::to_string(static_cast<int>(std::lround(100.0 * ratio))) + "%";
}

std::string percentFraction(double f) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f%%", 100.0 * f);
    return buf;
}

/// "a, b and c" of `names`, at most `most` of them, then "and N more".
std::string listed(const std::vector<std::string>& names, std::size_t most) {
    std::string out;
    const std::size_t shown = std::min(names.size(), most);
    for (std::size_t k = 0; k < shown; ++k) {
        if (k > 0) out += (k + 1 == shown && names.size() <= most) ? " and " : ", ";
        out += names[k];
    }
    if (names.size() > most) out += " and " + std::to_string(names.size() - most) + " more";
    return out;
}

bool isUvPlacement(const Placement& p) { return p.enabled && p.projection == Projection::Uv; }

} // namespace

std::optional<LintFinding> lintNoUvs(const Scene& scene, const Model& model) {
    if (model.hasUVs()) return std::nullopt;
    std::vector<std::string> ids;
    for (const Placement& p : scene.placements)
        if (isUvPlacement(p)) ids.push_back("'" + p.id + "'");
    if (ids.empty()) return std::nullopt;
    return LintFinding{"no_uvs", LintSeverity::Warning, -1,
                       "the model has no TEXCOORD_0: " +
                           std::string(ids.size() == 1 ? "placement " : "placements ") + listed(ids, kNames) +
                           (ids.size() == 1 ? " uses" : " use") +
                           " projection \"uv\", which needs the model's UVs; projection \"surface\" "
                           "(an anchor, size and depth on the body) works on any model"};
}

std::optional<LintFinding> lintModelUvOverlap(const Scene& scene, const UvDiagnosis& diagnosis) {
    if (scene.uvLayout != UvLayoutMode::Auto || !diagnosis.hasUVs || diagnosis.usable()) return std::nullopt;
    if (std::none_of(scene.placements.begin(), scene.placements.end(), isUvPlacement)) return std::nullopt;
    return LintFinding{"uv_overlap", LintSeverity::Info, -1,
                       "the model's UVs overlap: " + percentFraction(diagnosis.overlapFraction) +
                           " of the used texels are shared (" + diagnosis.describeSharing() +
                           "); uv_layout \"auto\" puts the height maps in a generated layout, and the "
                           "UV placements' centres are in that layout, not in the model's UVs"};
}

bool regionDrivenAt(const UvDiagnosis& diagnosis, glm::dvec2 uv, int joint, int parent) {
    if (uv.x < 0.0 || uv.y < 0.0 || uv.x > 1.0 || uv.y > 1.0) return false;
    for (int r : diagnosis.regionsAt(uv)) {
        const int node = diagnosis.regions[static_cast<std::size_t>(r)].jointNode;
        if (node >= 0 && (node == joint || node == parent)) return true;
    }
    return false;
}

std::optional<LintFinding> lintPlacementUvOverlap(const Scene& scene, std::size_t index,
                                                  const std::vector<glm::dvec2>& samples, int joint,
                                                  int parent, const UvDiagnosis& diagnosis) {
    if (diagnosis.overlapTexels == 0 || !modelUvsHoldHeightmaps(scene.uvLayout, diagnosis)) return std::nullopt;
    std::map<int, std::size_t> under, shared; // region → samples (all; overlapped)
    std::size_t overlapped = 0;
    for (glm::dvec2 uv : samples) {
        if (uv.x < 0.0 || uv.y < 0.0 || uv.x > 1.0 || uv.y > 1.0) continue; // not painted
        bool ov = false;
        const auto regions = diagnosis.regionsAt(uv, &ov);
        for (int r : regions) ++under[r];
        if (!ov) continue;
        ++overlapped;
        for (int r : regions) ++shared[r];
    }
    if (overlapped == 0) return std::nullopt;
    // The placement's own regions: driven by its joint or the joint's parent, else the region
    // under most of the footprint.
    std::vector<int> own;
    for (const auto& [r, count] : under) {
        const int node = diagnosis.regions[static_cast<std::size_t>(r)].jointNode;
        if (node >= 0 && (node == joint || node == parent)) own.push_back(r);
    }
    if (own.empty()) {
        std::size_t most = 0;
        for (const auto& [r, count] : under)
            if (count > most) {
                most = count;
                own.assign(1, r);
            }
    }
    std::vector<std::pair<int, std::size_t>> others;
    for (const auto& [r, count] : shared)
        if (std::find(own.begin(), own.end(), r) == own.end()) others.emplace_back(r, count);
    std::stable_sort(others.begin(), others.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    auto nameOf = [&](int r) { return diagnosis.regions[static_cast<std::size_t>(r)].name; };
    std::vector<std::string> ownNames, otherNames;
    for (int r : own) ownNames.push_back(nameOf(r));
    for (const auto& [r, count] : others) otherNames.push_back(nameOf(r));
    const std::string share = percentOf(overlapped, samples.size()) + " of the footprint";
    const std::string fix = "uv_layout \"generated\" gives every triangle texels of its own";
    std::string message;
    if (others.empty())
        message = share + " lies on texels where " + listed(ownNames, kRegionNames) +
                  " folds onto itself (two of its triangles hold one texel): the pattern also shows "
                  "on its other half; " + fix;
    else
        message = "the pattern also shows on " + listed(otherNames, kRegionNames) + ": " + share +
                  " lies on texels that their triangles share with " + listed(ownNames, kRegionNames) +
                  " (the model's UVs overlap there); " + fix;
    return LintFinding{"uv_overlap", LintSeverity::Warning, static_cast<int>(index), message};
}

} // namespace dermis
