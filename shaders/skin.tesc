// Skin pass, tessellated displacement (beyond the paper): each edge is split so that its pieces
// are about u_viewport.z pixels long on screen (at most u_viewport.w pieces). Edge levels depend
// only on the edge's own end points, so neighbouring triangles agree and no cracks open.
layout(vertices = 3) out;

in vec3 v_position[];
in vec3 v_normal[];
in vec2 v_uv[];
in vec2 v_mapUv[];
in vec3 v_restPosition[];
in vec3 v_restNormal[];
out vec3 tc_position[];
out vec3 tc_normal[];
out vec2 tc_uv[];
out vec2 tc_mapUv[];
out vec3 tc_restPosition[];
out vec3 tc_restNormal[];
#ifdef DERMIS_PBR
in vec4 v_tangent[];
in vec2 v_uv1[];
in vec4 v_color[];
out vec4 tc_tangent[];
out vec2 tc_uv1[];
out vec4 tc_color[];
#endif

vec2 toScreen(vec3 p) {
    vec4 c = u_viewProj * vec4(p, 1.0);
    return c.xy / max(c.w, 1e-6) * 0.5 * u_viewport.xy;
}

float edgeLevel(int a, int b) {
    float len = distance(toScreen(v_position[a]), toScreen(v_position[b]));
    return clamp(len / u_viewport.z, 1.0, u_viewport.w);
}

void main() {
    tc_position[gl_InvocationID] = v_position[gl_InvocationID];
    tc_normal[gl_InvocationID] = v_normal[gl_InvocationID];
    tc_uv[gl_InvocationID] = v_uv[gl_InvocationID];
    tc_mapUv[gl_InvocationID] = v_mapUv[gl_InvocationID];
    tc_restPosition[gl_InvocationID] = v_restPosition[gl_InvocationID];
    tc_restNormal[gl_InvocationID] = v_restNormal[gl_InvocationID];
#ifdef DERMIS_PBR
    tc_tangent[gl_InvocationID] = v_tangent[gl_InvocationID];
    tc_uv1[gl_InvocationID] = v_uv1[gl_InvocationID];
    tc_color[gl_InvocationID] = v_color[gl_InvocationID];
#endif
    if (gl_InvocationID == 0) {
        // Outer level i is the edge opposite corner i.
        gl_TessLevelOuter[0] = edgeLevel(1, 2);
        gl_TessLevelOuter[1] = edgeLevel(2, 0);
        gl_TessLevelOuter[2] = edgeLevel(0, 1);
        gl_TessLevelInner[0] = max(gl_TessLevelOuter[0], max(gl_TessLevelOuter[1], gl_TessLevelOuter[2]));
    }
}
