// Skin pass, tessellated displacement: interpolates the skinned triangle and displaces every
// generated vertex along its interpolated normal by the displacement map.
layout(triangles, equal_spacing, ccw) in;

in vec3 tc_position[];
in vec3 tc_normal[];
in vec2 tc_uv[];
in vec2 tc_mapUv[];

layout(binding = 0) uniform sampler2D u_heightMap; // RG32F: bump, displacement

out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv;
out vec2 v_mapUv;

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
    gl_Position = u_viewProj * vec4(p, 1.0);
}
