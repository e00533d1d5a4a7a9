// Dermis io shell — private to server/io/gltf_*.cpp (the glTF loader of gltf_loader.hpp): the one
// tinygltf configuration, and what the loader (gltf_loader.cpp), the accessor reader
// (gltf_accessors.cpp) and the converter (gltf_convert.cpp) share. Not included by any public
// header.
//
// tinygltf: every unit of the loader includes <tiny_gltf.h> through this header, so that all see
// the same TINYGLTF_NO_* configuration; gltf_loader.cpp alone defines TINYGLTF_IMPLEMENTATION
// before including it (tinygltf's implementation section is outside its include guard: this
// header must be the unit's only path to <tiny_gltf.h>).
//
// Errors are ErrorCode::Parse made by parseError, with `where` = kWhere and `field` the JSON
// pointer at fault; nothing here throws on bad input (allocation failure aside, caught by
// parseGltf).
#pragma once

#include <fstream> // tinygltf's writer needs it even with TINYGLTF_NO_FS
// No stb_image: images are captured encoded (gltf_loader.cpp) and decoded by image_io. No
// stb_image_write: this loader never writes glTF. No default file access: only the confined
// callbacks of gltf_loader.cpp.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_FS
#include <tiny_gltf.h>

#include "io/gltf_loader.hpp"
#include "io/image_header.hpp"

#include "core/model.hpp"
#include "core/result.hpp"

#include <glm/glm.hpp>

#include <cstddef>
#include <initializer_list>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace dermis::gltf_detail {

namespace tg = tinygltf;

inline constexpr const char* kWhere = "dermis::parseGltf";

/// ErrorCode::Parse from parseGltf, naming `field`.
Error parseError(const std::string& field, const std::string& what);

std::string str(std::size_t v);
std::string str(int v);

/// Encoded image bytes by glTF image index, filled by the tinygltf image hook.
struct Captured {
    std::map<int, PendingImages::Entry> images;
};

// ------------------------------------------------------------------------------------------------
// Accessors (gltf_accessors.cpp; glTF 2.0 §3.6 "Accessors", §3.11 normalised data)

/// How an accessor's components are delivered.
enum class Want {
    Float,   ///< any component type; normalised integers per §3.11, others as their value
    Integer, ///< unsigned integer component types only, not normalised (indices, JOINTS_n)
};

/// Accessor contents: count × components values, row by row.
struct AccessorData {
    std::size_t count = 0;
    int components = 0;
    int componentType = 0;
    bool normalized = false;
    std::vector<double> values;
    double at(std::size_t element, int component) const {
        return values[element * static_cast<std::size_t>(components) +
                      static_cast<std::size_t>(component)];
    }
};

/// True for the integer component types of glTF 2.0 (not FLOAT, not invalid ones).
bool isIntegerType(int componentType);

/// Reads accessor `index` of element type `type` (TINYGLTF_TYPE_*), checking every byte range,
/// the component type against `want` (and against `allowed` when non-empty), and sparse
/// substitution (§3.6.2.3). Errors name `field`, the place that references the accessor.
Result<AccessorData> readAccessor(const tg::Model& g, int index, int type, Want want,
                                  std::initializer_list<int> allowed, const std::string& field);

/// Finite and within float range, so that converting to float is defined.
bool fitsFloat(double x);
bool allFitFloat(const std::vector<double>& v);

// ------------------------------------------------------------------------------------------------
// Limits from declared sizes (gltf_preflight.cpp)

/// ErrorCode::TooLarge from parseGltf (or `where`), naming `field`.
Error tooLarge(const std::string& field, const std::string& what, const char* where = kWhere);

/// Checks `g` against `limits` from the declared sizes only (accessor counts, node instancing,
/// skin joint lists, animation channels) — nothing is read from buffers and nothing big is
/// allocated. Mirrors what convertGltf will read: the meshes of the default scene's nodes (each
/// node once), every skin, every animation channel. Indices that do not exist are skipped (the
/// converter reports them).
Status checkDeclaredSizes(const tg::Model& g, const GltfLimits& limits);

/// Reads the declared size of every pending image (image_header.hpp) and checks the sum of
/// width × height × 4 against limits.maxTextureBytes, before anything is decoded. Errors name
/// "/images/<i>" and `where`; `sizes` gets one size per entry.
Status checkDeclaredTextures(const PendingImages& images, const GltfLimits& limits,
                             const char* where, std::vector<ImageSize>& sizes);

// ------------------------------------------------------------------------------------------------
// Conversion (gltf_convert.cpp)

/// glTF → Model (nodes, skins, materials, meshes of the default scene, animations), validating
/// everything it reads. The base-colour images it uses are taken out of `captured` into
/// ParsedGltf::images, still encoded.
Result<ParsedGltf> convertGltf(const tg::Model& g, Captured& captured);

/// Per node that instances a mesh with morph targets: its first index into Model::morphWeights
/// and the mesh's target count.
using MorphSlots = std::map<int, std::pair<int, int>>;

/// Animations → m.clips (gltf_animations.cpp): translation, rotation, scale and weights channels
/// (weights through `morphSlots`; a node without slots moves nothing), keys checked (strictly
/// increasing finite times, one value per key — per target for weights —, finite values).
Status convertAnimations(const tg::Model& g, Model& m, const MorphSlots& morphSlots);

// ------------------------------------------------------------------------------------------------
// Morph targets (gltf_morph.cpp; glTF 2.0 §3.7.2.2)

/// Adds the morph weights of node `nodeIndex` (whose mesh has targets) to m.morphWeights: named
/// by the mesh's extras.targetNames (else "<mesh>#<k>"), rest values from node.weights, else
/// mesh.weights, else 0. Fails when the primitives disagree on the target count or a weights
/// array has another length. `slots` gets the node's entry; no-op for a mesh without targets.
Status addMorphWeights(const tg::Model& g, int nodeIndex, Model& m, MorphSlots& slots);

/// Reads the POSITION, NORMAL and TANGENT deltas of `prim`'s targets into part.morphs (weights
/// firstWeight + k), each checked for the part's vertex count and finite values. Other target
/// attributes (TEXCOORD_n, COLOR_n) are ignored.
Status readMorphTargets(const tg::Model& g, const tg::Primitive& prim, const std::string& field,
                        int firstWeight, MeshPart& part);

/// A rigid part's morph deltas into its rest world space (MeshPart: rigid parts are stored
/// there): positions and tangents by the linear part of `world`, normals by its inverse
/// transpose; normal and tangent deltas scaled like the part's own were when normalised
/// (`normalScale`, `tangentScale`: per vertex, 1 / |M·v₀| before normalisation).
void transformMorphs(MeshPart& part, const glm::dmat4& world, const std::vector<double>& normalScale,
                     const std::vector<double>& tangentScale);

} // namespace dermis::gltf_detail
