// Dermis core — private to lint.cpp: what lint reads of a surface placement (SPEC §8), whose
// footprint is a decal on the rest surface rather than a UV rectangle. Samples are points of the
// rest mesh (bind space) with their normal, the model's UV there when it has one, and the skin
// weight of interest; a UV placement's grid samples get the same (through the UV index), so
// overlaps are counted alike between both kinds.
//
// Pure; reads the model given (and `lookup`, which must index it). Not a public header.
#pragma once

#include "model.hpp"
#include "scene.hpp"
#include "uv_lookup.hpp"

#include "bake.hpp"

#include <glm/glm.hpp>

#include <optional>
#include <vector>

namespace dermis::lint_detail {

/// A point of the skin a placement covers where its pattern is not flat.
struct SkinSample {
    glm::dvec3 position{0.0}, normal{0, 0, 1}; ///< bind space; valid when hasSurface
    bool hasSurface = false;
    glm::dvec2 uv{0.0};                         ///< the model's UV; valid when hasUv
    bool hasUv = false;
    int part = -1;
    std::uint32_t vertex = 0;                   ///< for a surface placement's samples: a mesh vertex
};

/// The mesh vertices surface placement `p` reaches (its decal, SPEC §8, evaluated at each vertex
/// with the vertex normal; pattern |L| > `flat` where the image is given), with their UVs where
/// the part has them. At most `maxSamples` (spread evenly over the covered vertices).
std::vector<SkinSample> surfaceSamples(const Placement& p, const Model& model,
                                       const PatternImages& images, float flat,
                                       std::size_t maxSamples = 400);

/// The same sample with its surface point and normal from the UV index (for a UV placement's
/// grid sample `uv`); hasSurface false where no chart is.
SkinSample uvSample(const Model& model, const UvLookup& lookup, glm::dvec2 uv);

/// Whether surface placement `q` covers sample `s` (the decal reaches it and its pattern is not
/// flat there).
bool surfaceCovers(const Placement& q, const PatternImages& images, float flat, const SkinSample& s);

/// The largest skin weight of node `node` at a surface placement's samples (vertex weights).
float vertexWeight(const Model& model, const SkinSample& s, int node);

/// Distance from the anchor of `p` to the nearest mesh vertex (bind space); nullopt without one.
std::optional<double> anchorToSurface(const Placement& p, const Model& model, SkinSample* nearest = nullptr);

} // namespace dermis::lint_detail
