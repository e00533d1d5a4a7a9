// Skin pass (paper §4 stage 2), vertex stage: linear blend skinning (the paper's SSD) with the
// joint palette in a shader storage buffer (any joint count), then — in the "vertex"
// displacement variant — displacement along the skinned normal by the displacement map.
// Variants: DERMIS_TESSELLATED (displacement moves to skin.tese), DERMIS_CAPTURE (outputs the
// undisplaced skinned vertex for transform feedback; no later stages).

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in uvec4 a_joints;
layout(location = 4) in vec4 a_weights;
layout(location = 5) in vec2 a_mapUv; // the height maps' layout (SPEC §8); a_uv keeps the model's
#ifdef DERMIS_PBR
layout(location = 6) in vec4 a_tangent; // TANGENT (u_maps.z & 2), bind space
layout(location = 7) in vec2 a_uv1;     // TEXCOORD_1 (zero when the model has none)
layout(location = 8) in vec4 a_color;   // COLOR_0 (u_maps.z & 4)
#endif

// world(node_k) · inverseBind_k of every influence of every part; a part starts at u_part.x.
layout(std430, binding = 0) readonly buffer Palette {
    mat4 u_palette[];
};

layout(binding = 0) uniform sampler2D u_heightMap; // RG32F in the layout's UV space: bump, displacement

out vec3 v_position; // world space
out vec3 v_normal;   // world space, unit
out vec2 v_uv;    // the model's TEXCOORD_0: base colour
out vec2 v_mapUv; // the height-map layout's UV: bump, displacement, outlines
out vec3 v_restPosition; // bind space (the rest surface, SPEC §8): surface decal outlines
out vec3 v_restNormal;   // bind space, not normalised
#ifdef DERMIS_PBR
out vec4 v_tangent; // world space xyz (not normalised), w the bitangent's sign
out vec2 v_uv1;
out vec4 v_color;
#endif

void main() {
    int base = u_part.x;
    // Σ w_k · J_k, the blended matrix (same sum as dermis::skin on the CPU).
    mat4 m = a_weights.x * u_palette[base + int(a_joints.x)] +
             a_weights.y * u_palette[base + int(a_joints.y)] +
             a_weights.z * u_palette[base + int(a_joints.z)] +
             a_weights.w * u_palette[base + int(a_joints.w)];
    vec3 p = (m * vec4(a_position, 1.0)).xyz;
    vec3 n = normalize(transpose(inverse(mat3(m))) * a_normal);
    v_uv = a_uv;
    v_mapUv = a_mapUv;
    v_restPosition = a_position;
    v_restNormal = a_normal;
#ifdef DERMIS_PBR
    v_tangent = vec4(mat3(m) * a_tangent.xyz, a_tangent.w);
    v_uv1 = a_uv1;
    v_color = a_color;
#endif
#if !defined(DERMIS_TESSELLATED) && !defined(DERMIS_CAPTURE)
    if (u_part.z != 0) p += n * (textureLod(u_heightMap, a_mapUv, 0.0).g * u_heights.x);
#endif
    v_position = p;
    v_normal = n;
#if !defined(DERMIS_TESSELLATED) && !defined(DERMIS_CAPTURE)
    gl_Position = u_viewProj * vec4(p, 1.0);
#endif
}
