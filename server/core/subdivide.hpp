// Dermis core — synthetic load for benchmarks and tests: midpoint subdivision of skinned meshes
// and extra joints in a rig.
//
// Pure functions on values (no I/O, no GL); they return new models and never modify their input.
// Used by dermis-bench's scaling run to grow the default character to ~70k or ~280k triangles
// and 200 joints without new model files.
#pragma once

#include "model.hpp"
#include "result.hpp"

namespace dermis {

/// Splits every triangle of `part` into four at its edge midpoints (shared edges share their
/// midpoint vertex, so the mesh stays watertight where it was). A midpoint vertex interpolates
/// its edge's ends: position and UV averaged, normal averaged and renormalised, skin weights
/// averaged over the union of both ends' influences, keeping the four largest (renormalised to
/// sum 1). Triangle count ×4, orientation kept. Precondition: indices in range (as the loader
/// guarantees); fails with InvalidArgument naming "indices" otherwise.
Result<MeshPart> subdivideMidpoint(const MeshPart& part);

/// `levels` rounds of subdivideMidpoint on every part (×4^levels triangles). levels ∈ [0, 6].
Result<Model> subdivideModel(const Model& model, int levels);

/// Adds joints until the model has `total` (no change if it already has that many): each new
/// joint is a child node of an existing joint (round-robin), at a small offset, and is added as
/// one more influence of every skinned part (inverse bind = inverse of its rest world matrix),
/// so it is posed and uploaded with the palette each frame. Vertex weights are unchanged (at most
/// four influences per vertex): extra joints grow the pose and palette work, not the per-vertex
/// blend. Fails (InvalidArgument, "joints") on a model without joints or total > 65535.
Result<Model> withSyntheticJoints(const Model& model, int total);

} // namespace dermis
