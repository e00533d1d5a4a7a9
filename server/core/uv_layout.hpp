// Dermis core — a character's UV layout for people: the unique edges of its texture-space
// triangles (what an editor draws under the footprints) and a wireframe raster of them.
//
// Pure. Works on TEXCOORD_0 as stored or on any texture layout (u right, v down: row 0 of a
// texture is v = 0). Does not detect charts or overlaps (uv_diagnosis, layout_gen's
// checkTextureLayout) and draws no footprints.
#pragma once

#include "model.hpp"
#include "texture_layout.hpp"

#include <glm/glm.hpp>

#include <vector>

namespace dermis {

/// One UV edge, endpoints in [0,1]² for a well-formed atlas (values outside are kept).
struct UvEdge {
    glm::vec2 a, b;
};

/// Every triangle edge of every part once (per part; an edge shared by two triangles of a part
/// appears once), in part then triangle order. Triangles with an index past the part's UVs are
/// skipped. Empty for a model without UVs.
std::vector<UvEdge> uvEdges(const Model& model);
/// The same for any layout (texture_layout.hpp): each part's layout triangles' edges once.
std::vector<UvEdge> uvEdges(const TextureLayout& layout);

/// A size×size RGBA wireframe: transparent black with the edges in opaque white (one-pixel lines,
/// DDA). Precondition: size ≥ 1. Pixels outside [0,1]² are clipped.
Image8 rasterizeUvEdges(const std::vector<UvEdge>& edges, int size);

} // namespace dermis
