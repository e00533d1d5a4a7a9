// Height pass (paper §4 stage 1): L_out of one placement at this texel (SPEC §2), written to the
// red (bump) or green (displacement) channel of the RG32F height target; additive blending sums
// placements. Variant DERMIS_SURFACE: a surface placement (SPEC §8), its pattern coordinate from
// the rest-surface map instead of the footprint.

layout(binding = 0) uniform sampler2D u_pattern; // R32F, values L ∈ [−1, 1], row 0 = s.y near 0
#ifdef DERMIS_SURFACE
// The layout's rest-surface map (dermis::RestSurfaceMap), one texel per height-map texel.
layout(binding = 1) uniform sampler2D u_restPosition; // RGB32F bind-space position
layout(binding = 2) uniform sampler2D u_restNormal;   // RGB32F unit normal, 0 where uncovered
#endif

layout(location = 0) out vec2 o_heights; // bump, displacement

// Bilinear sample at s ∈ [0,1]² with texel centres at (k+0.5)/N, clamped to the edge texels —
// the same arithmetic as dermis::sampleBilinear (texelFetch: no filtering precision loss).
float samplePattern(vec2 s) {
    ivec2 n = ivec2(u_mapSize.zw);
    vec2 x = s * vec2(n) - 0.5;
    vec2 f0 = floor(x);
    vec2 f = x - f0;
    ivec2 i0 = clamp(ivec2(f0), ivec2(0), n - 1);
    ivec2 i1 = clamp(ivec2(f0) + 1, ivec2(0), n - 1);
    float a = texelFetch(u_pattern, ivec2(i0.x, i0.y), 0).r;
    float b = texelFetch(u_pattern, ivec2(i1.x, i0.y), 0).r;
    float c = texelFetch(u_pattern, ivec2(i0.x, i1.y), 0).r;
    float d = texelFetch(u_pattern, ivec2(i1.x, i1.y), 0).r;
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

void main() {
#ifdef DERMIS_SURFACE
    // SPEC §8: the decal at this texel's rest-surface point p (normal n_p):
    // s = (((p − c)·t)/w + ½, ((p − c)·b)/h + ½); nothing where |(p − c)·n| > depth, n_p·n ≤ 0
    // (uncovered texels have n_p = 0) or s outside [0, 1]² — dermis::SurfaceFrame::toPattern.
    ivec2 texel = ivec2(gl_FragCoord.xy);
    vec3 p = texelFetch(u_restPosition, texel, 0).xyz;
    vec3 np = texelFetch(u_restNormal, texel, 0).xyz;
    if (!(dot(np, u_anchorNormal.xyz) > 0.0)) discard;
    vec3 dp = p - u_anchor.xyz;
    if (abs(dot(dp, u_anchorNormal.xyz)) > u_anchor.w) discard;
    vec2 s = vec2(dot(dp, u_anchorTangent.xyz) * u_anchorNormal.w + 0.5,
                  dot(dp, u_anchorBinormal.xyz) * u_anchorTangent.w + 0.5);
#else
    vec2 uv = gl_FragCoord.xy / u_mapSize.xy;
    vec2 d = uv - u_centerScale.xy;
    float c = u_rotation.x, sn = u_rotation.y;
    // s = R(−rotation)·(p − center)/scale + 0.5 (SPEC "Conventions").
    vec2 s = vec2(c * d.x + sn * d.y, -sn * d.x + c * d.y) / u_centerScale.zw + 0.5;
#endif
    if (any(lessThan(s, vec2(0.0))) || any(greaterThan(s, vec2(1.0)))) discard;

    float L = samplePattern(s);
    // u_drive.z: gain(t) (scale) or offset(t) (bias) of SPEC §2's table, computed once per
    // placement on the CPU (dermis::deformConstant) instead of a log per fragment.
    float h = u_drive.x, t = u_drive.y, k = u_drive.z;
    float value;
    if (t <= 0.0) {
        value = 0.0;
    } else if (t >= 1.0) {
        value = L * h;                                        // both models at t = 1
    } else if (u_mode.x == 0) {
        value = L * h * k;                                    // scale model, paper eq. 1
    } else {
        value = max(h * (L - k), 0.0);                        // bias model, paper eq. 2
    }
    o_heights = u_mode.y == 0 ? vec2(value, 0.0) : vec2(0.0, value);
}
