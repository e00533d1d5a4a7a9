// Depth only, for two passes: the key light's shadow map (`render.key_light`,
// core/render_settings.hpp KeyLight), drawn from the light (core/key_light.hpp shadowCamera), and
// the skin pass's depth prepass, drawn from the frame's camera (frame_pass.cpp drawSkinPass). By
// skin.vert with DERMIS_PBR, so that a part is skinned, morphed and displaced as the frame draws
// it (vertex displacement even when the frame is tessellated; the prepass is not drawn for
// tessellated frames). pbr.glsl comes before this file (materialUv, hasMap). Two programs: without
// DERMIS_MASK, for opaque parts, it writes every fragment and runs no code — so that a software
// rasterizer tests and writes depth before shading and reads no texture (with the alpha test in
// the program llvmpipe ran it, base colour lookup included, for every fragment of every part:
// 16 % of a range frame's CPU); with DERMIS_MASK, for glTF MASK parts (u_maps.y 1), it writes
// where the alpha reaches the cutoff, as skin.frag draws it. The renderer draws no BLEND parts
// into either.

layout(binding = 2) uniform sampler2D u_baseColorTexture; // sRGB8_A8: only its alpha is read

in vec2 v_uv;
in vec2 v_uv1;
in vec4 v_color;

void main() {
#ifdef DERMIS_MASK
    float alpha = u_baseColor.a;
    if ((u_maps.z & 4) != 0) alpha *= v_color.a;
    if (hasMap(1)) alpha *= texture(u_baseColorTexture, materialUv(0, v_uv, v_uv1)).a;
    if (alpha < u_emissive.w) discard;
#endif
}
