// Dermis core — a skinned character in memory: node hierarchy, joints, mesh parts, clips.
//
// Plain data, filled by a loader shell (server/io/gltf_loader) or built by hand in tests. The core
// never reads files: a Model owns decoded data only. Conventions follow glTF 2.0: right-handed,
// metres, quaternions [x, y, z, w] (glm::quat stores w, x, y, z — use glm::quat(w, x, y, z)),
// column-major matrices, UV (0,0) at the first pixel of the first image row.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace dermis {

/// One node of the glTF scene hierarchy, in rest (non-animated) local TRS.
struct Node {
    std::string name;   ///< may be empty for unnamed nodes
    int parent = -1;    ///< index into Model::nodes, −1 for a root
    glm::vec3 translation{0.0f};
    glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f}; ///< glm order (w, x, y, z)
    glm::vec3 scale{1.0f};
};

/// One influence of a mesh part: the node whose world matrix moves the vertices, and the matrix
/// taking the part's bind-space positions into that node's local space.
struct Influence {
    int node = -1;
    glm::mat4 inverseBind{1.0f};
};

/// One morph target of a mesh part (glTF 2.0 §3.7.2.2): displacements added to the part's
/// bind-space attributes, scaled by the weight of Model::morphWeights[weight]:
///   p = p₀ + Σ w_k·Δp_k,  n = normalize(n₀ + Σ w_k·Δn_k),  t = normalize(t₀ + Σ w_k·Δt_k)
/// (core/rig.hpp morphPart; skin.vert on the GPU). Each array is empty or has one entry per vertex
/// of the part; a rigid part's deltas are in its rest world space like its positions.
struct MorphTarget {
    int weight = -1; ///< index into Model::morphWeights
    std::vector<glm::vec3> positions, normals, tangents;
};

/// One morph weight of the model: target k of the mesh a node instances (glTF keeps the weights
/// per node, `node.weights` else `mesh.weights`; animations drive them by node). Parts of the
/// same node instance share their weights.
struct MorphWeight {
    std::string name; ///< mesh.extras.targetNames[k], else "<mesh name>#<k>"
    int node = -1;    ///< the node that instances the mesh
    float rest = 0.0f; ///< the default weight
};

/// One triangle list (a glTF primitive). Skinned primitives keep glTF's bind space; a rigid mesh
/// attached to node N is stored as a one-influence skin: positions in rest world space and
/// inverseBind = inverse(restWorld(N)), so skinning with the posed world matrix moves it rigidly.
struct MeshPart {
    std::string name;                     ///< the glTF mesh's name, else its node's ("#k" per primitive)
    std::string node;                     ///< the name of the glTF node that instances the mesh ("" if none)
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;       ///< unit; computed (area-weighted) when the file has none
    std::vector<glm::vec2> uvs;           ///< TEXCOORD_0; empty when the file has none
    std::vector<glm::vec2> uvs1;          ///< TEXCOORD_1; empty when the file has none
    /// TANGENT: unit xyz, w = ±1 the bitangent's sign (b = w·n × t). A normal-mapped part whose
    /// file has none gets MikkTSpace tangents on load (core/tangents.hpp, tangentsGenerated);
    /// empty otherwise (the shading then builds the frame per pixel from the UV derivatives).
    std::vector<glm::vec4> tangents;
    bool tangentsGenerated = false; ///< `tangents` were generated on load, not read from the file
    std::vector<glm::vec4> colors;        ///< COLOR_0 as linear RGBA; empty when the file has none
    std::vector<glm::u16vec4> joints;     ///< indices into `influences`, one per vertex
    std::vector<glm::vec4> weights;       ///< normalised (sum 1), one per vertex
    std::vector<std::uint32_t> indices;   ///< triangle list, 3 per triangle
    std::vector<Influence> influences;
    int material = -1;                    ///< index into Model::materials, −1 for none
    /// glTF morph targets of the primitive (§3.7.2.2), applied in bind space before skinning.
    std::vector<MorphTarget> morphs;
};

/// An RGBA8 image, row 0 first.
struct Image8 {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba; ///< width·height·4 bytes
};

/// Which UV set a material's texture reads and its KHR_texture_transform:
/// uv' = offset + R(rotation)·(scale ∘ uv), R rotating by `rotation` radians counter-clockwise in
/// the extension's sense (glTF: T·R·S; a point (1, 0) scaled by 1 goes to (cos r, −sin r)).
struct TextureUv {
    int texCoord = 0; ///< 0: MeshPart::uvs (TEXCOORD_0), 1: MeshPart::uvs1 (TEXCOORD_1)
    glm::vec2 offset{0.0f};
    glm::vec2 scale{1.0f};
    float rotation = 0.0f;
    /// The 3×3 matrix of the transform (column-major, applied to (u, v, 1)).
    glm::mat3 matrix() const;
    bool operator==(const TextureUv&) const = default;
};

/// glTF 2.0 §3.9.4 alpha modes.
enum class AlphaMode { Opaque, Mask, Blend };

/// A glTF 2.0 metallic-roughness material (§3.9) with KHR_materials_emissive_strength and
/// KHR_materials_unlit. Texture members are indices into Model::images (−1 for none); the images
/// are plain RGBA8: base colour and emissive hold sRGB-encoded colour, the others linear data
/// (metallic in B, roughness in G; occlusion in R; the normal map's xyz in RGB). Every value is as
/// the file gives it, checked to be finite; the shading clamps ranges.
struct Material {
    std::string name;
    glm::vec4 baseColorFactor{1.0f};
    int baseColorTexture = -1; ///< index into Model::images, −1 for none
    TextureUv baseColorUv;
    float metallicFactor = 1.0f;
    float roughnessFactor = 1.0f;
    int metallicRoughnessTexture = -1;
    TextureUv metallicRoughnessUv;
    int normalTexture = -1; ///< tangent space, OpenGL convention (+Y up in the image)
    float normalScale = 1.0f;
    TextureUv normalUv;
    int occlusionTexture = -1;
    float occlusionStrength = 1.0f;
    TextureUv occlusionUv;
    glm::vec3 emissiveFactor{0.0f}; ///< times KHR_materials_emissive_strength
    int emissiveTexture = -1;
    TextureUv emissiveUv;
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f;
    bool doubleSided = false;
    bool unlit = false; ///< KHR_materials_unlit: base colour only
};

enum class Interpolation { Linear, Step, CubicSpline };
enum class ChannelPath { Translation, Rotation, Scale, Weights };

/// One animation channel. `values` holds, per key, 3 (T, S), 4 (R, x y z w) or `morphCount`
/// (Weights) floats; for CubicSpline each key holds in-tangent, value, out-tangent (3 groups), as
/// in glTF.
struct Channel {
    int node = -1;
    ChannelPath path = ChannelPath::Rotation;
    /// Weights: the node's morph weights are Model::morphWeights[morphFirst, morphFirst + morphCount)
    int morphFirst = -1, morphCount = 0;
    Interpolation interpolation = Interpolation::Linear;
    std::vector<float> times; ///< strictly increasing seconds
    std::vector<float> values;
};

struct Clip {
    std::string name;
    float duration = 0.0f; ///< last key time over all channels (start is 0)
    std::vector<Channel> channels;
};

struct Model {
    std::vector<Node> nodes;
    std::vector<int> joints;  ///< node indices that are joints of a skin, in first-seen order
    std::vector<MeshPart> parts;
    std::vector<Material> materials;
    std::vector<Image8> images;
    std::vector<Clip> clips;
    std::vector<MorphWeight> morphWeights; ///< every morph weight (MorphTarget::weight)

    bool hasUVs() const;        ///< every part has TEXCOORD_0 (false for a model without parts)
    std::size_t triangleCount() const;
    /// Index into `nodes` of the joint named `name` (joints only), −1 if none.
    int findJoint(const std::string& name) const;
    /// Index into `clips` of the clip named `name`, −1 if none.
    int findClip(const std::string& name) const;
    /// The nearest ancestor of node `node` that is a joint (skipping non-joint nodes between
    /// them), −1 for none or an index out of range.
    int parentJoint(int node) const;
    /// The base-colour image of the model, for pictures of its texture space: the index into
    /// `images` that covers the most triangles, counting each part's triangles for the image its
    /// material names as baseColorTexture (two materials sharing an image add up; parts without a
    /// material or texture count for none); ties go to the lower image index. −1 when no triangle
    /// has a base-colour texture (none named, an index out of range or an empty image).
    int dominantBaseColorImage() const;
};

/// Area-weighted vertex normals of a triangle list: each triangle adds its unnormalised face
/// normal (counter-clockwise winding, glTF's front face) to its corners, then each sum is
/// normalised. Vertices on no (or only degenerate) triangles get (0, 0, 1). Triangles with an index
/// out of range are ignored. Returns one unit normal per position.
std::vector<glm::vec3> computeNormals(const std::vector<glm::vec3>& positions,
                                      const std::vector<std::uint32_t>& indices);

} // namespace dermis
