// Skin pass, tessellated displacement: interpolates the skinned triangle and displaces every
// generated vertex along its interpolated normal by the displacement map.
layout(triangles, equal_spacing, ccw) in;

in vec3 tc_position[];
in vec3 tc_normal[];
in vec2 tc_uv[];
in vec2 tc_mapUv[];
in vec3 tc_restPosition[];
in vec3 tc_restNormal[];
#ifdef DERMIS_PBR
in vec4 tc_tangent[];
in vec2 tc_uv1[];
in vec4 tc_color[];
out vec4 v_tangent;
out vec2 v_uv1;
out vec4 v_color;
#endif

layout(binding = 0) uniform sampler2D u_heightMap; // RG32F: bump, displacement

out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv;
out vec2 v_mapUv;
out vec3 v_restPosition;
out vec3 v_restNormal;

void main() {
    vec3 b = gl_TessCoord;
    vec3 p = b.x * tc_position[0] + b.y * tc_position[1] + b.z * tc_position[2];
    vec3 n = normalize(b.x * tc_normal[0] + b.y * tc_normal[1] + b.z * tc_normal[2]);
    vec2 uv = b.x * tc_uv[0] + b.y * tc_uv[1] + b.z * tc_uv[2];
    vec2 mapUv = b.x * tc_mapUv[0] + b.y * tc_mapUv[1] + b.z * tc_mapUv[2];
    if (u_part.z != 0) p += n * (textureLod(u_heightMap, mapUv, 0.0).g * u_heights.x);
    v_position = p;
    v_normal = n;
    v_uv = uv;
    v_mapUv = mapUv;
    v_restPosition = b.x * tc_restPosition[0] + b.y * tc_restPosition[1] + b.z * tc_restPosition[2];
    v_restNormal = b.x * tc_restNormal[0] + b.y * tc_restNormal[1] + b.z * tc_restNormal[2];
#ifdef DERMIS_PBR
    v_tangent = vec4(b.x * tc_tangent[0].xyz + b.y * tc_tangent[1].xyz + b.z * tc_tangent[2].xyz,
                     tc_tangent[0].w);
    v_uv1 = b.x * tc_uv1[0] + b.y * tc_uv1[1] + b.z * tc_uv1[2];
    v_color = b.x * tc_color[0] + b.y * tc_color[1] + b.z * tc_color[2];
#endif
    gl_Position = u_viewProj * vec4(p, 1.0);
}
