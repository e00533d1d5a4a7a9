// Dermis core — the outline of a placement's footprint in the height-map layout in use (SPEC §8),
// for the editor's texture view: what to draw (segments in UV), into how many pieces the layout
// cuts it, where each piece lies, where its anchor lies, and whether a texture point is inside it
// (its hit test).
//
// A surface placement's footprint is the set of rest-surface points its decal reaches
// (SurfaceFrame::toPattern, heightmap.hpp): normal·n > 0, |d·n| ≤ depth and |d·t| ≤ w/2,
// |d·b| ≤ h/2 with d = position − anchor, b = n × t. Over one triangle, with positions and normals
// interpolated barycentrically as the rest-surface map does (texture_layout.hpp), each of these
// seven conditions is a half-plane of the triangle's barycentric coordinates, so the footprint's
// part in a triangle is the triangle clipped by seven half-planes: a convex polygon, exact for
// the interpolated surface. Its edges that come from a clipping plane are the decal's border and
// become segments; its edges on the triangle's own edges are not drawn. In a layout whose charts
// split at seams the footprint falls into several pieces; a piece is a group of triangles with a
// footprint part (positive area) connected through shared UV edges (equal UV corners) that the
// footprint touches along a stretch. A decal smaller than a triangle is simply a polygon inside
// that triangle: one piece, one closed loop, even when no mesh vertex lies inside it.
//
// A UV placement's footprint is its rotated rectangle (SPEC "Conventions": s = R(−rotation)·(p −
// center)/scale + ½ ∈ [0,1]²): 4 segments, one piece, whatever the model; not clipped to [0,1]².
//
// Pure (no GL, HTTP or images): reads the model given; nothing is cached. Nothing here throws
// but std::bad_alloc.
#pragma once

#include "model.hpp"
#include "result.hpp"
#include "scene.hpp"
#include "uv_lookup.hpp"

#include <glm/glm.hpp>

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

namespace dermis {

/// The most segments an outline holds (surfaceFootprintOutline truncates beyond, see there).
constexpr std::size_t kMaxOutlineSegments = 50000;

/// One connected piece of a footprint in UV space.
struct OutlinePiece {
    glm::dvec2 min{0.0}, max{0.0}; ///< UV bounds of the footprint's part in the piece (not only its border)
    std::size_t triangles = 0;     ///< triangles holding part of it (0 for a UV placement's rectangle)
};

struct SurfaceOutline {
    Projection projection = Projection::Surface;
    /// The border, one segment per clipped edge: u0, v0, u1, v1 in the layout's UV space (v down,
    /// like TEXCOORD_0). Unordered; a segment of a surface placement lies inside one triangle, and
    /// two segments that meet on a triangle edge share that end bit for bit (computed once per
    /// edge, from the edge's corners in a fixed order), so a piece that no chart border cuts is a
    /// closed loop: every end is shared by exactly two segments.
    std::vector<std::array<double, 4>> segments;
    /// Per segment: the index into `pieces` of the piece it borders.
    std::vector<std::size_t> segmentPiece;
    /// The pieces, ordered by the first triangle (part, then index order) of each.
    std::vector<OutlinePiece> pieces;
    /// More than `maxSegments` border segments: `segments` holds the first maxSegments (part,
    /// triangle order); `pieces` still counts and bounds every piece.
    bool truncated = false;
    /// Where the placement sits in the layout. Surface placement: the UV (interpolated
    /// barycentrically) of the rest-surface point nearest to the anchor position — the closest
    /// point on a triangle, among the triangles coming within SurfaceFrame::reach of the anchor
    /// whose interpolated normal at that point faces the anchor normal (dot > 0), else among all
    /// triangles whatever their facing and distance (ties: the first in part, triangle order);
    /// only triangles of the layout count (UVs, indices in range, UV area). Empty when there is
    /// none. UV placement: its center.
    std::optional<glm::dvec2> anchorUv;
};

/// The outline of placement `p`'s footprint in the UV space of `model`'s TEXCOORD_0 — the layout
/// in use: the model's own UVs, or another layout seen through modelThroughLayout
/// (texture_layout.hpp; the service's ModelDerived::throughLayout gives that model).
///
/// Surface placement (SPEC §8): the anchor frame of surfaceFrameOf (bake.hpp), evaluated on the
/// bind-space positions and normals of every triangle of every part with UVs (parts without
/// TEXCOORD_0, or with fewer UVs than positions, are not in the layout and give nothing); a part
/// without one normal per position uses its triangles' face normals, as the rest-surface map
/// does. Triangles with an index out of range, with zero UV area, or whose bounding box lies
/// farther from the anchor than SurfaceFrame::reach are skipped. A decal that reaches no
/// triangle gives no segment and no piece (not an error: e.g. an anchor off the body or a
/// decal facing away from every surface).
///
/// Also the anchor's UV (SurfaceOutline::anchorUv), from the same triangles, whether or not the
/// decal reaches them.
///
/// UV placement: the rectangle's 4 edges, corners in the order s = (0,0), (1,0), (1,1), (0,1);
/// anchorUv its center; `model` is not read.
///
/// `maxSegments` (≥ 1) caps the segments (see SurfaceOutline::truncated). Fails
/// (InvalidArgument) on a surface placement whose anchor is degenerate ("anchor": a zero normal
/// or a tangent parallel to it — possible only for scenes built in code; the parser refuses
/// them), whose size or depth is not a finite number > 0 ("size", "depth"), on a surface
/// placement in a model without any part with UVs ("uv_layout"), and on a UV placement whose
/// center, scale or rotation is not finite or whose scale is not > 0 ("center", "scale",
/// "rotation"). Messages name dermis::surfaceFootprintOutline and the field.
Result<SurfaceOutline> surfaceFootprintOutline(const Model& model, const Placement& p,
                                               std::size_t maxSegments = kMaxOutlineSegments);

/// The footprint's hit test: whether texture point `uv` of `model`'s TEXCOORD_0 (indexed by
/// `lookup`, which must index `model`) is inside placement `p`'s footprint. Surface placement:
/// some triangle covering `uv` (UvLookup::findAll: every one where the layout overlaps itself)
/// has its interpolated rest-surface point and normal reached by the decal
/// (SurfaceFrame::toPattern, what the bake evaluates per texel); false where no triangle covers
/// `uv` or the anchor is degenerate. UV placement: s ∈ [0,1]² (Footprint::toPattern).
bool footprintContains(const Model& model, const UvLookup& lookup, const Placement& p, glm::dvec2 uv);

} // namespace dermis
