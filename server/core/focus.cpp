#include "focus.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

namespace {

/// Whether uv lies inside the footprint (SPEC §2 mapping to pattern coordinates).
bool inside(glm::dvec2 uv, glm::dvec2 center, glm::dvec2 scale, double c, double s) {
    const glm::dvec2 d = uv - center;
    const glm::dvec2 q(c * d.x + s * d.y, -s * d.x + c * d.y); // R(−rotation)·d
    return std::abs(q.x) <= 0.5 * scale.x && std::abs(q.y) <= 0.5 * scale.y;
}

} // namespace

std::optional<FootprintRegion> footprintRegion(const Model& model, const UvLookup& lookup,
                                               const std::vector<SkinnedPart>& posed,
                                               glm::dvec2 center, glm::dvec2 scale,
                                               double rotationDegrees) {
    const double a = rotationDegrees * 3.14159265358979323846 / 180.0;
    const double c = std::cos(a), s = std::sin(a);
    FootprintRegion region;
    double estimate = 0.0;
    int centrePart = -1;
    if (const auto h = lookup.find(center)) {
        const MeshPart& part = model.parts[static_cast<std::size_t>(h->part)];
        const std::size_t t = 3 * static_cast<std::size_t>(h->triangle);
        const std::vector<glm::vec3>& pos = posed.at(static_cast<std::size_t>(h->part)).positions;
        const std::uint32_t i[3] = {part.indices[t], part.indices[t + 1], part.indices[t + 2]};
        region.target = h->bary.x * pos[i[0]] + h->bary.y * pos[i[1]] + h->bary.z * pos[i[2]];
        region.hit = true;
        centrePart = h->part;
        // World units per UV unit across the triangle: the ratio of its longest edges.
        double world = 0.0, uv = 0.0;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t p = i[k], q = i[(k + 1) % 3];
            world = std::max(world, static_cast<double>(glm::length(pos[p] - pos[q])));
            uv = std::max(uv, static_cast<double>(glm::length(part.uvs[p] - part.uvs[q])));
        }
        if (uv > 0.0) estimate = 0.5 * glm::length(scale) * world / uv;
    }
    glm::dvec3 sum(0.0);
    std::size_t count = 0;
    double far = 0.0;
    for (std::size_t pi = 0; pi < model.parts.size() && pi < posed.size(); ++pi) {
        const MeshPart& part = model.parts[pi];
        if (part.uvs.empty() || (centrePart >= 0 && static_cast<int>(pi) != centrePart)) continue;
        for (std::size_t v = 0; v < part.uvs.size() && v < posed[pi].positions.size(); ++v) {
            if (!inside(glm::dvec2(part.uvs[v]), center, scale, c, s)) continue;
            const glm::vec3 p = posed[pi].positions[v];
            sum += glm::dvec3(p);
            ++count;
            if (region.hit) far = std::max(far, static_cast<double>(glm::length(p - region.target)));
        }
    }
    if (!region.hit) {
        if (count == 0) return std::nullopt;
        region.target = glm::vec3(sum / static_cast<double>(count));
        for (std::size_t pi = 0; pi < model.parts.size() && pi < posed.size(); ++pi)
            for (std::size_t v = 0; v < model.parts[pi].uvs.size() && v < posed[pi].positions.size(); ++v)
                if (inside(glm::dvec2(model.parts[pi].uvs[v]), center, scale, c, s))
                    far = std::max(far, static_cast<double>(glm::length(posed[pi].positions[v] - region.target)));
        region.radius = far;
    } else {
        region.radius = estimate > 0.0 ? std::clamp(far, 0.5 * estimate, 3.0 * estimate) : far;
    }
    if (!(region.radius > 0.0) || !std::isfinite(region.radius)) region.radius = 1e-3;
    return region;
}

double focusDistance(double radius, double margin) {
    const double halfFov = 15.0 * 3.14159265358979323846 / 180.0;
    return std::max(radius * margin / std::sin(halfFov), 1e-3);
}

} // namespace dermis
