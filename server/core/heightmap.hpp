// Dermis core — height images, pattern placements in texture space (and on the rest surface,
// SPEC §8), and the CPU reference of the height-map stage (paper §4, first stage; SPEC §2
// "Height maps" and "Conventions").
//
// Pure and deterministic: the same inputs give bit-identical maps for any thread count (each
// texel sums its placements in document order; threads split rows).
#pragma once

#include "deform.hpp"
#include "result.hpp"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace dermis {

/// Largest height-map side (SPEC §2: default 1024², up to 4096²).
constexpr int kMaxHeightmapSize = 4096;

/// A single-channel float image, row 0 first (row 0 = v near 0).
struct HeightImage {
    int width = 0, height = 0;
    std::vector<float> data; ///< width·height values

    HeightImage() = default;
    HeightImage(int w, int h, float fill = 0.0f)
        : width(w), height(h), data(static_cast<std::size_t>(w) * h, fill) {}
    float at(int i, int j) const { return data[static_cast<std::size_t>(j) * width + i]; }
    float& at(int i, int j) { return data[static_cast<std::size_t>(j) * width + i]; }
};

/// An immutable pattern (or base) image shared by its owner and the frames that use it, with a
/// process-unique content id: ids come from a counter and are never reused, so a cache keyed by
/// the id cannot mistake a new image for a deleted one that had the same address.
struct PatternImage {
    std::uint64_t contentId = 0; ///< > 0
    HeightImage pixels;
};
/// Wraps `pixels` with a fresh content id. Thread-safe.
std::shared_ptr<const PatternImage> makePatternImage(HeightImage pixels);

/// Bilinear sample at normalised coordinates s ∈ [0,1]² (texel centres at (k+0.5)/N), clamped to
/// the edge texels. Precondition: image non-empty.
float sampleBilinear(const HeightImage& image, double su, double sv);

/// Where a placement sits in UV space (SPEC "Conventions").
struct Footprint {
    glm::dvec2 center{0.5, 0.5};
    glm::dvec2 scale{0.1, 0.1}; ///< > 0
    double rotationDeg = 0.0;

    /// s = R(−rotation)·(p − center)/scale + 0.5; inside the footprint iff s ∈ [0,1]².
    glm::dvec2 toPattern(glm::dvec2 uv) const;
    /// Inverse of toPattern.
    glm::dvec2 toUV(glm::dvec2 s) const;
    /// Axis-aligned UV bounds of the rotated rectangle: {min, max}.
    std::pair<glm::dvec2, glm::dvec2> uvBounds() const;
};

/// Texel rectangle [x0, x1) × [y0, y1) of a W×H map whose texel centres may lie in the footprint
/// (clipped to the map; empty when x0 ≥ x1 or y0 ≥ y1).
struct TexelRect { int x0 = 0, y0 = 0, x1 = 0, y1 = 0; };
TexelRect footprintTexels(const Footprint& f, int width, int height);

/// A placement ready to bake: pattern image, footprint, model, and the current t and constant.
struct BakePlacement {
    const HeightImage* pattern = nullptr; ///< not owned; must outlive the bake
    std::uint64_t patternId = 0;          ///< PatternImage::contentId; 0 = unknown (GPU hashes the pixels)
    Footprint footprint;
    DeformModel model = DeformModel::Scale;
    Target target = Target::Bump;
    Response response = Response::Log2;
    double h = 1.0;
    double t = 0.0; ///< normalised angle from normalizedT
    int source = -1; ///< index of the scene placement it comes from (−1: not from a scene)
    // Surface placements (SPEC §8): the footprint is unused; the pattern coordinate of a texel
    // comes from its rest-surface point (RestSurfaceMap) and these, in bind space.
    bool surface = false;
    /// Orthonormal. anchorTangent is the pattern's u direction with the placement's `rotation`
    /// already applied (resolvePlacements turns the anchor's tangent about its normal).
    glm::dvec3 anchorPosition{0.0}, anchorNormal{0, 0, 1}, anchorTangent{1, 0, 0};
    glm::dvec2 size{0.1, 0.1}; ///< > 0, model units
    double depth = 0.05;       ///< > 0, model units
};

/// The contribution of one placement at a UV point (0 outside its footprint).
float placementHeight(const BakePlacement& p, glm::dvec2 uv);

/// A surface placement's projection (SPEC §8) with its constants computed once: c = anchor
/// position, n = anchor normal, t = anchor tangent (rotation applied), b = n × t.
struct SurfaceFrame {
    glm::dvec3 c{0.0}, n{0, 0, 1}, t{1, 0, 0}, b{0, 1, 0};
    double invW = 10.0, invH = 10.0, depth = 0.05;

    explicit SurfaceFrame(const BakePlacement& p);
    /// The pattern coordinate s = (((p−c)·t)/w + ½, ((p−c)·b)/h + ½) of rest-surface point
    /// `position` with unit normal `normal`; false where the decal does not reach it:
    /// |(p−c)·n| > depth, normal·n ≤ 0, or s outside [0,1]².
    bool toPattern(glm::dvec3 position, glm::dvec3 normal, glm::dvec2& s) const;
    /// Radius of a sphere about c holding every point the decal reaches (the pattern box
    /// w × h × 2·depth), slightly widened against rounding.
    double reach() const;
};

/// The contribution of one surface placement at a rest-surface point p with unit normal n
/// (SPEC §8: pattern at (((p−c)·t)/w + ½, ((p−c)·b)/h + ½), 0 where |(p−c)·n| > depth or
/// n_p·n ≤ 0 or outside the pattern square), sampled bilinearly like placementHeight and put
/// through the deformation model (paper eq. 1, 2) with p.t.
float surfacePlacementHeight(const BakePlacement& p, glm::dvec3 position, glm::dvec3 normal);

struct RestSurfaceMap; // texture_layout.hpp
struct TextureLayout;  // texture_layout.hpp

/// Texel rectangle of `rest` (clipped to the map) outside which surface placement `p` adds
/// nothing: the union of the rest map's tiles whose bounds come within SurfaceFrame::reach of
/// the anchor. Empty (x0 ≥ x1) when none does.
TexelRect surfacePlacementTexels(const BakePlacement& p, const RestSurfaceMap& rest);
/// Whether tile `tile` of `rest` (RestSurfaceMap::tileMin/Max index) may hold a texel that the
/// decal of `frame` reaches (its bounds within reach of the anchor).
bool surfaceTileNear(const SurfaceFrame& frame, const RestSurfaceMap& rest, std::size_t tile);

struct HeightMaps {
    HeightImage bump, displacement;
};

/// What both height-map stages take: the CPU reference (bakeHeightMaps,
/// frame_plan.hpp) and the GPU pass (gl/renderer.hpp).
struct HeightMapInput {
    std::vector<BakePlacement> placements; ///< document order; `pattern` points into live images
    const HeightImage* base = nullptr;     ///< optional static bump map
    std::uint64_t baseId = 0;              ///< its PatternImage::contentId (0 = unknown)
    int width = 1024, height = 1024;
    /// The layout the maps live in (SPEC §8) and its rest-surface map at width×height (the latter
    /// set when any placement is a surface placement). Shared, immutable, cached per model.
    std::shared_ptr<const TextureLayout> layout;
    std::shared_ptr<const RestSurfaceMap> rest;
};

struct BakeSettings {
    int width = 1024, height = 1024;
    const HeightImage* base = nullptr; ///< static bump map; sampled bilinearly if sizes differ
    int threads = 0;                   ///< 0 = hardware concurrency
    /// Rest-surface map of the layout at width×height; required when a placement is `surface`.
    const RestSurfaceMap* rest = nullptr;
};

/// Bakes both maps: every texel centre sums its placements' L_out into the target map, plus the
/// base map on bump. A surface placement's L_out at a texel is surfacePlacementHeight at the
/// texel's rest-surface point (settings.rest; texels with coverage 0 get nothing).
/// Fails on a non-positive or > kMaxHeightmapSize size, a null pattern, or a surface placement
/// without a rest map of the map's size ("/placements/<k>/projection").
Result<HeightMaps> bakeHeightMaps(const std::vector<BakePlacement>& placements,
                                  const BakeSettings& settings);

/// Same, into caller-owned maps: their storage is reused when the size matches (no allocation
/// in a per-frame loop) and fully overwritten. On failure `maps` is left unchanged.
Status bakeHeightMapsInto(const std::vector<BakePlacement>& placements,
                          const BakeSettings& settings, HeightMaps& maps);

} // namespace dermis
