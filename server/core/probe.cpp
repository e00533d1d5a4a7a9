// Probe of one texel. See probe.hpp.
#include "probe.hpp"

#include "texture_layout.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

Result<ProbeResult> probeHeights(const HeightMapInput& in, double u, double v) {
    const char* where = "dermis::probeHeights";
    for (auto [value, name] : {std::pair{u, "u"}, std::pair{v, "v"}})
        if (!std::isfinite(value) || value < 0.0 || value > 1.0)
            return makeError(ErrorCode::InvalidArgument, where, name, "must be in [0, 1]");
    if (in.width <= 0 || in.height <= 0 || in.width > kMaxHeightmapSize || in.height > kMaxHeightmapSize)
        return makeError(ErrorCode::InvalidArgument, where, "/heightmap/size",
                         "each side must be in [1, " + std::to_string(kMaxHeightmapSize) + "]");
    ProbeResult r;
    r.texelX = std::min(in.width - 1, static_cast<int>(u * in.width));
    r.texelY = std::min(in.height - 1, static_cast<int>(v * in.height));
    r.u = (r.texelX + 0.5) / in.width;
    r.v = (r.texelY + 0.5) / in.height;
    if (in.base && !in.base->data.empty()) {
        const bool same = in.base->width == in.width && in.base->height == in.height;
        r.base = same ? in.base->at(r.texelX, r.texelY) : sampleBilinear(*in.base, r.u, r.v);
    }
    r.bump = r.base;
    const glm::dvec2 uv(r.u, r.v);
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        const BakePlacement& p = in.placements[k];
        if (!p.pattern || p.pattern->data.empty())
            return makeError(ErrorCode::InvalidArgument, where,
                             "/placements/" + std::to_string(k) + "/pattern", "no pattern image");
        glm::dvec2 s;
        float height = 0.0f;
        if (p.surface) {
            // SPEC §8: the decal at the texel's rest-surface point.
            const RestSurfaceMap* rest = in.rest.get();
            if (!rest || rest->width != in.width || rest->height != in.height ||
                rest->position.size() != static_cast<std::size_t>(in.width) * in.height)
                return makeError(ErrorCode::InvalidArgument, where,
                                 "/placements/" + std::to_string(k) + "/projection",
                                 "a surface placement needs the rest-surface map at the map size");
            const std::size_t idx = static_cast<std::size_t>(r.texelY) * in.width + r.texelX;
            if (!rest->coverage[idx]) continue;
            const glm::dvec3 pos(rest->position[idx]), nrm(rest->normal[idx]);
            if (!SurfaceFrame(p).toPattern(pos, nrm, s)) continue;
            if (p.t > 0.0) height = surfacePlacementHeight(p, pos, nrm);
        } else {
            s = p.footprint.toPattern(uv);
            if (s.x < 0.0 || s.x > 1.0 || s.y < 0.0 || s.y > 1.0) continue;
            if (p.t > 0.0) height = placementHeight(p, uv);
        }
        ProbeContribution c;
        c.source = p.source;
        c.target = p.target;
        c.t = p.t;
        c.L = sampleBilinear(*p.pattern, s.x, s.y);
        c.height = height;
        (p.target == Target::Bump ? r.bump : r.displacement) += c.height;
        r.contributions.push_back(c);
    }
    return r;
}

} // namespace dermis
