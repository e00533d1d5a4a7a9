// Dermis — declarations shared by every program. Prepended after "#version" and the variant
// #defines by the renderer (server/gl/programs.cpp). Each uniform block here has a C++ mirror in
// server/gl/private/uniform_blocks.hpp with the same std140 layout; UniformBlockGLTest checks it.

// Per-placement constants of the height pass (paper §4 stage 1; SPEC §2; surface placements
// SPEC §8).
layout(std140, binding = 0) uniform HeightPassBlock {
    vec4 u_centerScale;  // UV placement: footprint centre (u, v), footprint size (u, v) in UV
                         // units; surface placement: the UV rectangle drawn (u0, v0, u1, v1)
    vec4 u_rotation;     // cos(rotation), sin(rotation), quad margin (s units, x and y)
    vec4 u_drive;        // h, t, gain(t) or offset(t) (dermis::deformConstant), 0
    ivec4 u_mode;        // model (0 scale, 1 bias), target (0 bump, 1 displacement), response,
                         // projection (0 uv, 1 surface)
    vec4 u_mapSize;      // map width, height, pattern width, height (texels)
    vec4 u_anchor;       // surface: anchor position c (bind space), depth
    vec4 u_anchorNormal; // surface: unit normal n, 1/w
    vec4 u_anchorTangent; // surface: unit tangent t (rotation applied), 1/h
    vec4 u_anchorBinormal; // surface: b = n × t, 0
};

// Per-frame constants of the skin pass (paper §4 stage 2).
layout(std140, binding = 1) uniform FrameBlock {
    mat4 u_viewProj;       // world → clip (picture row 0 at the top)
    vec4 u_cameraPos;      // world camera position, 0
    vec4 u_lightDir;       // unit vector towards the key light (world), ambient level
    vec4 u_heights;        // displacement scale, bump scale (model units per height unit), 0, 0
    vec4 u_heightmapSize;  // width, height, 1/width, 1/height of the height maps
    vec4 u_viewport;       // frame width, height, target edge length of a tessellated edge (px), max level
};

// Outlines on the skin (the editor's selection, hover and place brush), drawn as a band where the
// surface lies on their border. Shape (u_outlineStyle.w): 0 a UV footprint rectangle in the
// height maps' layout (SPEC §2: centre, size, rotation; v_mapUv), 1 a surface decal's rectangle on
// the rest surface (SPEC §8: the anchor frame, v_restPosition), 2 a circle on the rest surface (the
// surface place brush: the decal frame with size = the diameter).
layout(std140, binding = 3) uniform OutlineBlock {
    ivec4 u_outlineCount;    // outlines in use (0..8), 0, 0, 0
    vec4 u_outlineRect[8];   // shape 0: centre u, v; size u, v
    vec4 u_outlineStyle[8];  // cos(rotation), sin(rotation), kind (0 selected, 1 hovered, 2 brush), shape
    vec4 u_outlineAnchor[8]; // shapes 1, 2: anchor position (bind space), depth
    vec4 u_outlineAxisU[8];  // shapes 1, 2: tangent / width (rotation applied), 0
    vec4 u_outlineAxisV[8];  // shapes 1, 2: (normal × tangent) / height, 0
};

// Per-part constants of the skin pass.
layout(std140, binding = 2) uniform PartBlock {
    vec4 u_baseColor;  // material base colour factor (linear)
    ivec4 u_part;      // first palette matrix of the part, has a base-colour texture and the
                       // model's UVs to sample it (a_uv), has height-map UVs (a_mapUv: the
                       // layout in use covers the part), view (0 shaded, 1 bump, 2 displacement,
                       // 3 normal: FrameView in server/core/render_settings.hpp; the same for
                       // every part of a frame)
    // glTF metallic-roughness (DERMIS_PBR programs only; core/model.hpp Material):
    vec4 u_emissive;   // emissive factor (× KHR_materials_emissive_strength), alpha cutoff
    vec4 u_material;   // metallic, roughness, normal scale, occlusion strength
    ivec4 u_maps;      // textures present (bits: 1 base colour, 2 metallic-roughness, 4 normal,
                       // 8 occlusion, 16 emissive), alpha mode (0 opaque, 1 mask, 2 blend),
                       // flags (1 unlit, 2 vertex tangents, 4 vertex colours), UV set (bit k
                       // set: texture k of the order above reads TEXCOORD_1)
    vec4 u_uvTransform[10]; // per texture (same order) two rows of its KHR_texture_transform:
                            // uv' = (dot(row0.xyz, (uv, 1)), dot(row1.xyz, (uv, 1)))
    ivec4 u_morph;     // morph targets of the part, its first weight in u_morphWeights, vertex
                       // count, 0 (skin.vert)
};

// Image-based light of the DERMIS_PBR programs (core/environment.hpp): the environment's
// irradiance as order-2 spherical harmonics, its GGX-prefiltered radiance (u_envSpecular, one
// mip level per roughness step) and the split-sum table (u_brdfLut).
layout(std140, binding = 4) uniform EnvironmentBlock {
    vec4 u_irradianceSh[9]; // rgb coefficients of E(n)/π (evalIrradiance)
    vec4 u_envParams;       // exposure, cos(rotation), sin(rotation), last specular level
    ivec4 u_envMode;        // tone mapping (0 none, 1 Khronos PBR Neutral, 2 ACES filmic), 0, 0, 0
};
