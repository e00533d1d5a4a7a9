// Height pass (paper §4 stage 1): one quad over a placement's footprint in the height map.
// The quad is the footprint rectangle widened by u_rotation.zw in pattern units so that every
// texel centre inside the footprint is covered; heightpass.frag discards the rest exactly.
// Height-map texel (i, j) has its centre at UV ((i+0.5)/W, (j+0.5)/H) and is window pixel
// (i, j): clip = uv·2 − 1, so row 0 of the render target is v near 0 (SPEC "Conventions").

//
// Variant DERMIS_SURFACE (surface placements, SPEC §8): the quad is the UV rectangle
// u_centerScale = (u0, v0, u1, v1) that holds every texel the decal may reach (from the
// rest-surface map's tile bounds, dermis::surfacePlacementTexels).

void main() {
    // Triangle strip corners 0..3.
    vec2 corner = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
#ifdef DERMIS_SURFACE
    gl_Position = vec4(mix(u_centerScale.xy, u_centerScale.zw, corner) * 2.0 - 1.0, 0.0, 1.0);
    return;
#endif
    // s ∈ {−m, 1+m}².
    vec2 s = mix(-u_rotation.zw, vec2(1.0) + u_rotation.zw, corner);
    vec2 d = (s - 0.5) * u_centerScale.zw;
    float c = u_rotation.x, sn = u_rotation.y;
    vec2 uv = u_centerScale.xy + vec2(c * d.x - sn * d.y, sn * d.x + c * d.y); // R(rotation)·d
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
