// Dermis io shell — characters from glTF 2.0 (.glb / .gltf), in two steps (after filament's
// AssetLoader / ResourceLoader):
//   1. parseGltf: bytes → Model (nodes, joints, mesh parts, materials, clips). Embedded or
//      buffer-view images are captured as encoded bytes (tinygltf's image-loader hook) but not
//      decoded.
//   2. loadGltfResources: decodes the captured images (decodeImage8: PNG and JPEG directly,
//      other formats through the OpenImageIO module) into Model::images.
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
//
// Limits (GltfLimits): a small file can declare a huge model — an accessor without a buffer view
// is count zeros (glTF 2.0 §3.6.2.1), one mesh can be instanced by many nodes, a PNG of a few
// hundred kilobytes can declare 16384² pixels. So every size is checked from what the file
// declares BEFORE anything is allocated for it: triangles, vertices and mesh parts after
// instancing, accessor element counts and the accessor values read in all, skin joints (step 1,
// from the parsed JSON, before any accessor is read), and texture sizes from the PNG IHDR / JPEG
// SOF header bytes (step 2, before any image is decoded). Past a limit: ErrorCode::TooLarge whose
// `field` is the JSON pointer of the primitive, accessor, skin or image at fault and whose message
// gives the declared size and the limit. Textures within the decode budget but with a side above
// `maxImageSide` are decoded and then downscaled (box filter, aspect kept) to fit.
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

/// What a loaded model may hold; every check uses the sizes the file declares, before allocating
/// (see the top of this file). Defaults: the server's defaults (ServerLimits).
struct GltfLimits {
    /// Triangles of all loaded primitives, each counted once per node that instances its mesh.
    std::size_t maxTriangles = 1000000;
    /// Distinct joints of all skins (and joints listed by any one skin).
    std::size_t maxJoints = 1024;
    /// Mesh parts (triangle primitives × instances).
    std::size_t maxParts = 4096;
    /// Base-colour textures with a larger side are downscaled to fit after decoding.
    int maxImageSide = 4096;
    /// Σ width × height × 4 over the base-colour textures, at their declared (full) size: what
    /// decoding allocates. Past it the model is refused, not downscaled.
    std::size_t maxTextureBytes = std::size_t(256) << 20;

    /// Vertices after instancing, and the elements of any one accessor read: 3 × maxTriangles
    /// (at least 65536).
    std::size_t maxElements() const;
    /// Accessor values (elements × components) read in all, counting each use (a mesh's
    /// attributes once per instance, skin influences per skinned part, animation channels):
    /// 24 × maxElements().
    std::size_t maxValues() const;
};

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
/// Past a limit of `limits` (triangles, vertices, parts, accessor counts, values, joints):
/// ErrorCode::TooLarge, decided from the declared sizes before any accessor is read.
Result<ParsedGltf> parseGltf(const std::vector<std::uint8_t>& bytes, const std::string& baseDir,
                             const GltfLimits& limits = {});

/// Step 2. Decodes every pending image to RGBA8 (decodeImage8: libpng / libjpeg-turbo, else the
/// OpenImageIO module) into parsed.model.images and clears parsed.images. A corrupt image is an
/// error (field "/images/<i>"), leaving the model's images partly filled. Before decoding anything, reads
/// every image's declared size from its header: not a PNG or JPEG → Unsupported; the declared
/// sizes over limits.maxTextureBytes in all → TooLarge (nothing decoded). Images with a side over
/// limits.maxImageSide are downscaled after decoding.
Status loadGltfResources(ParsedGltf& parsed, const GltfLimits& limits = {});

/// Both steps for a file on disk.
Result<Model> loadGltfFile(const std::string& path, const GltfLimits& limits = {});

/// Named files held in memory: plain file name → bytes.
using GltfFiles = std::map<std::string, std::vector<std::uint8_t>>;

/// Both steps for a .gltf (or .glb) given with its files in memory, as an upload brings them:
/// `mainFile` names it among `files`; its external URIs (percent-decoded, as glTF asks) resolve
/// only to other entries of `files` by plain name. A URI with a folder, "..", an absolute path or
/// a name not in `files` fails like an unreadable file (Parse). Reads no file of this machine
/// and writes none. NotFound (field `mainFile`) when `mainFile` is not in `files`.
Result<Model> loadGltfFromFiles(const GltfFiles& files, const std::string& mainFile,
                                const GltfLimits& limits = {});

} // namespace dermis
