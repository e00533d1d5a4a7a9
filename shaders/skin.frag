// Skin pass, fragment stage: bump mapping from the height maps without precomputed tangents
// (Mikkelsen, "Bump Mapping Unparametrized Surfaces on the GPU", 2010: the surface gradient from
// screen-space derivatives), then one of three shadings: "legacy", the base colour under one
// Blinn-Phong key light and a hemisphere fill; DERMIS_PBR, `render.shading` "pbr", glTF
// metallic-roughness under image-based light (pbr.glsl), exposure and tone mapping; or
// DERMIS_PBR with DERMIS_SKIN, "skin", that with subsurface scattering and a second specular lobe
// (pbr.glsl shadeSkin); either of the last two with DERMIS_KEY_LIGHT adds the directional key
// light and its shadow (pbr.glsl keyLight). Writes linear colour; the sRGB render target encodes it.
//
// Views (DERMIS_VIEW, FrameView in server/core/render_settings.hpp; one program per view, so that a
// software rasterizer, which runs every branch for every pixel, shades only its view's code):
// 0 shaded; unlit pictures of the maps on the surface for authoring: 1 bump / 2 displacement
// height as grey byte 128 + 127·height (clamped to [−1, 1]), 3 the perturbed world normal as bytes
// 255·(n·0.5 + 0.5). Those are picture values: written through the sRGB EOTF so that the
// target's encoding gives them back.
// The pbr programs draw the shaded view; with DERMIS_PBR_VIEWS also the material's views, chosen
// by u_part.w (3 normal, 4 base colour, 5 lighting). Without DERMIS_PBR_MAPS they never read the
// metallic-roughness, normal, occlusion and emissive textures (for materials that have none:
// their checks of u_maps would not spare a software rasterizer the lookups, for the same reason).
#ifndef DERMIS_VIEW
#define DERMIS_VIEW 0
#endif
//
// Outlines (OutlineBlock, common.glsl): footprint rectangles in the height maps' UV space, surface
// decals' rectangles and the surface brush's circle on the rest surface, drawn over any view as a
// band about 2 pixels wide where the surface lies on their border — selected
// (orange, with a faint tint inside and a dark rim outside), hovered (pale blue), the place brush
// (dashed cyan). With u_outlineCount.x = 0 nothing runs and the frame is exactly the one without
// outlines. The legacy programs always have them (DERMIS_OUTLINES); the pbr ones only in the
// variant a frame with outlines asks for.
//
// Two UVs (SPEC §8): v_uv is the model's TEXCOORD_0 (base colour), v_mapUv the UV of the height
// maps' layout (heights, bump gradient, outlines) — the same values when the layout is the model's.

layout(binding = 0) uniform sampler2D u_heightMap;        // RG32F: bump, displacement
layout(binding = 2) uniform sampler2D u_baseColorTexture; // sRGB8_A8, decoded to linear by the sampler

in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;    // the model's TEXCOORD_0: base colour
in vec2 v_mapUv; // the height-map layout's UV (SPEC §8): heights and UV outlines
in vec3 v_restPosition; // bind space: surface decal outlines (SPEC §8)
in vec3 v_restNormal;
#ifdef DERMIS_PBR
in vec4 v_tangent;
in vec2 v_uv1;
in vec4 v_color;
#endif

layout(location = 0) out vec4 o_color;

// Height of the shaded surface in model units: bump map · bump scale, plus the displacement map ·
// displacement scale (its relief shades the bulge at pixel, not vertex, resolution).
float surfaceHeight(vec2 uv) {
    return dot(textureLod(u_heightMap, uv, 0.0).rg, u_heights.yx);
}

// The bump map's surface gradient (Mikkelsen 2010/2020): the normal bumped by the height maps is
// normalize(n − bumpGradient(n)); zero where the part has no height-map UVs.
vec3 bumpGradient(vec3 n) {
    // dH/du, dH/dv by differences one texel apart (three samples of the RG map).
    vec2 e = u_heightmapSize.zw;
    vec2 uv0 = v_mapUv - 0.5 * e;
    float h0 = surfaceHeight(uv0);
    float dHdu = (surfaceHeight(uv0 + vec2(e.x, 0.0)) - h0) / e.x;
    float dHdv = (surfaceHeight(uv0 + vec2(0.0, e.y)) - h0) / e.y;
    vec2 dUVdx = dFdx(v_mapUv), dUVdy = dFdy(v_mapUv);
    float dBs = dHdu * dUVdx.x + dHdv * dUVdx.y; // dH along screen x
    float dBt = dHdu * dUVdy.x + dHdv * dUVdy.y; // dH along screen y
    vec3 sigmaS = dFdx(v_position), sigmaT = dFdy(v_position);
    vec3 r1 = cross(sigmaT, n), r2 = cross(n, sigmaS);
    float det = dot(sigmaS, r1);
    if (abs(det) < 1e-20) return vec3(0.0);
    return sign(det) * (dBs * r1 + dBt * r2) / abs(det);
}

vec3 perturbedNormal(vec3 n) {
    return normalize(n - bumpGradient(n));
}

// The linear value the sRGB target encodes to picture value c (exact sRGB EOTF).
vec3 pictureValue(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}

// Linear colours of the outline kinds (sRGB 255,170,40 / 200,225,255 / 60,205,255).
const vec3 kOutlineColor[3] = vec3[3](vec3(1.0, 0.402, 0.021), vec3(0.578, 0.753, 1.0),
                                      vec3(0.045, 0.610, 1.0));

// `color` with every outline drawn over it. Without DERMIS_OUTLINES (the pbr programs of frames
// that have none: ranges, farms, the editor with nothing selected) it is `color`, and the
// outline inputs are not read, so the linker drops them: on llvmpipe the empty loop and the two
// extra interpolated vectors cost ≈ 12 % of a 1024² pbr frame's CPU (docs/benchmarks.md).
vec3 outlined(vec3 color) {
#ifndef DERMIS_OUTLINES
    return color;
#else
    for (int i = 0; i < u_outlineCount.x; ++i) {
        vec4 r = u_outlineRect[i];
        vec4 st = u_outlineStyle[i];
        int kind = int(st.z);
        int shape = int(st.w);
        vec2 q;
        bool away = false; // a surface shape's point behind the surface or beyond the depth
        if (shape == 0) {
            // s − 0.5 = R(−rotation)·(uv − centre) / size (SPEC §2): q in [−0.5, 0.5]² inside.
            vec2 d = v_mapUv - r.xy;
            q = vec2(st.x * d.x + st.y * d.y, -st.y * d.x + st.x * d.y) / r.zw;
        } else {
            // s − 0.5 = (d·t / w, d·b / h), d = rest position − anchor (SPEC §8, SurfaceFrame in
            // heightmap.hpp); nothing beyond the depth or on surfaces facing away.
            vec4 a = u_outlineAnchor[i];
            vec3 d = v_restPosition - a.xyz;
            vec3 n = cross(u_outlineAxisU[i].xyz, u_outlineAxisV[i].xyz);
            away = dot(v_restNormal, n) <= 0.0 || abs(dot(d, normalize(n))) > a.w;
            q = vec2(dot(d, u_outlineAxisU[i].xyz), dot(d, u_outlineAxisV[i].xyz));
        }
        vec2 perPixel = max(fwidth(q), vec2(1e-7));
        vec2 e = (abs(q) - 0.5) / perPixel; // pixels beyond each edge (negative inside)
        float dist = length(max(e, vec2(0.0))) + min(max(e.x, e.y), 0.0); // signed, to the border
        if (shape == 2) dist = (length(q) - 0.5) / max(length(fwidth(q)) * 0.70710678, 1e-7); // circle
        // A surface shape where one pixel spans a quarter of it (a silhouette's sliver, whose
        // derivatives jump across the body) draws no band: it would mark pixels far from it.
        if (shape != 0 && max(perPixel.x, perPixel.y) > 0.25) away = true;
        if (away || dist > 4.0) continue; // (after the derivatives: uniform control flow above)
        float halfWidth = kind == 1 ? 0.9 : 1.3;
        float band = 1.0 - smoothstep(halfWidth - 0.5, halfWidth + 0.5, abs(dist));
        if (kind == 2) { // dashes of 6 pixels along the border
            float along = shape == 2 ? atan(q.y, q.x) * 0.5 / max(length(fwidth(q)) * 0.70710678, 1e-7)
                                     : e.x > e.y ? q.y / perPixel.y : q.x / perPixel.x;
            band *= step(0.5, fract(along / 12.0));
        }
        vec3 c = kOutlineColor[clamp(kind, 0, 2)];
        if (dist < 0.0 && kind != 1) color = mix(color, c, kind == 0 ? 0.10 : 0.06); // tint inside
        if (kind == 0) color *= 1.0 - 0.6 * (1.0 - smoothstep(0.0, 1.0, abs(dist - halfWidth - 1.0))); // rim
        color = mix(color, c, band);
    }
    return color;
#endif
}

void main() {
    vec3 n = normalize(v_normal);
    vec3 toCamera = normalize(u_cameraPos.xyz - v_position);
    if (dot(n, toCamera) < 0.0) n = -n; // two-sided: back faces are lit like front faces
#ifndef DERMIS_PBR
    if (u_part.z != 0) n = perturbedNormal(n);
#endif

#if DERMIS_VIEW == 1 || DERMIS_VIEW == 2 // bump or displacement height as grey
    vec2 heights = u_part.z != 0 ? textureLod(u_heightMap, v_mapUv, 0.0).rg : vec2(0.0);
    float height = clamp(DERMIS_VIEW == 1 ? heights.r : heights.g, -1.0, 1.0);
    o_color = vec4(outlined(pictureValue(vec3((128.0 + 127.0 * height) / 255.0))), 1.0);
#elif DERMIS_VIEW == 3 // the perturbed world normal
    o_color = vec4(outlined(pictureValue(n * 0.5 + 0.5)), 1.0);
#elif defined(DERMIS_PBR)
    // glTF metallic-roughness under the environment (pbr.glsl); the model's normal map and the
    // bump compose as surface gradients on the geometric normal.
    vec3 ng = normalize(v_normal);
    bool back = dot(ng, toCamera) < 0.0;
    if (back) ng = -ng;
    vec4 base = u_baseColor;
    if ((u_maps.z & 4) != 0) base *= v_color;
    if (hasMap(1)) base *= texture(u_baseColorTexture, materialUv(0, v_uv, v_uv1));
    if (u_maps.y == 1 && base.a < u_emissive.w) discard;
    // Views of the material (FrameView; u_part.w): 4 base colour as it is, 5 the light alone on a
    // white rough dielectric, 3 the world normal with the model's normal map and the bump.
#ifdef DERMIS_PBR_VIEWS
    const int view = u_part.w;
#else
    const int view = 0;
#endif
    vec3 color;
    if (view == 4 || ((u_maps.z & 1) != 0 && view != 5 && view != 3)) {
        color = base.rgb; // the base colour view, or KHR_materials_unlit
    } else {
        vec3 gradient = u_part.z != 0 ? bumpGradient(ng) : vec3(0.0);
#ifdef DERMIS_PBR_MAPS
        if (hasMap(4)) {
            vec3 g = normalMapGradient(ng, materialUv(2, v_uv, v_uv1), v_tangent, v_position);
            gradient += back ? -g : g;
        }
#endif
        vec3 nn = normalize(ng - gradient);
        if (view == 3) {
            o_color = vec4(outlined(pictureValue(nn * 0.5 + 0.5)), 1.0);
            return;
        }
        float metallic = u_material.x, roughness = u_material.y;
        if (view == 5) {
            base = vec4(1.0);
            metallic = 0.0;
            roughness = 1.0;
        }
#ifdef DERMIS_PBR_MAPS
        else if (hasMap(2)) {
            vec4 mr = texture(u_metallicRoughnessTexture, materialUv(1, v_uv, v_uv1));
            roughness *= mr.g;
            metallic *= mr.b;
        }
#endif
        metallic = clamp(metallic, 0.0, 1.0);
        roughness = clamp(roughness, 0.03, 1.0);
        float occlusion = 1.0;
#ifdef DERMIS_PBR_MAPS
        if (hasMap(8) && view != 5)
            occlusion = 1.0 + u_material.w * (texture(u_occlusionTexture, materialUv(3, v_uv, v_uv1)).r - 1.0);
#endif
#ifdef DERMIS_SKIN
        color = shadeSkin(base.rgb, metallic, roughness, occlusion, nn, ng, toCamera);
#else
        color = shadePbr(base.rgb, metallic, roughness, occlusion, nn, toCamera);
#endif
#ifdef DERMIS_KEY_LIGHT
        color += keyLight(base.rgb, metallic, roughness, nn, ng, toCamera, ng, v_position);
#endif
        vec3 emissive = u_emissive.rgb;
#ifdef DERMIS_PBR_MAPS
        if (hasMap(16)) emissive *= texture(u_emissiveTexture, materialUv(4, v_uv, v_uv1)).rgb;
#endif
        if (view != 5) color += emissive;
    }
    if (view == 4) {
        o_color = vec4(outlined(color), 1.0);
        return;
    }
    o_color = vec4(outlined(toneMap(color)), u_maps.y == 2 ? clamp(base.a, 0.0, 1.0) : 1.0);
#else
    vec4 base = u_baseColor;
    if (u_part.y != 0) base *= texture(u_baseColorTexture, v_uv);

    vec3 l = u_lightDir.xyz;
    float diffuse = max(dot(n, l), 0.0);
    float fill = 0.5 + 0.5 * n.y; // sky/ground hemisphere
    vec3 h = normalize(l + toCamera);
    float specular = pow(max(dot(n, h), 0.0), 48.0) * 0.15 * step(0.0, dot(n, l));
    vec3 color = base.rgb * (0.85 * diffuse + u_lightDir.w * fill) + vec3(specular);
    o_color = vec4(outlined(color), 1.0);
#endif
}
