// Dermis core — lint's findings about the model's own UVs (SPEC §8 "UV diagnosis"), for lintScene
// (lint.hpp), which calls these; they read the model's UvDiagnosis (uv_diagnosis.hpp).
//
//   no_uvs      (warning, the scene: placement −1) the model has no TEXCOORD_0 and the scene has
//               enabled placements with projection "uv": they name at most five of them and
//               suggest projection "surface", which needs no UVs.
//   uv_overlap  (warning, per enabled UV placement) where the height maps live in the model's
//               UVs (modelUvsHoldHeightmaps: uv_layout "model", or "auto" on usable UVs) and
//               the footprint's non-flat samples inside [0,1]² land on overlapped texels: the
//               regions claiming those texels that are not the placement's own — where the
//               pattern also shows — with the share of the footprint. The placement's own
//               regions are those driven by its joint or that joint's parent (else the region
//               under most of the footprint); a footprint on texels only its own region claims
//               twice is a fold ("its other half").
//               (info, the scene) uv_layout "auto" on a model whose UVs overlap (not usable),
//               with enabled UV placements: the overlap and the regions sharing texels, and that
//               the height maps use a generated layout, in which the placements' UVs are.
//
// Pure; never fails. Samples are UV points (lint.cpp's 12×12 footprint grid, flat ones left out).
#pragma once

#include "lint.hpp"
#include "uv_diagnosis.hpp"

#include <glm/glm.hpp>

#include <cstddef>
#include <optional>
#include <vector>

namespace dermis {

/// no_uvs for `scene` on `model` (nullopt when the model has UVs or no enabled UV placement).
std::optional<LintFinding> lintNoUvs(const Scene& scene, const Model& model);

/// The scene-wide uv_overlap info (nullopt unless uv_layout is auto, the model has UVs that are
/// not usable, and an enabled UV placement exists).
std::optional<LintFinding> lintModelUvOverlap(const Scene& scene, const UvDiagnosis& diagnosis);

/// uv_overlap of placement `index` of `scene` from its `samples`; `joint` and `parent` are its
/// driver joint's node and that joint's parent joint (−1 for none). nullopt when the height maps
/// are not in the model's UVs or no sample lands on an overlapped texel.
std::optional<LintFinding> lintPlacementUvOverlap(const Scene& scene, std::size_t index,
                                                  const std::vector<glm::dvec2>& samples, int joint,
                                                  int parent, const UvDiagnosis& diagnosis);

/// Whether a region claiming the texel under `uv` is driven by `joint` or `parent` (no_influence:
/// triangles too small to hold a texel centre, as palette atlases collapse them, are found by
/// the diagnosis' texel map, not by UvLookup).
bool regionDrivenAt(const UvDiagnosis& diagnosis, glm::dvec2 uv, int joint, int parent);

} // namespace dermis
