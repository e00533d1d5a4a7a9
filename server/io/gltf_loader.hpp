// Dermis io shell — characters from glTF 2.0 (.glb / .gltf), in two steps (after filament's
// AssetLoader / ResourceLoader):
//   1. parseGltf: bytes → Model (nodes, joints, mesh parts, materials, clips). Embedded or
//      buffer-view images are captured as encoded bytes (tinygltf's image-loader hook) but not
//      decoded.
//   2. loadGltfResources: decodes the captured images with OpenImageIO into Model::images.
// loadGltfFile does both for a file on disk (external .bin/.png resolved beside the .gltf),
// loadGltfFromFiles for a .gltf and its files held in memory (an upload).
//
// What is loaded: every triangle primitive (TRIANGLES; TRIANGLE_STRIP and TRIANGLE_FAN are
// converted to lists) of every mesh reachable from the default scene (scene 0 when `scene` is
// absent, every root node when there are no scenes):
//   * skinned meshes in glTF's bind space (rest-pose skinning maps it to world space by the
//     transform above the skeleton, e.g. CesiumMan's "Z_UP" root rotation);
//   * meshes on plain nodes as one-influence rigid skins in rest world space (see MeshPart);
// with POSITION, NORMAL (computed, area-weighted, when missing), TEXCOORD_0, JOINTS_n/WEIGHTS_n
// (the 4 largest weights per vertex, renormalised; a vertex with no weight follows influence 0).
// Also: all nodes with names and rest TRS (a node `matrix` is decomposed), so Model::nodes has the
// file's node indices; skin joints with inverse bind matrices (identity when absent);
// Model::joints = the joints of all skins, in file order, each once; base-colour factor and
// texture (Model::images holds only the images used as base-colour textures); animations
// (translation, rotation, scale; LINEAR, STEP, CUBICSPLINE; unnamed clips are named
// "animation<i>"). Accessors may be strided, normalised integers (KHR_mesh_quantization) or
// sparse. Not loaded: morph targets and "weights" channels, cameras, lights, other texture slots,
// points and lines (skipped with no error).
//
// External files of a .gltf (buffers, images) are read only from inside `baseDir`: absolute URIs,
// ".." and links leading out of it are refused; with an empty `baseDir` no file is read.
//
// Failure: empty, truncated, garbage or inconsistent files (bad GLB chunks, accessor or buffer
// view out of bounds, out-of-range indices or joints, NaN positions, non-increasing key times,
// node cycles, JSON nested deeper than 64 levels) give an Error (ErrorCode::Parse) whose `field`
// is the JSON pointer at fault, e.g. "/meshes/0/primitives/1/attributes/POSITION"; glTF 1.0, GLB
// version 1 and unsupported required extensions give ErrorCode::Unsupported. Never a crash or an
// out-of-bounds read.
#pragma once

#include "core/model.hpp"
#include "core/result.hpp"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace dermis {

/// Largest glTF/GLB file (and external resource) accepted, in bytes.
constexpr std::size_t kMaxGltfBytes = std::size_t(1) << 30;

/// Encoded images captured by parseGltf, consumed by loadGltfResources.
struct PendingImages {
    struct Entry {
        int imageIndex = -1;             ///< index in Model::images
        int gltfImage = -1;              ///< index in the file's `images` (for messages)
        std::vector<std::uint8_t> bytes; ///< PNG / JPEG / … as stored in the file
        std::string mimeType;
    };
    std::vector<Entry> entries;
};

struct ParsedGltf {
    Model model;
    PendingImages images;
};

/// Step 1. `baseDir` resolves external URIs of a .gltf ("" for a self-contained .glb).
Result<ParsedGltf> parseGltf(const std::vector<std::uint8_t>& bytes, const std::string& baseDir);

/// Step 2. Decodes every pending image to RGBA8 (OpenImageIO, through decodeImage8) into
/// parsed.model.images and clears parsed.images. A corrupt image is an error (field
/// "/images/<i>"), leaving the model's images partly filled.
Status loadGltfResources(ParsedGltf& parsed);

/// Both steps for a file on disk.
Result<Model> loadGltfFile(const std::string& path);

/// Named files held in memory: plain file name → bytes.
using GltfFiles = std::map<std::string, std::vector<std::uint8_t>>;

/// Both steps for a .gltf (or .glb) given with its files in memory, as an upload brings them:
/// `mainFile` names it among `files`; its external URIs (percent-decoded, as glTF asks) resolve
/// only to other entries of `files` by plain name. A URI with a folder, "..", an absolute path or
/// a name not in `files` fails like an unreadable file (Parse). Reads no file of this machine
/// and writes none. NotFound (field `mainFile`) when `mainFile` is not in `files`.
Result<Model> loadGltfFromFiles(const GltfFiles& files, const std::string& mainFile);

} // namespace dermis
