// Scene lint. See lint.hpp.
#include "lint.hpp"

#include "lint_surface.hpp"
#include "lint_uv.hpp"
#include "mirror.hpp"
#include "model_derived.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <set>
#include <sstream>

namespace dermis {

std::string_view toString(LintSeverity s) {
    return s == LintSeverity::Info ? "info" : "warning";
}

namespace {

/// The most other placements one overlap finding names (the rest are counted).
constexpr std::size_t kOverlapNames = 5;

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

/// Per placement: does any clip sample give t > 0? (true when the model has no clips, or no clip
/// turns the placement's joint about its axis by more than half a degree from the rest pose:
/// nothing to judge by.)
std::vector<bool> reachable(const Scene& scene, const Model& model) {
    std::vector<bool> out(scene.placements.size(), model.clips.empty());
    std::vector<bool> moved(scene.placements.size(), false);
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
                if (theta && std::abs(*theta) > 0.5) moved[i] = true;
                if (theta && normalizedT(*theta, p.thetaMin, p.thetaMax) > 0.0) out[i] = true;
            }
        }
    }
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = out[i] || !moved[i];
    return out;
}

/// |a − b| in degrees, modulo 180 (so 0 for a footprint turned by a half turn).
double halfTurnDistance(double a, double b) {
    const double d = std::fmod(std::abs(a - b), 180.0);
    return std::min(d, 180.0 - d);
}

std::string num(double x, int decimals = 2) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, x);
    return buf;
}

/// mirror_asymmetric findings: pairs are enabled placements with the same pattern on joints that
/// are mirror twins by name (mirrorJointName), each paired once with the candidate nearest to
/// where it mirrors; the pair is compared with what mirrorPlacement makes of the first. The
/// symmetry plane and rest skin are `derived`'s, built (lazily) only when a pair is found.
void lintMirrorPairs(const Scene& scene, const Model& model, const UvLookup& lookup,
                     const ModelDerived& derived, std::vector<LintFinding>& out) {
    const std::size_t n = scene.placements.size();
    std::vector<bool> paired(n, false);
    const double texW = scene.heightmapSize[0], texH = scene.heightmapSize[1];
    for (std::size_t i = 0; i < n; ++i) {
        const Placement& p = scene.placements[i];
        if (!p.enabled || paired[i]) continue;
        const std::string twinJoint = mirrorJointName(model, p.joint);
        if (twinJoint.empty()) continue;
        std::vector<std::size_t> candidates;
        for (std::size_t j = 0; j < n; ++j) {
            const Placement& q = scene.placements[j];
            if (j != i && !paired[j] && q.enabled && q.pattern == p.pattern && q.joint == twinJoint &&
                q.projection == p.projection)
                candidates.push_back(j);
        }
        if (candidates.empty()) continue;
        auto m = mirrorPlacement(p, model, lookup, derived.symmetryPlane(), derived.restSkin());
        if (!m) continue; // a centre on no chart: off_chart says so
        std::size_t best = candidates.front();
        double bestTexels = std::numeric_limits<double>::infinity();
        const bool surface = p.projection == Projection::Surface;
        // Surface placements (SPEC §8): anchor distance in units of kMirrorAnchorFraction ·
        // max(size), so that 1 is the twin threshold as kMirrorCenterTexels is for centres.
        const double anchorUnit = kMirrorAnchorFraction * std::max(m->size[0], m->size[1]);
        for (std::size_t j : candidates) {
            const Placement& q = scene.placements[j];
            const double d = surface ? kMirrorCenterTexels * surfaceAnchorDistance(q, *m) / anchorUnit
                                     : std::hypot((q.center[0] - m->center[0]) * texW, (q.center[1] - m->center[1]) * texH);
            if (d < bestTexels) {
                bestTexels = d;
                best = j;
            }
        }
        paired[i] = paired[best] = true;
        const Placement& q = scene.placements[best];

        std::vector<std::string> what;
        if (surface) {
            const auto& a = m->anchor.position;
            if (bestTexels > kMirrorCenterTexels)
                what.push_back("its anchor is " + num(surfaceAnchorDistance(q, *m), 4) +
                               " model units from where '" + p.id + "' mirrors to (" + num(a[0], 4) +
                               ", " + num(a[1], 4) + ", " + num(a[2], 4) + ")");
            const double dw = std::abs(q.size[0] / m->size[0] - 1.0), dh = std::abs(q.size[1] / m->size[1] - 1.0);
            if (std::max(dw, dh) > kMirrorScaleFraction || halfTurnDistance(q.rotation, m->rotation) > kMirrorRotationDegrees)
                what.push_back("its size (" + num(q.size[0], 3) + " x " + num(q.size[1], 3) + ", rotation " +
                               num(q.rotation, 1) + ") is not the mirrored one (" + num(m->size[0], 3) + " x " +
                               num(m->size[1], 3) + ", rotation " + num(m->rotation, 1) + ")");
        } else if (bestTexels > kMirrorCenterTexels)
            what.push_back("its centre (" + num(q.center[0], 4) + ", " + num(q.center[1], 4) + ") is " +
                           num(bestTexels, 1) + " texels from where '" + p.id + "' mirrors to (" +
                           num(m->center[0], 4) + ", " + num(m->center[1], 4) + ")");
        // A footprint's mirror image is a reflection, which a placement cannot express: the twin
        // may have the mirrored rotation (what the mirror route makes) or that turned by 180°
        // (the reflection itself for a pattern symmetric about its v axis, like a crease).
        const double turn = halfTurnDistance(q.rotation, m->rotation);
        const double du = std::abs(q.scale[0] / m->scale[0] - 1.0), dv = std::abs(q.scale[1] / m->scale[1] - 1.0);
        if (!surface && (turn > kMirrorRotationDegrees || std::max(du, dv) > kMirrorScaleFraction))
            what.push_back("its footprint (scale " + num(q.scale[0], 3) + " x " + num(q.scale[1], 3) +
                           ", rotation " + num(q.rotation, 1) + ") is not the mirrored one (scale " +
                           num(m->scale[0], 3) + " x " + num(m->scale[1], 3) + ", rotation " +
                           num(m->rotation, 1) + " or " + num(m->rotation + (m->rotation > 0 ? -180.0 : 180.0), 1) + ")");
        // An axis and its opposite with the negated range are the same driver.
        glm::dvec3 am(m->axis[0], m->axis[1], m->axis[2]), aq(q.axis[0], q.axis[1], q.axis[2]);
        am = glm::normalize(am);
        aq = glm::normalize(aq);
        double qMin = q.thetaMin, qMax = q.thetaMax;
        if (glm::dot(am, aq) < 0.0) {
            aq = -aq;
            qMin = -qMin;
            qMax = -qMax;
        }
        const double axisDeg = glm::degrees(std::acos(std::clamp(glm::dot(am, aq), -1.0, 1.0)));
        if (axisDeg > kMirrorAxisDegrees)
            what.push_back("its axis is " + num(axisDeg, 1) + " degrees from the mirrored axis");
        if (std::abs(qMin - m->thetaMin) > kMirrorThetaDegrees || std::abs(qMax - m->thetaMax) > kMirrorThetaDegrees)
            what.push_back("its theta range [" + num(q.thetaMin, 1) + ", " + num(q.thetaMax, 1) + "]" +
                           (qMin != q.thetaMin ? " (about the opposite axis: [" + num(qMin, 1) + ", " + num(qMax, 1) + "])" : "") +
                           " is not the mirrored [" + num(m->thetaMin, 1) + ", " + num(m->thetaMax, 1) + "]");
        if (std::abs(q.h - p.h) > 1e-6 || q.model != p.model || q.target != p.target || q.response != p.response)
            what.push_back("its h, model, target or response differs");
        if (what.empty()) continue;
        std::string message = "mirror pair '" + p.id + "' / '" + q.id + "' is not symmetric: ";
        for (std::size_t k = 0; k < what.size(); ++k) message += (k ? "; " : "") + what[k];
        out.push_back({"mirror_asymmetric", LintSeverity::Warning, static_cast<int>(i), message});
    }
}

} // namespace

namespace {

std::vector<LintFinding> lintSceneWith(const Scene& scene, const Model& model, const UvLookup& lookup,
                                       const PatternImages& images, const ModelDerived& derived) {
    std::vector<LintFinding> out;
    // Surface placements (SPEC §8) need no UVs of the model's own; UV placements do.
    const bool anySurface = std::any_of(scene.placements.begin(), scene.placements.end(),
                                        [](const Placement& p) { return p.projection == Projection::Surface; });
    const bool anyUv = std::any_of(scene.placements.begin(), scene.placements.end(),
                                   [](const Placement& p) { return p.projection == Projection::Uv; });
    const bool uvs = model.hasUVs();
    if (auto f = lintNoUvs(scene, model)) out.push_back(*f);
    if (anyUv && !uvs && !anySurface) return out;
    // The model's UV diagnosis (cached per model by `derived`), only for scenes with UV placements
    // checked in the model's UVs.
    const bool anyInUvs = uvs && std::any_of(scene.placements.begin(), scene.placements.end(), [](const Placement& p) {
        return p.enabled && p.projection == Projection::Uv;
    });
    const UvDiagnosis* diagnosis = anyInUvs ? &derived.uvDiagnosis() : nullptr;
    if (diagnosis)
        if (auto f = lintModelUvOverlap(scene, *diagnosis)) out.push_back(*f);
    const std::vector<bool> reach = reachable(scene, model);
    std::vector<std::vector<glm::dvec2>> points(scene.placements.size());
    // Skin samples: a surface placement's covered vertices; a UV placement's grid samples on the
    // surface (only needed to compare with surface placements).
    std::vector<std::vector<lint_detail::SkinSample>> skins(scene.placements.size());
    for (std::size_t i = 0; i < scene.placements.size(); ++i) {
        const Placement& p = scene.placements[i];
        if (!p.enabled) continue;
        if (p.projection == Projection::Surface) {
            skins[i] = lint_detail::surfaceSamples(p, model, images, kFlat);
        } else if (uvs) {
            points[i] = samples(p, images);
            if (anySurface)
                for (glm::dvec2 uv : points[i]) skins[i].push_back(lint_detail::uvSample(model, lookup, uv));
        }
    }
    // Whether placement q covers sample k of placement i.
    auto coveredBy = [&](const Placement& q, std::size_t i, std::size_t k) {
        if (q.projection == Projection::Surface) return lint_detail::surfaceCovers(q, images, kFlat, skins[i][k]);
        if (scene.placements[i].projection == Projection::Surface)
            return skins[i][k].hasUv && covers(q, images, skins[i][k].uv);
        return covers(q, images, points[i][k]);
    };

    for (std::size_t i = 0; i < scene.placements.size(); ++i) {
        const Placement& p = scene.placements[i];
        if (!p.enabled) continue;
        if (p.projection == Projection::Uv && !uvs) continue; // no_uvs said it
        const int idx = static_cast<int>(i);
        const bool surface = p.projection == Projection::Surface;
        std::size_t off = 0;
        std::set<int> charts;
        float influence = 0.0f;
        const int joint = findPosable(model, p.joint);
        // A joint's angle bends the skin of its own bone and of the bone it turns against (its
        // parent joint's): a crease across the joint, or a muscle on the parent bone bulging as
        // the joint bends (the biceps on upper_arm, driven by the elbow, forearm).
        const int parent = joint >= 0 ? model.parentJoint(joint) : -1;
        auto weightAt = [&](const UvLookup::Hit& hit) {
            float w = 0.0f;
            if (joint >= 0) w = std::max(w, lookup.weightOf(hit, joint));
            if (parent >= 0) w = std::max(w, lookup.weightOf(hit, parent));
            return w;
        };
        for (glm::dvec2 uv : points[i]) {
            // Where the atlas overlaps itself (palette swatches, mirrored islands) several
            // triangles hold the point: the placement's is the one its joints weigh most (the
            // first found was another region's, and no_influence was wrong there).
            const auto hits = lookup.findAll(uv);
            if (hits.empty()) {
                ++off;
                continue;
            }
            std::size_t best = 0;
            float bestWeight = -1.0f;
            for (std::size_t k = 0; k < hits.size(); ++k)
                if (const float w = weightAt(hits[k]); w > bestWeight) {
                    bestWeight = w;
                    best = k;
                }
            charts.insert(hits[best].chart);
            influence = std::max(influence, bestWeight);
            if (influence < 0.01f && diagnosis && regionDrivenAt(*diagnosis, uv, joint, parent)) influence = 1.0f;
        }
        std::size_t n = points[i].size();
        if (surface) { // seamless by construction: no off_chart / across_seam; off_surface instead
            std::vector<lint_detail::SkinSample> under = skins[i];
            if (under.empty()) {
                lint_detail::SkinSample nearest;
                const auto d = lint_detail::anchorToSurface(p, model, &nearest);
                if (!d || *d > p.depthOrDefault())
                    out.push_back({"off_surface", LintSeverity::Warning, idx,
                                   "the anchor lies " + (d ? num(*d, 4) : std::string("far")) +
                                       " model units from the rest mesh, beyond the decal's depth (" +
                                       num(p.depthOrDefault(), 4) + "): the pattern reaches no skin"});
                else
                    under.push_back(nearest); // a decal smaller than the mesh's vertex spacing
            }
            for (const lint_detail::SkinSample& sk : under) {
                influence = std::max(influence, lint_detail::vertexWeight(model, sk, joint));
                influence = std::max(influence, lint_detail::vertexWeight(model, sk, parent));
            }
            n = skins[i].size();
            if (!under.empty() && joint >= 0 && influence < 0.01f)
                out.push_back({"no_influence", LintSeverity::Warning, idx,
                               "neither joint '" + p.joint + "' nor its parent has skin weight under "
                               "the decal: the skin there does not bend with that joint"});
        }
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
        if (!surface && joint >= 0 && n > off && influence < 0.01f)
            out.push_back({"no_influence", LintSeverity::Warning, idx,
                           "neither joint '" + p.joint + "' nor its parent has skin weight under "
                           "the footprint: the skin there does not bend with that joint"});
        // Each pair once (on the earlier placement), all of a placement's pairs in one finding
        // naming at most kOverlapNames of them: the answer grows with the placements, not with
        // their square (issue #27: 82 MB at 1,000 placements before).
        std::size_t overlaps = 0;
        std::string named;
        for (std::size_t j = i + 1; j < scene.placements.size(); ++j) {
            const Placement& q = scene.placements[j];
            if (!q.enabled || q.target != p.target) continue;
            if (q.projection == Projection::Uv && !uvs) continue;
            std::size_t shared = 0;
            const bool viaSurface = surface || q.projection == Projection::Surface;
            const std::size_t count = viaSurface ? skins[i].size() : points[i].size();
            for (std::size_t k = 0; k < count; ++k)
                if (coveredBy(q, i, k)) ++shared;
            if (shared == 0) continue;
            if (++overlaps <= kOverlapNames)
                named += std::string(named.empty() ? "" : ", ") + "'" + q.id + "' (" + percent(shared, n) + ")";
        }
        if (overlaps == 1)
            out.push_back({"overlap", LintSeverity::Warning, idx,
                           "overlaps placement " + named + " of this footprint on the " +
                               std::string(toString(p.target)) + " map: heights add up"});
        else if (overlaps > 1)
            out.push_back({"overlap", LintSeverity::Warning, idx,
                           "overlaps " + std::to_string(overlaps) + " placements on the " +
                               std::string(toString(p.target)) + " map (share of this footprint): " + named +
                               (overlaps > kOverlapNames ? " and " + std::to_string(overlaps - kOverlapNames) + " more" : "") +
                               ": heights add up"});
        if (diagnosis && !surface)
            if (auto f = lintPlacementUvOverlap(scene, i, points[i], joint, parent, *diagnosis)) out.push_back(*f);
    }
    lintMirrorPairs(scene, model, lookup, derived, out);
    std::stable_sort(out.begin(), out.end(),
                     [](const LintFinding& a, const LintFinding& b) { return a.placement < b.placement; });
    return out;
}

} // namespace

std::vector<LintFinding> lintScene(const Scene& scene, const Model& model, const UvLookup& lookup,
                                   const PatternImages& images) {
    // Derived data for this call only; the model is the caller's (not owned: aliasing pointer).
    const ModelDerived derived(std::shared_ptr<const Model>(std::shared_ptr<const Model>(), &model));
    return lintSceneWith(scene, model, lookup, images, derived);
}

std::vector<LintFinding> lintScene(const Scene& scene, const ModelDerived& derived,
                                   const PatternImages& images) {
    return lintSceneWith(scene, derived.model(), derived.uvLookup(), images, derived);
}

} // namespace dermis
