// glTF 2.0 metallic-roughness shading under image-based light, for the skin pass's DERMIS_PBR
// programs: included into skin.frag after common.glsl (ProgramDesc::includes). The BRDF follows
// the Khronos glTF-Sample-Viewer's IBL (split-sum specular from a GGX-prefiltered environment and
// a DFG table, Lambert diffuse from irradiance, Fdez-Agüera's multiple-scattering energy
// compensation); the textures, their UV sets and KHR_texture_transform as glTF 2.0 §3.9 and the
// extension say. The tangent frame of the normal map is the vertex TANGENT when the model has
// one, else built per pixel from the derivatives of position and the map's UV (as three.js and
// the sample viewer do without tangents); the normal map and the dynamic bump are composed as
// surface gradients (Mikkelsen, "Surface Gradient Based Bump Mapping Framework", 2020).

layout(binding = 3) uniform sampler2D u_metallicRoughnessTexture; // linear: G roughness, B metallic
layout(binding = 4) uniform sampler2D u_normalTexture;            // linear, tangent space
layout(binding = 5) uniform sampler2D u_occlusionTexture;         // linear: R occlusion
layout(binding = 6) uniform sampler2D u_emissiveTexture;          // sRGB
layout(binding = 7) uniform sampler2D u_envSpecular; // equirectangular, level k: roughness k/last
layout(binding = 8) uniform sampler2D u_brdfLut;     // RG: DFG scale, bias by (N·V, roughness)

const float kPi = 3.14159265358979;

// Texture k (0 base colour, 1 metallic-roughness, 2 normal, 3 occlusion, 4 emissive): its UV set
// and transform.
vec2 materialUv(int k, vec2 uv0, vec2 uv1) {
    vec3 uv = vec3(((u_maps.w >> k) & 1) != 0 ? uv1 : uv0, 1.0);
    return vec2(dot(u_uvTransform[2 * k].xyz, uv), dot(u_uvTransform[2 * k + 1].xyz, uv));
}

bool hasMap(int bit) { return (u_maps.x & bit) != 0; }

// The environment's frame: rotated about +Y by u_envParams (cos, sin).
vec3 envDirection(vec3 d) {
    return vec3(u_envParams.y * d.x - u_envParams.z * d.z, d.y, u_envParams.z * d.x + u_envParams.y * d.z);
}

// Equirectangular lookup as three.js maps it (core/environment.hpp equirectUv): u from
// atan(z, x), row 0 at the top.
vec2 equirectTexcoord(vec3 d) {
    return vec2(atan(d.z, d.x) * (0.5 / kPi) + 0.5, 0.5 - asin(clamp(d.y, -1.0, 1.0)) / kPi);
}

// The irradiance about `n` with SH band 1 scaled by `band1` and band 2 by `band2` per channel
// (1 and 1: the environment's own; the skin shading blurs it by attenuating them).
vec3 irradianceBands(vec3 n, vec3 band1, vec3 band2) {
    vec3 d = envDirection(n);
    // Real SH basis, order 2 (the constants of core/environment.cpp's projection).
    float x = d.x, y = d.y, z = d.z;
    vec3 e1 = u_irradianceSh[1].rgb * 0.488603 * y + u_irradianceSh[2].rgb * 0.488603 * z +
              u_irradianceSh[3].rgb * 0.488603 * x;
    vec3 e2 = u_irradianceSh[4].rgb * 1.092548 * x * y + u_irradianceSh[5].rgb * 1.092548 * y * z +
              u_irradianceSh[6].rgb * 0.315392 * (3.0 * z * z - 1.0) +
              u_irradianceSh[7].rgb * 1.092548 * x * z +
              u_irradianceSh[8].rgb * 0.546274 * (x * x - y * y);
    return max(u_irradianceSh[0].rgb * 0.282095 + band1 * e1 + band2 * e2, vec3(0.0));
}

vec3 irradiance(vec3 n) { return irradianceBands(n, vec3(1.0), vec3(1.0)); }

vec3 prefilteredRadiance(vec3 r, float roughness) {
    return textureLod(u_envSpecular, equirectTexcoord(envDirection(r)), roughness * u_envParams.w).rgb;
}

// Khronos PBR Neutral (the reference implementation's constants).
vec3 toneMapPbrNeutral(vec3 color) {
    const float startCompression = 0.8 - 0.04;
    const float desaturation = 0.15;
    float x = min(color.r, min(color.g, color.b));
    float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    color -= offset;
    float peak = max(color.r, max(color.g, color.b));
    if (peak < startCompression) return color;
    const float d = 1.0 - startCompression;
    float newPeak = 1.0 - d * d / (peak + d - startCompression);
    color *= newPeak / peak;
    float g = 1.0 - 1.0 / (desaturation * (peak - newPeak) + 1.0);
    return mix(color, vec3(newPeak), g);
}

// ACES filmic as three.js's ACESFilmicToneMapping (Stephen Hill's fit, input scaled by 1/0.6).
vec3 toneMapAcesFilmic(vec3 color) {
    const mat3 inputMatrix = mat3(0.59719, 0.07600, 0.02840, 0.35458, 0.90834, 0.13383,
                                  0.04823, 0.01566, 0.83777);
    const mat3 outputMatrix = mat3(1.60475, -0.10208, -0.00327, -0.53108, 1.10813, -0.07276,
                                   -0.07367, -0.00605, 1.07602);
    color *= 1.0 / 0.6;
    color = inputMatrix * color;
    vec3 a = color * (color + 0.0245786) - 0.000090537;
    vec3 b = color * (0.983729 * color + 0.4329510) + 0.238081;
    color = outputMatrix * (a / b);
    return clamp(color, 0.0, 1.0);
}

vec3 toneMap(vec3 color) {
    color *= u_envParams.x;
    if (u_envMode.x == 1) return toneMapPbrNeutral(color);
    if (u_envMode.x == 2) return toneMapAcesFilmic(color);
    return clamp(color, 0.0, 1.0);
}

// The surface gradient of the normal map at `uv` (Mikkelsen 2020: −(x/z)·T − (y/z)·B, the
// sampled tangent-space normal's xy scaled by the material's normal scale), with T, B from the
// vertex tangent or from the derivatives of position and uv. `n` the unit surface normal.
vec3 normalMapGradient(vec3 n, vec2 uv, vec4 tangent, vec3 position) {
    vec3 tn = texture(u_normalTexture, uv).xyz * 2.0 - 1.0;
    tn.xy *= u_material.z;
    tn.z = max(tn.z, 1e-3);
    vec3 T, B;
    if ((u_maps.z & 2) != 0 && dot(tangent.xyz, tangent.xyz) > 1e-12) {
        T = normalize(tangent.xyz - n * dot(n, tangent.xyz));
        B = tangent.w * cross(n, T);
    } else {
        // dP = T_u du + T_v dv solved from the screen derivatives; T = dP/du, B = −dP/dv (the
        // image's +Y is towards smaller v).
        vec3 dpx = dFdx(position), dpy = dFdy(position);
        vec2 dux = dFdx(uv), duy = dFdy(uv);
        float det = dux.x * duy.y - dux.y * duy.x;
        if (abs(det) < 1e-20) return vec3(0.0);
        vec3 tu = (dpx * duy.y - dpy * dux.y) / det;
        vec3 tv = (dpy * dux.x - dpx * duy.x) / det;
        tu -= n * dot(n, tu);
        tv -= n * dot(n, tv);
        if (dot(tu, tu) < 1e-20 || dot(tv, tv) < 1e-20) return vec3(0.0);
        T = normalize(tu);
        B = -normalize(tv);
    }
    return -(tn.x / tn.z) * T - (tn.y / tn.z) * B;
}

// Outgoing radiance of the glTF metallic-roughness BRDF under the environment (linear, before
// exposure and tone mapping). `n` the shading normal, `v` towards the camera.
// The split-sum specular terms at (N·V, roughness) for reflectance f0: roughness-dependent
// Fresnel (Fdez-Agüera 2019), single scattering (FssEss) and multiple scattering (FmsEms).
void splitSumTerms(vec3 f0, float NdotV, float roughness, out vec3 FssEss, out vec3 FmsEms) {
    vec2 dfg = texture(u_brdfLut, vec2(NdotV, roughness)).rg;
    vec3 Fr = max(vec3(1.0 - roughness), f0) - f0;
    vec3 kS = f0 + Fr * pow(1.0 - NdotV, 5.0);
    FssEss = kS * dfg.x + dfg.y;
    float Ems = 1.0 - (dfg.x + dfg.y);
    vec3 Favg = f0 + (1.0 - f0) / 21.0;
    FmsEms = Ems * FssEss * Favg / (1.0 - Favg * Ems);
}

vec3 shadePbr(vec3 baseColor, float metallic, float roughness, float occlusion, vec3 n, vec3 v) {
    vec3 f0 = mix(vec3(0.04), baseColor, metallic);
    vec3 diffuseColor = baseColor * (1.0 - metallic);
    float NdotV = clamp(dot(n, v), 1e-4, 1.0);
    vec3 FssEss, FmsEms;
    splitSumTerms(f0, NdotV, roughness, FssEss, FmsEms);
    vec3 kD = diffuseColor * (1.0 - FssEss - FmsEms);
    vec3 specular = FssEss * prefilteredRadiance(reflect(-v, n), roughness);
    vec3 diffuse = (FmsEms + kD) * irradiance(n);
    return (diffuse + specular) * occlusion;
}

#ifdef DERMIS_SKIN
// Skin (`render.shading` "skin", Shading::Skin in core/render_settings.hpp, whose constants come in
// as the DERMIS_SKIN_* defines): the metallic-roughness BRDF above with light scattered under the
// surface and a second specular lobe.
// * Scattering, for image-based light: a diffusion profile blurs the irradiance over the sphere
//   of directions; a Gaussian of angular width σ attenuates SH band l by exp(−l(l+1)σ²/2), so
//   band 1 by exp(−σ²) and band 2 by exp(−3σ²), σ per channel (red scatters furthest). Band 0,
//   the mean, is kept: under a uniform environment the diffuse light is pbr's.
// * The diffuse normal of each channel is the bumped normal `n` blended towards the unbumped
//   `nSmooth` (red most): wrinkles and the normal map's detail soften in red, as on skin, and
//   keep their edge in blue and in the specular.
// * Two GGX lobes (roughness r and r·DERMIS_SKIN_LOBE_ROUGHNESS, the second weighted
//   DERMIS_SKIN_LOBE_WEIGHT), as dual-lobe skin models do (Kelemen and Szirmay-Kalos).
vec3 skinIrradiance(vec3 n, vec3 nSmooth) {
    const vec3 sigma = DERMIS_SKIN_SCATTER;
    const vec3 blend = DERMIS_SKIN_NORMAL_BLEND;
    vec3 band1 = exp(-sigma * sigma), band2 = exp(-3.0 * sigma * sigma);
    vec3 nr = normalize(mix(n, nSmooth, blend.r));
    vec3 ng = normalize(mix(n, nSmooth, blend.g));
    vec3 nb = normalize(mix(n, nSmooth, blend.b));
    return vec3(irradianceBands(nr, band1, band2).r, irradianceBands(ng, band1, band2).g,
                irradianceBands(nb, band1, band2).b);
}

vec3 shadeSkin(vec3 baseColor, float metallic, float roughness, float occlusion, vec3 n, vec3 nSmooth,
               vec3 v) {
    vec3 f0 = mix(vec3(0.04), baseColor, metallic);
    vec3 diffuseColor = baseColor * (1.0 - metallic);
    float NdotV = clamp(dot(n, v), 1e-4, 1.0);
    vec3 FssEss, FmsEms;
    splitSumTerms(f0, NdotV, roughness, FssEss, FmsEms);
    vec3 kD = diffuseColor * (1.0 - FssEss - FmsEms);
    // The second lobe's single-scattering term at its own roughness.
    float roughness2 = max(roughness * DERMIS_SKIN_LOBE_ROUGHNESS, 0.03);
    vec3 FssEss2, FmsEms2;
    splitSumTerms(f0, NdotV, roughness2, FssEss2, FmsEms2);
    vec3 r = reflect(-v, n);
    const float w = DERMIS_SKIN_LOBE_WEIGHT;
    vec3 specular = (1.0 - w) * FssEss * prefilteredRadiance(r, roughness) +
                    w * FssEss2 * prefilteredRadiance(r, roughness2);
    vec3 diffuse = (FmsEms + kD) * skinIrradiance(n, nSmooth);
    return (diffuse + specular) * occlusion;
}
#endif

#ifdef DERMIS_KEY_LIGHT
// The directional key light (`render.key_light`, core/render_settings.hpp KeyLight), added to the
// image-based light: the glTF-Sample-Viewer's punctual-light BRDF (Lambert diffuse, GGX with the
// height-correlated Smith visibility, Schlick's Fresnel), receiving colour × intensity ×
// max(n·l, 0), times the shadow map's visibility. Under DERMIS_SKIN the diffuse part wraps past
// the terminator per channel (Green 2004, "Real-Time Approximations to Subsurface Scattering":
// max((n_c·l + w)/(1 + w), 0) with w = the channel's scattering width and n_c its softened
// normal), and the specular has skin's second lobe. The material's occlusion map, which is
// light from the environment, does not apply.
layout(std140, binding = 5) uniform KeyLightBlock {
    mat4 u_shadowViewProj; // world → the shadow map's clip space (core/key_light.hpp)
    vec4 u_keyDirection;   // unit, towards the light (world); w 1 with a shadow map, else 0
    vec4 u_keyRadiance;    // colour × intensity (linear), 0
    vec4 u_shadowParams;   // normal offset (world units), depth bias (map depth units), 1 / map size, 0
};
layout(binding = 9) uniform sampler2DShadow u_shadowMap; // compare mode, border 1 (lit)

// Visibility of the key light at `position` (world) on a surface of geometric normal `ng` (unit,
// facing the camera): 1 lit, 0 in shadow. The lookup moves off the surface along the normal by
// up to one offset, more where the light grazes it, and compares with a small bias; four
// bilinear comparisons (a 3×3-texel tent) soften the edge.
float keyLightVisibility(vec3 position, vec3 ng) {
    if (u_keyDirection.w == 0.0) return 1.0;
    float NdotL = dot(ng, u_keyDirection.xyz);
    vec3 p = position + ng * (u_shadowParams.x * (1.5 - clamp(NdotL, 0.0, 1.0)));
    vec3 s = (u_shadowViewProj * vec4(p, 1.0)).xyz * 0.5 + 0.5;
    if (s.z >= 1.0) return 1.0;
    float ref = s.z - u_shadowParams.y;
    float d = 0.75 * u_shadowParams.z;
    return 0.25 * (texture(u_shadowMap, vec3(s.xy + vec2(-d, -d), ref)) +
                   texture(u_shadowMap, vec3(s.xy + vec2(d, -d), ref)) +
                   texture(u_shadowMap, vec3(s.xy + vec2(-d, d), ref)) +
                   texture(u_shadowMap, vec3(s.xy + vec2(d, d), ref)));
}

float distributionGgx(float NdotH, float alpha) {
    float a2 = alpha * alpha;
    float f = NdotH * NdotH * (a2 - 1.0) + 1.0;
    return a2 / (kPi * f * f);
}

float visibilitySmithGgxCorrelated(float NdotL, float NdotV, float alpha) {
    float a2 = alpha * alpha;
    float ggxV = NdotL * sqrt(NdotV * NdotV * (1.0 - a2) + a2);
    float ggxL = NdotV * sqrt(NdotL * NdotL * (1.0 - a2) + a2);
    float s = ggxV + ggxL;
    return s > 0.0 ? 0.5 / s : 0.0;
}

// Outgoing radiance from the key light (linear, before exposure): `n` the shading normal,
// `nSmooth` the unbumped one (skin), `v` towards the camera, `ng` the geometric normal facing the
// camera, `position` world.
vec3 keyLight(vec3 baseColor, float metallic, float roughness, vec3 n, vec3 nSmooth, vec3 v, vec3 ng,
              vec3 position) {
    vec3 l = u_keyDirection.xyz;
    vec3 f0 = mix(vec3(0.04), baseColor, metallic);
    vec3 diffuseColor = baseColor * (1.0 - metallic);
    vec3 h = normalize(l + v);
    float VdotH = clamp(dot(v, h), 0.0, 1.0);
    vec3 F = f0 + (1.0 - f0) * pow(1.0 - VdotH, 5.0);
    float NdotL = clamp(dot(n, l), 0.0, 1.0);
    float NdotV = clamp(dot(n, v), 1e-4, 1.0);
    float NdotH = clamp(dot(n, h), 0.0, 1.0);
    float alpha = roughness * roughness;
    vec3 specular = F * (visibilitySmithGgxCorrelated(NdotL, NdotV, alpha) * distributionGgx(NdotH, alpha));
#ifdef DERMIS_SKIN
    float alpha2 = max(roughness * DERMIS_SKIN_LOBE_ROUGHNESS, 0.03);
    alpha2 *= alpha2;
    const float w = DERMIS_SKIN_LOBE_WEIGHT;
    specular = (1.0 - w) * specular +
               w * F * (visibilitySmithGgxCorrelated(NdotL, NdotV, alpha2) * distributionGgx(NdotH, alpha2));
    const vec3 wrap = DERMIS_SKIN_SCATTER;
    const vec3 blend = DERMIS_SKIN_NORMAL_BLEND;
    vec3 wrapped = vec3(dot(normalize(mix(n, nSmooth, blend.r)), l), dot(normalize(mix(n, nSmooth, blend.g)), l),
                        dot(normalize(mix(n, nSmooth, blend.b)), l));
    wrapped = max((wrapped + wrap) / (1.0 + wrap), vec3(0.0));
    vec3 diffuse = (1.0 - F) * diffuseColor / kPi * wrapped;
#else
    vec3 diffuse = (1.0 - F) * diffuseColor / kPi * NdotL;
#endif
    return (diffuse + specular * NdotL) * u_keyRadiance.rgb * keyLightVisibility(position, ng);
}
#endif
