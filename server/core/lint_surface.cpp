// Lint's view of surface placements. See lint_surface.hpp.
#include "lint_surface.hpp"

#include "bake.hpp"
#include "heightmap.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dermis::lint_detail {

namespace {

/// The decal frame of `p` (bake.hpp surfaceFrameOf), or nothing for a degenerate anchor.
std::optional<SurfaceFrame> frameOf(const Placement& p) {
    BakePlacement b;
    if (!surfaceFrameOf(p, b)) return std::nullopt;
    return SurfaceFrame(b);
}

const HeightImage* imageOf(const Placement& p, const PatternImages& images) {
    const auto it = images.find(p.pattern);
    return it != images.end() && it->second ? &it->second->pixels : nullptr;
}

glm::dvec3 normalOf(const MeshPart& part, std::uint32_t v) {
    if (part.normals.size() == part.positions.size()) return glm::dvec3(part.normals[v]);
    return glm::dvec3(0, 0, 1);
}

} // namespace

std::vector<SkinSample> surfaceSamples(const Placement& p, const Model& model,
                                       const PatternImages& images, float flat,
                                       std::size_t maxSamples) {
    std::vector<SkinSample> all;
    const auto f = frameOf(p);
    if (!f) return all;
    const HeightImage* img = imageOf(p, images);
    for (std::size_t pi = 0; pi < model.parts.size(); ++pi) {
        const MeshPart& part = model.parts[pi];
        const bool uvs = part.uvs.size() >= part.positions.size();
        for (std::uint32_t v = 0; v < part.positions.size(); ++v) {
            SkinSample s;
            s.position = glm::dvec3(part.positions[v]);
            s.normal = normalOf(part, v);
            glm::dvec2 st;
            if (!f->toPattern(s.position, s.normal, st)) continue;
            if (img && std::abs(sampleBilinear(*img, st.x, st.y)) <= flat) continue;
            s.hasSurface = true;
            s.part = static_cast<int>(pi);
            s.vertex = v;
            if (uvs) {
                s.uv = glm::dvec2(part.uvs[v]);
                s.hasUv = true;
            }
            all.push_back(s);
        }
    }
    if (all.size() <= maxSamples) return all;
    std::vector<SkinSample> out;
    out.reserve(maxSamples);
    for (std::size_t k = 0; k < maxSamples; ++k) out.push_back(all[k * all.size() / maxSamples]);
    return out;
}

SkinSample uvSample(const Model& model, const UvLookup& lookup, glm::dvec2 uv) {
    SkinSample s;
    s.uv = uv;
    s.hasUv = true;
    const auto hit = lookup.find(uv);
    if (!hit) return s;
    const MeshPart& part = model.parts[static_cast<std::size_t>(hit->part)];
    glm::dvec3 n(0.0);
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = part.indices[3 * static_cast<std::size_t>(hit->triangle) + static_cast<std::size_t>(k)];
        if (v < part.positions.size()) n += static_cast<double>(hit->bary[k]) * normalOf(part, v);
    }
    s.position = glm::dvec3(lookup.position(*hit));
    s.normal = glm::length(n) > 0.0 ? glm::normalize(n) : glm::dvec3(0, 0, 1);
    s.hasSurface = true;
    s.part = hit->part;
    return s;
}

bool surfaceCovers(const Placement& q, const PatternImages& images, float flat, const SkinSample& s) {
    if (!s.hasSurface) return false;
    const auto f = frameOf(q);
    glm::dvec2 st;
    if (!f || !f->toPattern(s.position, s.normal, st)) return false;
    const HeightImage* img = imageOf(q, images);
    return !img || std::abs(sampleBilinear(*img, st.x, st.y)) > flat;
}

float vertexWeight(const Model& model, const SkinSample& s, int node) {
    if (s.part < 0 || node < 0) return 0.0f;
    const MeshPart& part = model.parts[static_cast<std::size_t>(s.part)];
    const std::uint32_t v = s.vertex;
    if (v >= part.joints.size() || v >= part.weights.size())
        return !part.influences.empty() && part.influences[0].node == node ? 1.0f : 0.0f;
    float w = 0.0f;
    for (int c = 0; c < 4; ++c)
        if (part.joints[v][c] < part.influences.size() && part.influences[part.joints[v][c]].node == node)
            w += part.weights[v][c];
    return w;
}

std::optional<double> anchorToSurface(const Placement& p, const Model& model, SkinSample* nearest) {
    const glm::dvec3 c(p.anchor.position[0], p.anchor.position[1], p.anchor.position[2]);
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t pi = 0; pi < model.parts.size(); ++pi) {
        const MeshPart& part = model.parts[pi];
        for (std::uint32_t v = 0; v < part.positions.size(); ++v) {
            const double d = glm::length(glm::dvec3(part.positions[v]) - c);
            if (d < best) {
                best = d;
                if (nearest) {
                    nearest->position = glm::dvec3(part.positions[v]);
                    nearest->normal = normalOf(part, v);
                    nearest->hasSurface = true;
                    nearest->part = static_cast<int>(pi);
                    nearest->vertex = v;
                }
            }
        }
    }
    if (!std::isfinite(best)) return std::nullopt;
    return best;
}

} // namespace dermis::lint_detail
