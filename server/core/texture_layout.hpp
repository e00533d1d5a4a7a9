// Dermis core — the texture space the height maps live in (SPEC §8 "Height-map layout"): a
// layout is, per mesh part, its own vertex list (a layout vertex names the part vertex it copies;
// seams of the layout duplicate vertices) with one UV each and the part's triangles re-indexed in
// the same order. The model's own TEXCOORD_0 is one layout (`modelTextureLayout`); the generated,
// non-overlapping chart layout (layout_gen.hpp) is another. The renderer samples the bump and
// displacement maps with the layout's UVs (a second UV attribute) while the base colour keeps the
// model's own.
//
// Also here: the rest-surface map of a layout, the bind-space position and normal of the surface
// under every texel centre, which surface placements are projected through (SPEC §8 "Surface
// placements"); the CPU reference and the GPU height pass read the same map.
//
// Pure (no GL, no I/O). Nothing here throws but std::bad_alloc.
#pragma once

#include "model.hpp"

#include <glm/glm.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dermis {

/// The scene member `uv_layout`: "auto" (the model's UVs when present and unique — overlap below
/// 0.5 % of used texels — else generated), "model", "generated".
enum class UvLayoutMode { Auto, Model, Generated };
std::string_view toString(UvLayoutMode m);
std::optional<UvLayoutMode> uvLayoutModeFromString(std::string_view s);

/// One part's layout. `indices` has the part's triangle count · 3 entries, triangle k of the
/// layout being triangle k of the part.
struct PartLayout {
    std::vector<std::uint32_t> source; ///< layout vertex → part vertex
    std::vector<glm::vec2> uvs;        ///< per layout vertex, glTF convention (v down), [0,1]²
    std::vector<std::uint32_t> indices;
};

struct TextureLayout {
    std::string kind; ///< "model" or "generated"
    std::vector<PartLayout> parts; ///< one per Model::parts entry; empty parts where there are no UVs
    bool empty() const;            ///< no part has a triangle with UVs
};

/// The model's own TEXCOORD_0 as a layout: source = identity, uvs = part.uvs, indices = part's.
/// A part without UVs (or with fewer UVs than positions) gets an empty PartLayout.
TextureLayout modelTextureLayout(const Model& model);

/// `model` as seen through `layout`: each part with layout triangles gets the layout's vertices
/// (positions, normals, joints and weights copied from the part vertex each names), the layout's
/// UVs as TEXCOORD_0 and its indices; a part without layout triangles keeps its vertices and
/// triangles but no UVs. Triangle k of a part stays triangle k with its corners in the same order,
/// so a UV hit on the result (part, triangle, barycentrics) names the same surface point of
/// `model`. Nodes, joints, materials, images and clips are copied. For the tools that work in
/// texture space (UV lookup, pick by UV, focus, mirror, lint) when the layout in use is not the
/// model's own. Precondition: `layout` is a layout of `model` (one PartLayout per part).
Model modelThroughLayout(const Model& model, const TextureLayout& layout);

/// Per texel centre ((i+0.5)/W, (j+0.5)/H) of a W×H map: the bind-space position and unit normal
/// of the layout's triangle covering it (barycentric interpolation of MeshPart positions and
/// normals), or — within `dilate` texels of a covered texel — those of the nearest covered texel
/// (gutters, so bilinear sampling across a chart edge reads continuous heights). coverage: 0 none,
/// 1 covered, 2 dilated. Where triangles overlap, the later triangle (part, then index order) wins.
///
/// Texels are rasterised at their centres: a centre on a shared edge belongs to both triangles
/// (the later wins), so no texel inside the union of a chart's triangles is left out. Degenerate
/// (zero UV area) triangles and triangles with an index out of range are skipped. The nearest
/// covered texel of a gutter texel is the one at the smallest Euclidean texel distance (≤
/// `dilate`); ties go to the smaller |row offset|, then the row above, then the column to the
/// left — a fixed rule, so the map is the same for any thread count.
struct RestSurfaceMap {
    int width = 0, height = 0;
    std::vector<glm::vec3> position; ///< width·height, row 0 first; 0 where coverage is 0
    std::vector<glm::vec3> normal;   ///< unit where coverage > 0, else 0
    std::vector<std::uint8_t> coverage;
    std::uint64_t contentId = 0;     ///< process-unique (a GPU cache key), > 0 once baked

    /// Culling aid for surface placements (bakeHeightMaps, the GPU pass): the map cut into tiles
    /// of kTile × kTile texels (the last row/column of tiles may be smaller), tilesX · tilesY of
    /// them, row-major; per tile the bounds of the positions of its texels with coverage > 0
    /// (tileMin > tileMax: the tile has none).
    static constexpr int kTile = 16;
    int tilesX = 0, tilesY = 0;
    std::vector<glm::vec3> tileMin, tileMax;
};

/// Bakes the rest-surface map. Deterministic (bit-identical for the same inputs and any thread
/// count; rows are split between up to `threads` threads, 0 = hardware concurrency). Content ids
/// come from their own counter with bit 62 set, so they never equal a PatternImage's id (a small
/// counter) or a GPU pixel hash (bit 63), and may share the renderer's texture cache with them.
/// Preconditions: width, height in [1, kMaxHeightmapSize] (else an empty map with contentId 0);
/// dilate ≥ 0.
RestSurfaceMap bakeRestSurface(const Model& model, const TextureLayout& layout, int width,
                               int height, int dilate = 4, int threads = 0);

} // namespace dermis
