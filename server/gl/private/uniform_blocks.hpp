// Dermis GL shell — C++ mirrors of the std140 uniform blocks declared in shaders/common.glsl.
//
// Plain structs with the GLSL block's member order and std140 offsets (every member here is a
// vec4, ivec4 or mat4, so each starts on a 16-byte boundary and the struct has no padding).
// UniformBlockGLTest compares sizeof/offsetof with what the GL reports for the linked programs;
// change both sides together. No GL includes: the renderer uploads these with glBufferSubData.
#pragma once

#include <glm/glm.hpp>

#include <cstddef>

namespace dermis::gl {

/// HeightPassBlock, binding 0: one placement of the height pass.
struct HeightPassBlock {
    glm::vec4 centerScale; ///< centre u, v; size u, v — surface: the UV rectangle u0, v0, u1, v1
    glm::vec4 rotation;    ///< cos, sin, quad margin in pattern units (x, y)
    glm::vec4 drive;       ///< h, t, deformConstant(model, response, t), 0
    glm::ivec4 mode;       ///< model (0 scale, 1 bias), target (0 bump, 1 displacement), response,
                           ///< projection (0 uv, 1 surface)
    glm::vec4 mapSize;     ///< map width, height; pattern width, height
    // Surface placements (SPEC §8, dermis::SurfaceFrame):
    glm::vec4 anchor;         ///< anchor position c, depth
    glm::vec4 anchorNormal;   ///< n, 1/w
    glm::vec4 anchorTangent;  ///< t (rotation applied), 1/h
    glm::vec4 anchorBinormal; ///< b = n × t, 0
};

/// FrameBlock, binding 1: per-frame constants of the skin pass.
struct FrameBlock {
    glm::mat4 viewProj;
    glm::vec4 cameraPos;
    glm::vec4 lightDir;      ///< xyz towards the light, w ambient level
    glm::vec4 heights;       ///< displacement scale, bump scale, 0, 0
    glm::vec4 heightmapSize; ///< width, height, 1/width, 1/height
    glm::vec4 viewport;      ///< width, height, tessellation edge target (px), max level
};

/// PartBlock, binding 2: per-part constants of the skin pass.
struct PartBlock {
    glm::vec4 baseColor;
    /// first palette matrix, has a base-colour texture and UVs to sample it, has height-map UVs
    /// (the layout in use covers the part), view (FrameView as int)
    glm::ivec4 part;
    // glTF metallic-roughness (the DERMIS_PBR programs):
    glm::vec4 emissive; ///< emissive factor, alpha cutoff
    glm::vec4 material; ///< metallic, roughness, normal scale, occlusion strength
    /// textures present (kMap* bits), alpha mode (0 opaque, 1 mask, 2 blend), flags (kPart*
    /// bits), UV set per texture (bit k: texture k reads TEXCOORD_1)
    glm::ivec4 maps;
    glm::vec4 uvTransform[10]; ///< per texture two rows of its KHR_texture_transform matrix
    /// morph targets of the part, first weight in the MorphWeights buffer, vertex count, 0
    glm::ivec4 morph;
};

/// PartBlock::maps.x bits, in the texture order of uvTransform and maps.w.
enum MaterialMapBit : int {
    kMapBaseColor = 1,
    kMapMetallicRoughness = 2,
    kMapNormal = 4,
    kMapOcclusion = 8,
    kMapEmissive = 16,
};
/// PartBlock::maps.z bits.
enum PartFlagBit : int { kPartUnlit = 1, kPartTangents = 2, kPartColors = 4 };

/// EnvironmentBlock, binding 4: the image-based light of the DERMIS_PBR programs.
struct EnvironmentBlock {
    glm::vec4 irradianceSh[9]; ///< rgb coefficients of E(n)/π, order of core/environment.hpp
    glm::vec4 params;          ///< exposure, cos(rotation), sin(rotation), last specular level
    glm::ivec4 mode;           ///< tone mapping (0 none, 1 PBR Neutral, 2 ACES filmic), 0, 0, 0
};

/// KeyLightBlock, binding 5: the directional key light of the DERMIS_KEY_LIGHT programs
/// (pbr.glsl; render.key_light).
struct KeyLightBlock {
    glm::mat4 shadowViewProj; ///< world → shadow map clip space (core/key_light.hpp)
    glm::vec4 direction;      ///< unit, towards the light; w 1 with a shadow map, else 0
    glm::vec4 radiance;       ///< colour × intensity, 0
    glm::vec4 shadowParams;   ///< normal offset (world), depth bias (map depth), 1 / map size, 0
};

/// OutlineBlock, binding 3: the outlines of a frame's skin pass (FrameOutline in renderer.hpp).
struct OutlineBlock {
    glm::ivec4 count;        ///< outlines in use (0..kOutlineSlots), 0, 0, 0
    glm::vec4 rect[8];       ///< centre u, v; size u, v
    glm::vec4 style[8];      ///< cos(rotation), sin(rotation), kind (0 selected, 1 hovered, 2 brush), shape
    glm::vec4 anchor[8];     ///< surface shapes: anchor position (bind space), depth
    glm::vec4 axisU[8];      ///< surface shapes: tangent / width, 0
    glm::vec4 axisV[8];      ///< surface shapes: (normal × tangent) / height, 0
};
inline constexpr int kOutlineSlots = 8; ///< the GLSL arrays' length (= dermis::kMaxFrameOutlines)

/// GLSL binding points of the blocks above and of the palette storage buffer.
enum BlockBinding : unsigned {
    kHeightPassBinding = 0,
    kFrameBinding = 1,
    kPartBinding = 2,
    kOutlineBinding = 3,
    kEnvironmentBinding = 4,
    kKeyLightBinding = 5,
    kPaletteBinding = 0,      // shader storage buffer bindings: the joint palette,
    kMorphDeltaBinding = 1,   // the drawn part's morph deltas,
    kMorphWeightBinding = 2,  // the frame's morph weights
};

static_assert(sizeof(glm::vec4) == 16 && sizeof(glm::mat4) == 64);
static_assert(sizeof(HeightPassBlock) == 144);
static_assert(sizeof(FrameBlock) == 144);
static_assert(sizeof(PartBlock) == 32 + 3 * 16 + 10 * 16 + 16);
static_assert(sizeof(EnvironmentBlock) == 9 * 16 + 2 * 16);
static_assert(sizeof(KeyLightBlock) == 64 + 3 * 16);
static_assert(sizeof(OutlineBlock) == 16 + 5 * 8 * 16);

} // namespace dermis::gl
