// Dermis core — surface placements (SPEC §8): a decal anchored on the rest surface, evaluated at
// a texel's rest-surface point (heightmap.hpp SurfaceFrame, surfacePlacementHeight) and the
// culling of the texels it can reach (surfacePlacementTexels), shared by the CPU bake, the probe
// and the GPU height pass (which evaluates the same formula per texel in shaders/heightpass.frag).
#include "heightmap.hpp"
#include "texture_layout.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

SurfaceFrame::SurfaceFrame(const BakePlacement& p)
    : c(p.anchorPosition), n(p.anchorNormal), t(p.anchorTangent), b(glm::cross(p.anchorNormal, p.anchorTangent)),
      invW(1.0 / p.size.x), invH(1.0 / p.size.y), depth(p.depth) {}

bool SurfaceFrame::toPattern(glm::dvec3 position, glm::dvec3 normal, glm::dvec2& s) const {
    if (!(glm::dot(normal, n) > 0.0)) return false; // back-facing (or no surface there)
    const glm::dvec3 d = position - c;
    if (std::abs(glm::dot(d, n)) > depth) return false;
    s = glm::dvec2(glm::dot(d, t) * invW + 0.5, glm::dot(d, b) * invH + 0.5);
    return s.x >= 0.0 && s.x <= 1.0 && s.y >= 0.0 && s.y <= 1.0;
}

double SurfaceFrame::reach() const {
    const double hw = 0.5 / invW, hh = 0.5 / invH;
    return std::sqrt(hw * hw + hh * hh + depth * depth) * (1.0 + 1e-6) + 1e-9;
}

float surfacePlacementHeight(const BakePlacement& p, glm::dvec3 position, glm::dvec3 normal) {
    glm::dvec2 s;
    if (!p.pattern || !SurfaceFrame(p).toPattern(position, normal, s)) return 0.0f;
    const float L = sampleBilinear(*p.pattern, s.x, s.y);
    return applyDeform(p.model, L, static_cast<float>(p.h), p.t,
                       deformConstant(p.model, p.response, p.t));
}

bool surfaceTileNear(const SurfaceFrame& frame, const RestSurfaceMap& rest, std::size_t tile) {
    const glm::dvec3 lo(rest.tileMin[tile]), hi(rest.tileMax[tile]);
    if (!(lo.x <= hi.x)) return false; // no covered texel in the tile
    const glm::dvec3 nearest = glm::clamp(frame.c, lo, hi);
    const glm::dvec3 d = frame.c - nearest;
    const double r = frame.reach();
    return glm::dot(d, d) <= r * r;
}

TexelRect surfacePlacementTexels(const BakePlacement& p, const RestSurfaceMap& rest) {
    TexelRect r{rest.width, rest.height, 0, 0};
    const std::size_t tiles = static_cast<std::size_t>(rest.tilesX) * rest.tilesY;
    if (rest.tileMin.size() != tiles || rest.tileMax.size() != tiles) { // no bounds: everything
        return TexelRect{0, 0, rest.width, rest.height};
    }
    const SurfaceFrame frame(p);
    constexpr int T = RestSurfaceMap::kTile;
    for (int ty = 0; ty < rest.tilesY; ++ty)
        for (int tx = 0; tx < rest.tilesX; ++tx) {
            if (!surfaceTileNear(frame, rest, static_cast<std::size_t>(ty) * rest.tilesX + tx)) continue;
            r.x0 = std::min(r.x0, tx * T);
            r.y0 = std::min(r.y0, ty * T);
            r.x1 = std::max(r.x1, std::min(rest.width, (tx + 1) * T));
            r.y1 = std::max(r.y1, std::min(rest.height, (ty + 1) * T));
        }
    if (r.x0 >= r.x1 || r.y0 >= r.y1) return TexelRect{};
    return r;
}

} // namespace dermis
