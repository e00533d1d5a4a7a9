// Dermis core — what a model's own UVs are good for (SPEC §8 "UV diagnosis"): used and overlapping
// texel fractions with the regions / joints that share texels, mirrored island pairs, missing or
// out-of-range UVs, texel density per driving joint. `uv_layout: auto` chooses the model's UVs
// when `usable()` (modelUvsHoldHeightmaps).
//
// How it is measured (diagnoseUvs):
//   texels:   every triangle with UVs is rasterized into a resolution² grid over [0,1]² (the
//             height map's texels), exactly: UVs snapped to 1/256 texel, integer edge functions,
//             a texel belongs to a triangle when its centre is inside (a top-left rule on edges,
//             so two triangles sharing an edge never both hold a texel). A triangle that holds no
//             texel centre (zero UV area, as palette atlases collapse whole faces onto a colour
//             swatch, or smaller than a texel) claims the texel under its UV centroid. UVs outside
//             [0,1] are counted (out of range) and wrapped (glTF samplers REPEAT by default: the
//             texel the model's own texture shows there).
//   island:   a connected piece of the atlas: triangles sharing vertex indices within a part
//             (glTF splits vertices along UV seams), as UvLookup's charts.
//   region:   the triangles of one part whose dominant skin joint (largest summed weight over
//             the corners; a rigid part's node, or the nearest joint above it) is the same: what
//             an artist can name, "Barbarian_Hat (head)". The part's label is its glTF node's
//             name, else the mesh name, else "part N".
//   overlap:  a texel claimed by triangles of two islands (palette swatches, mirrored islands),
//             or held by two triangles of one island (an island folded onto itself). The regions
//             of every triangle claiming an overlapped texel share it.
//   mirrored: two islands (each ≥ 16 texels of UV area) whose UV bounds coincide (IoU ≥ 0.75,
//             areas within 25 %) and whose rest-pose centroids mirror across the model's symmetry
//             plane (within 5 % of the body's size, both off the plane): left and right elbow
//             are one texel.
//   density:  per dominant joint, texels per unit of rest-pose world space at `resolution`:
//             resolution · √(UV area / surface area) of its triangles.
//
// Pure (no GL, no I/O); deterministic (the same model gives the same diagnosis, bit for bit).
// Nothing here throws but std::bad_alloc. O(triangles + covered texels); the texel map it keeps
// is resolution² · 4 bytes (4 MiB at 1024²).
#pragma once

#include "mirror.hpp"
#include "model.hpp"
#include "texture_layout.hpp"

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace dermis {

/// Overlap below this fraction of the used texels is "unique" (SPEC §8 `uv_layout: auto`).
inline constexpr double kUvOverlapUsable = 0.005;

struct UvDiagnosisOptions {
    int resolution = 1024; ///< texels per side of the grid (clamped to [16, 4096])
};

/// The triangles of one part with one dominant joint (see above).
struct UvRegion {
    std::string name;   ///< "<part label> (<joint>)", or the part label alone without a joint
    std::string part;   ///< the part's label (its node's name, else the mesh's, else "part N")
    int partIndex = -1; ///< index in Model::parts
    std::string joint;  ///< the dominant joint's node name, "" for none
    int jointNode = -1; ///< its index in Model::nodes, −1 for none
    std::size_t triangles = 0;
    std::size_t texels = 0;       ///< texels it claims
    std::size_t sharedTexels = 0; ///< of those, overlapped texels (shared or folded)
    std::size_t foldedTexels = 0; ///< overlapped texels no other region claims (it folds onto itself)
    /// The other regions claiming its overlapped texels: (region index, texels both claim), most
    /// texels first (ties: lower index first).
    std::vector<std::pair<int, std::size_t>> sharesWith;
};

/// Islands that are mirror images on the body and one in texture space, gathered by their
/// regions (an island's region: the one most of its triangles belong to).
struct UvMirroredPair {
    int regionA = -1, regionB = -1; ///< regionA ≤ regionB (equal: a region's two halves, a torso's)
    std::size_t islandPairs = 0;    ///< island pairs between the two
    std::size_t trianglesA = 0, trianglesB = 0; ///< triangles of those islands, on each side
};

/// Texel density of the triangles one joint drives (their dominant joint).
struct UvJointDensity {
    int node = -1;
    std::string joint;
    std::size_t triangles = 0;
    double surfaceArea = 0.0; ///< rest-pose world units²
    double uvArea = 0.0;      ///< of [0,1]² (overlapping triangles each count)
    double texelsPerUnit = 0.0;
};

struct UvDiagnosis {
    bool hasUVs = false;          ///< every part has TEXCOORD_0 (Model::hasUVs)
    double usedFraction = 0.0;    ///< texels of [0,1]² covered by at least one triangle
    double overlapFraction = 0.0; ///< of used texels, those claimed by more than one surface region
                                  ///< (two islands, or an island folded onto itself)

    int resolution = 0;              ///< the grid side these counts are at
    std::size_t usedTexels = 0, overlapTexels = 0;
    std::size_t triangles = 0;           ///< triangles with UVs (rasterized)
    std::size_t missingTriangles = 0;    ///< triangles without UVs (parts without TEXCOORD_0,
                                         ///< indices past the UVs, non-finite or huge UVs)
    std::size_t partsWithoutUvs = 0;
    std::size_t outOfRangeVertices = 0;  ///< UV vertices of triangles outside [0,1]² (wrapped)
    std::size_t outOfRangeTriangles = 0; ///< triangles with such a corner
    std::size_t subTexelTriangles = 0;   ///< triangles holding no texel centre (claim one texel)
    std::size_t islands = 0;
    std::vector<UvRegion> regions;             ///< by part, then first triangle
    std::vector<UvMirroredPair> mirroredPairs; ///< by regionA, then regionB
    std::vector<UvJointDensity> density;       ///< by node index
    /// Per part, per triangle: its region (index into `regions`), −1 without UVs.
    std::vector<std::vector<int>> triangleRegion;

    /// The model's UVs can hold height maps: present and overlap below 0.5 % of used texels.
    bool usable() const { return hasUVs && overlapFraction < kUvOverlapUsable; }

    /// The regions claiming the texel under `uv` (wrapped like the diagnosis; ascending indices;
    /// empty where no triangle is or uv is not finite). `overlapped`, when given, is set to
    /// whether that texel is an overlapped one.
    std::span<const int> regionsAt(glm::dvec2 uv, bool* overlapped = nullptr) const;

    /// For people: the regions sharing the most texels, each with what it shares them with —
    /// "Barbarian_Hat (head) shares texels with Barbarian_Body (hips), … and 3 more; …" — at
    /// most `regions` regions naming at most `others` others each; "" without overlap.
    std::string describeSharing(std::size_t regions = 3, std::size_t others = 3) const;

    /// The texel map: per texel (row-major, row 0 = v in [0, 1/resolution)), 0 for none, else
    /// 1 + an index into regionSets, with kOverlappedTexel set on overlapped texels.
    std::vector<std::uint32_t> texelSets;
    std::vector<std::vector<int>> regionSets; ///< ascending region indices
    static constexpr std::uint32_t kOverlappedTexel = 0x80000000u;
};

/// The diagnosis of `model`'s TEXCOORD_0 (see above). `rest` and `plane` must be restSkin(model)
/// and symmetryPlane(rest) of this model (ModelDerived caches both); they place the islands for
/// the mirrored pairs and the density. A model without parts or UVs gives zero fractions and
/// empty lists (hasUVs false).
UvDiagnosis diagnoseUvs(const Model& model, const RestSkin& rest, const SymmetryPlane& plane,
                        const UvDiagnosisOptions& options = {});
/// The same, computing the rest skin and symmetry plane itself.
UvDiagnosis diagnoseUvs(const Model& model, const UvDiagnosisOptions& options = {});

/// Whether the height maps of a scene with `mode` live in the model's own UVs: "model" always,
/// "generated" never, "auto" when the model's UVs are usable() (else a generated layout).
bool modelUvsHoldHeightmaps(UvLayoutMode mode, const UvDiagnosis& diagnosis);

} // namespace dermis
