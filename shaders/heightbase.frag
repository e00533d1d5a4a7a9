// Height pass, first draw: the character's static height map (paper §5) into the bump (red)
// channel, bilinear at texel centres (exact copy when the sizes match), zero displacement (green).

layout(binding = 0) uniform sampler2D u_base; // R32F

layout(location = 0) out vec2 o_heights; // bump, displacement

void main() {
    ivec2 n = textureSize(u_base, 0);
    vec2 s = gl_FragCoord.xy / u_mapSize.xy;
    vec2 x = s * vec2(n) - 0.5;
    vec2 f0 = floor(x);
    vec2 f = x - f0;
    ivec2 i0 = clamp(ivec2(f0), ivec2(0), n - 1);
    ivec2 i1 = clamp(ivec2(f0) + 1, ivec2(0), n - 1);
    float a = texelFetch(u_base, ivec2(i0.x, i0.y), 0).r;
    float b = texelFetch(u_base, ivec2(i1.x, i0.y), 0).r;
    float c = texelFetch(u_base, ivec2(i0.x, i1.y), 0).r;
    float d = texelFetch(u_base, ivec2(i1.x, i1.y), 0).r;
    o_heights = vec2(mix(mix(a, b, f.x), mix(c, d, f.x), f.y), 0.0);
}
