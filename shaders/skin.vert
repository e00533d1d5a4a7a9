// Skin pass (paper §4 stage 2), vertex stage: the model's morph targets, then linear blend
// skinning (the paper's SSD) with the joint palette in a shader storage buffer (any joint
// count), then — in the "vertex" displacement variant — displacement along the skinned normal by
// the displacement map.
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

// glTF morph targets (core/model.hpp MorphTarget), applied in bind space before skinning: the
// drawn part's deltas, per target k and vertex v three vec4 at ((k·nv + v)·3) — position,
// normal, tangent — and the frame's weights, the part's starting at u_morph.y.
layout(std430, binding = 1) readonly buffer MorphDeltas {
    vec4 u_morphDeltas[];
};
layout(std430, binding = 2) readonly buffer MorphWeights {
    float u_morphWeights[];
};

layout(binding = 0) uniform sampler2D u_heightMap; // RG32F in the layout's UV space: bump, displacement

#if !defined(DERMIS_TESSELLATED) && !defined(DERMIS_CAPTURE)
// The skin pass's depth prepass draws with another program (shadow.frag's) and the shading pass
// keeps only the fragments at exactly its depths (GL_EQUAL): both must compute the same
// positions, whatever their other outputs let a compiler do.
invariant gl_Position;
#endif

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
    // Morph targets (dermis::morphPart): p + Σ w·Δp; normal and tangent renormalised, kept when
    // the sum vanishes.
    vec3 position = a_position;
    vec3 normal = a_normal;
#ifdef DERMIS_PBR
    vec4 tangent = a_tangent;
#endif
    if (u_morph.x > 0) {
        vec3 dn = vec3(0.0);
#ifdef DERMIS_PBR
        vec3 dt = vec3(0.0);
#endif
        for (int k = 0; k < u_morph.x; ++k) {
            float w = u_morphWeights[u_morph.y + k];
            if (w == 0.0) continue;
            int i = (k * u_morph.z + gl_VertexID) * 3;
            position += w * u_morphDeltas[i].xyz;
            dn += w * u_morphDeltas[i + 1].xyz;
#ifdef DERMIS_PBR
            dt += w * u_morphDeltas[i + 2].xyz;
#endif
        }
        vec3 nSum = normal + dn;
        if (dot(nSum, nSum) > 0.0) normal = normalize(nSum);
#ifdef DERMIS_PBR
        vec3 tSum = tangent.xyz + dt;
        if (dot(tSum, tSum) > 0.0) tangent.xyz = normalize(tSum);
#endif
    }
    int base = u_part.x;
    // Σ w_k · J_k, the blended matrix (same sum as dermis::skin on the CPU).
    mat4 m = a_weights.x * u_palette[base + int(a_joints.x)] +
             a_weights.y * u_palette[base + int(a_joints.y)] +
             a_weights.z * u_palette[base + int(a_joints.z)] +
             a_weights.w * u_palette[base + int(a_joints.w)];
    vec3 p = (m * vec4(position, 1.0)).xyz;
    vec3 n = normalize(transpose(inverse(mat3(m))) * normal);
    v_uv = a_uv;
    v_mapUv = a_mapUv;
    v_restPosition = a_position;
    v_restNormal = a_normal;
#ifdef DERMIS_PBR
    v_tangent = vec4(mat3(m) * tangent.xyz, tangent.w);
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
