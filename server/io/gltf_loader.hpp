// Dermis io shell — characters from glTF 2.0 (.glb / .gltf), in two steps (after filament's
// AssetLoader / ResourceLoader):
//   1. parseGltf: bytes → Model (nodes, joints, mesh parts, materials, clips). Embedded or
//      buffer-view images are captured as encoded bytes (tinygltf's image-loader hook) but not
//      decoded.
//   2. loadGltfResources: decodes the captured images with OpenImageIO into Model::images.
// loadGltfFile does both for a file on disk (external .bin/.png resolved beside the .gltf).
//
// What is loaded: every primitive (TRIANGLES mode) of every mesh reachable from the default
// scene — skinned meshes in bind space, meshes on plain nodes as one-influence rigid skins (see
// MeshPart) — with POSITION, NORMAL (computed when missing), TEXCOORD_0, JOINTS_0, WEIGHTS_0
// (renormalised); nodes with names and rest TRS (a node `matrix` is decomposed); skin joints with
// inverse bind matrices; base-colour factor and texture; animations (translation, rotation,
// scale; LINEAR, STEP, CUBICSPLINE). Not loaded: morph targets, cameras, lights, other texture
// slots, non-triangle primitives (skipped with no error).
//
// Failure: truncated, garbage or inconsistent files (bad accessor bounds, out-of-range indices,
// NaN positions, non-increasing key times) give an Error with the field at fault; never a crash.
#pragma once

#include "core/model.hpp"
#include "core/result.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace dermis {

/// Encoded images captured by parseGltf, consumed by loadGltfResources.
struct PendingImages {
    struct Entry {
        int imageIndex = -1;            ///< index in Model::images
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

/// Step 2. Decodes every pending image to RGBA8 (OpenImageIO). A corrupt image is an error.
Status loadGltfResources(ParsedGltf& parsed);

/// Both steps for a file on disk.
Result<Model> loadGltfFile(const std::string& path);

} // namespace dermis
