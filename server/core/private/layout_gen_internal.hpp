// Dermis core — private to server/core/layout_gen*.cpp: the steps of the generated height-map
// layout (layout_gen.hpp) that generateTextureLayout (layout_gen.cpp) runs, each in its own file:
//   * layout_charts.cpp: a part welded by position, its edges sorted into chart boundaries (UV
//     seams, creases, borders, non-manifold or inconsistently oriented edges, degenerate
//     triangles) and inner edges, charts grown over inner edges inside a normal cone, a chart's
//     triangles as a local mesh (vertices split along its boundary) and its topology;
//   * layout_flatten.cpp: each chart flattened by LSCM and checked (no flip, no boundary crossing,
//     bounded area stretch), split in two and retried where a check fails;
//   * layout_pack.cpp: charts scaled to one texel density, turned to their smallest box, packed
//     on the texel grid with gutters, as boxes and by outline (degenerate triangles in a lattice
//     of one-texel cells);
//   * layout_check.cpp: checkTextureLayout (public, layout_gen.hpp), the final verification.
// Not included outside these files. Nothing here fails: every chart ends flattened (a single
// triangle always is) and packing returns false only when nothing fits at any density.
#pragma once

#include "core/layout_gen.hpp"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace dermis::layout_detail {

// --- charts (layout_charts.cpp) -----------------------------------------------------------------

/// One part welded by position (bit-equal positions are one vertex), with per-triangle data and
/// adjacency across inner edges.
struct PartMesh {
    std::vector<glm::dvec3> positions; ///< welded vertices
    std::vector<glm::uvec3> tris;      ///< welded triangles, in the part's triangle order
    std::vector<glm::dvec3> normals;   ///< unit face normals (0 for degenerate triangles)
    std::vector<double> areas;         ///< face areas
    std::vector<char> degenerate;      ///< repeated welded vertex or (near-)zero area
    /// adj[t][c]: triangle across edge (t[c], t[c+1]) when that edge is an inner edge (exactly
    /// two triangles, opposite directions, same UVs on both sides where both have a UV area,
    /// dihedral ≤ crease, neither degenerate), else −1.
    std::vector<std::array<int, 3>> adj;
};

/// Welds and classifies the edges of `part`. Precondition: indices in range (checked by the
/// caller).
PartMesh buildPartMesh(const MeshPart& part, const LayoutGenOptions& options);

/// Charts grown over inner edges: best-first by normal deviation (with a small distance term for
/// compact charts), every triangle within options.coneDegrees of both the seed's normal and the
/// chart's running area-weighted normal; seeds in triangle order. Then borders smoothed (a
/// triangle with two neighbours in another chart whose cone it fits joins it; up to 8 passes) and
/// charts under a tenth of the mean chart area merged into the neighbour they share most edges
/// with whose cone all their triangles fit (smallest first). Degenerate triangles are in no
/// chart. Returns chart triangle lists, each sorted ascending, in order of first triangle.
std::vector<std::vector<std::uint32_t>> growCharts(const PartMesh& mesh,
                                                   const LayoutGenOptions& options);

/// A chart's triangles as a local mesh: corners united across inner edges between member
/// triangles, so the chart's boundary and any non-manifold vertex split its vertices.
struct LocalChart {
    std::vector<std::uint32_t> tris;                    ///< part triangle ids (ascending)
    std::vector<std::uint32_t> welded;                  ///< local vertex → welded vertex
    std::vector<glm::uvec3> local;                      ///< per member triangle, local vertices
    std::vector<std::array<std::uint32_t, 2>> boundary; ///< directed boundary edges (local)
    int loops = 0;                                      ///< boundary loops
    int euler = 0;                                      ///< V − E + F
    bool isDiskLike() const { return loops >= 1 && (2 - euler - loops) == 0; } ///< genus 0
};

/// `member` is a scratch array of the part's triangle count, all −1 on entry and on return.
LocalChart buildLocalChart(const PartMesh& mesh, std::vector<std::uint32_t> tris,
                           std::vector<int>& member);

/// Splits a triangle set in two non-empty parts: a set that is not edge-connected into the
/// piece of its first triangle and the rest; a connected one into two connected halves grown
/// from two far-apart seeds (two-source Dijkstra over inner edges, centroid distances).
/// Precondition: tris.size() ≥ 2. `member` as for buildLocalChart.
std::array<std::vector<std::uint32_t>, 2>
splitChart(const PartMesh& mesh, const std::vector<std::uint32_t>& tris, std::vector<int>& member);

// --- flattening (layout_flatten.cpp) ------------------------------------------------------------

/// A flattened chart: UVs in metres (area-preserving overall: Σ UV area = Σ surface area),
/// triangles positively oriented (y up).
struct FlatChart {
    int part = 0;
    LocalChart chart;
    std::vector<glm::dvec2> uv; ///< per local vertex
    double area = 0.0;          ///< surface area, m²
};

/// Flattens every chart of `charts` (part `part`), splitting those that fail the checks; appends
/// to `out`. `splits` counts the splits made.
void flattenCharts(const PartMesh& mesh, int part, std::vector<std::vector<std::uint32_t>> charts,
                   const LayoutGenOptions& options, std::vector<FlatChart>& out, int& splits);

// --- packing (layout_pack.cpp) ------------------------------------------------------------------

/// Where packing put things: per chart the map from its metre UVs to [0,1]² (uv' = origin +
/// R·uv with R a rotation times the density, v flipped so that front faces read clockwise in
/// (u, v-down) terms like glTF), and the degenerate cells.
struct Placement {
    glm::dvec2 origin{0};
    glm::dmat2 linear{1.0};
};
struct Packing {
    std::vector<Placement> charts;
    double texelsPerMetre = 0.0;  ///< density at options.resolution
    glm::ivec2 degenerateCell{0}; ///< lower corner (texels) of the degenerate grid
    int degenerateColumns = 0;    ///< cells per row of that grid
};

/// Turns each chart to its smallest bounding box and packs all of them (and a lattice of
/// `degenerateCount` one-texel cells) into options.resolution² texels with options.gutterTexels
/// free texels between charts and along the border, at the largest density found that fits
/// (layout_pack.cpp says how). False when the charts do not fit at any density.
bool packCharts(const std::vector<FlatChart>& charts, std::size_t degenerateCount,
                const LayoutGenOptions& options, Packing& packing);

/// UV (in [0,1]², v down) of corner `corner` (0..2) of degenerate cell `cell`: the cells are
/// one-texel triangles of a lattice, neighbours sharing corners (one connected piece).
glm::dvec2 degenerateUv(const Packing& packing, const LayoutGenOptions& options, std::size_t cell,
                        int corner);

} // namespace dermis::layout_detail
