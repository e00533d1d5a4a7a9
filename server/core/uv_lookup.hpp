// Dermis core — from a texture-space point to the surface (SPEC §6: the index that lint, pick and
// mirror share): which triangle of the rest mesh covers a UV point, where that is on the body,
// which skin weights hold there, and which UV chart it belongs to.
//
// A uniform grid over [0, 1]² holds every triangle whose UV bounding box touches a cell; a query
// tests the triangles of one cell exactly (barycentric coordinates, a small tolerance on the
// edges). Charts are the connected components of triangles sharing vertex indices within a part
// (glTF duplicates vertices along UV seams, so a chart is a piece of the atlas). Where the atlas
// overlaps itself (palette textures) find returns the first triangle found, findAll all of them.
//
// Pure; immutable after construction, so concurrent queries are safe. Holds a pointer to the
// model: it must outlive the lookup. Positions are in glTF bind space (the rest mesh).
#pragma once

#include "model.hpp"

#include <glm/glm.hpp>

#include <optional>
#include <vector>

namespace dermis {

class UvLookup {
public:
    /// Indexes `model`'s triangles by UV; parts without UVs are left out. `cells` per side (0 =
    /// about √(triangles), clamped to [8, 512]).
    explicit UvLookup(const Model& model, int cells = 0);

    struct Hit {
        int part = -1;
        int triangle = -1;   ///< index of the triangle within the part (indices[3·triangle…])
        glm::vec3 bary{0.0f}; ///< barycentric weights of the triangle's three corners
        int chart = -1;      ///< 0 … chartCount() − 1
    };

    /// The triangle covering `uv`, or nullopt where no chart is (or uv is not finite).
    std::optional<Hit> find(glm::dvec2 uv) const;
    /// Every triangle covering `uv`, in the order find() tries them (find() answers the first):
    /// more than one where the atlas overlaps itself (palette swatches, mirrored islands) or on
    /// a shared edge. Empty where find() answers nullopt. Zero-area triangles are never found.
    std::vector<Hit> findAll(glm::dvec2 uv) const;
    /// The rest-mesh position at a hit (bind space).
    glm::vec3 position(const Hit& h) const;
    /// The skin weight of node `node` at a hit: the corners' weights blended barycentrically.
    float weightOf(const Hit& h, int node) const;
    int chartCount() const { return chartCount_; }

private:
    /// Calls onHit(Hit) for each triangle covering uv, in grid order, until it returns false.
    template <class Visit>
    void visit(glm::dvec2 uv, Visit&& onHit) const;
    struct Tri {
        int part, triangle, chart;
    };
    const Model* model_;
    int cells_ = 8;
    std::vector<Tri> tris_;
    std::vector<std::vector<int>> grid_; ///< per cell (row-major), indices into tris_
    int chartCount_ = 0;
};

} // namespace dermis
