// Dermis core — tangent frames for normal maps, generated as MikkTSpace does (Morten Mikkelsen,
// "Simulation of wrinkled surfaces revisited", 2008; the algorithm of mikktspace.c with its default
// settings), which is what glTF 2.0 asks of a client when a normal-mapped primitive has no TANGENT
// (§3.7.2.1) and what Blender, Substance and the Khronos sample viewer bake and shade with.
//
// Pure functions: no GL, no I/O. Debian ships no mikktspace package; this is a small
// implementation of its algorithm, not a copy of its code.
#pragma once

#include "core/model.hpp"
#include "core/result.hpp"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace dermis {

/// One tangent per triangle corner (3 per triangle of `indices`, in order) of a triangle list:
///  * each triangle's tangent and bitangent are the directions of +u and +v of the texture on it
///    (v of the image's up: `uvs` are glTF's, v down, and are flipped for the frame);
///  * a corner's tangent is its triangle's, projected onto the plane of the corner's normal and
///    weighted by the corner's angle in that plane; the corners of a vertex — vertices equal in
///    position, normal and UV count as one, as mikktspace welds them — sum when their triangles'
///    UV orientation agrees (mirrored UV islands keep their own frame);
///  * xyz is the normalised sum, w = ±1 the orientation, so that the bitangent is w·(n × t): the
///    convention of glTF's TANGENT and of the shading (core/model.hpp MeshPart::tangents).
/// A corner whose vertex has no triangle with a usable UV mapping (zero UV area, degenerate
/// positions) gets a unit vector perpendicular to its normal, w = 1.
/// Preconditions: positions, normals and uvs have one entry per vertex; indices in range and a
/// multiple of 3. Fails (InvalidArgument, naming the argument) otherwise. Does not modify anything.
Result<std::vector<glm::vec4>> cornerTangents(const std::vector<glm::vec3>& positions,
                                              const std::vector<glm::vec3>& normals,
                                              const std::vector<glm::vec2>& uvs,
                                              const std::vector<std::uint32_t>& indices);

/// Sets part.tangents from cornerTangents over UV set `uvSet` (0: uvs, 1: uvs1). A vertex whose
/// corners got different tangents (the two sides of a mirror seam sharing the vertex) is split:
/// copies of it, with every per-vertex array (positions, normals, UVs, colours, joints, weights
/// and each morph target's deltas) copied, are appended and the triangles re-indexed, so the part
/// may gain vertices. Morph targets get no tangent deltas. Fails (InvalidArgument, field "normals"
/// or "uvs"/"uvs1") when the part lacks normals or that UV set, leaving it unchanged; replaces
/// tangents the part already had.
Status generateTangents(MeshPart& part, int uvSet = 0);

} // namespace dermis
