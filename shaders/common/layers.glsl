// How the glTF layers stack on the base BRDF (docs/layers.md), as the Khronos
// extensions and the glTF spec's appendix B layer them:
//     base   = Cook-Torrance (docs/conventions.md); its diffuse lobe shares with the transmission BTDF
//              (KHR_materials_transmission, KHR_materials_volume) and its specular lobe may be
//              anisotropic (KHR_materials_anisotropy)
//     sheen  = sheen BRDF + base * sheen albedo scaling     (KHR_materials_sheen)
//     coated = clearcoat BRDF + sheen * (1 - clearcoat F_c)  (KHR_materials_clearcoat)
// Each layer's functions live in its own file (common/clearcoat.glsl, sheen.glsl,
// anisotropy.glsl, transmission.glsl, included at the end of common/shading.glsl); this file
// declares them, so the base's code (punctual.glsl, ibl.glsl, accuracy/ground_truth.glsl) can
// call them before they are defined. Everything is under the layer's HAS_* define: a material
// without a layer compiles without it (app/core/layers/__init__.py: layer_defines).
//
// "punctual" selects the punctual lights' choices (k = (r+1)^2/8, roughness floored at
// MIN_PUNCTUAL_ROUGHNESS, as punctual.glsl); false is docs/conventions.md's exact BRDF (k = r^2/2),
// used for the compact sources of ibl.glsl (their angular "spread" widens the lobes) and for
// the ground truth (spread 0).

#ifdef HAS_CLEARCOAT
// What the coat lets through to the layers below: 1 - clearcoat * F_c(n_c.v), F0 = 0.04.
float clearcoat_base_weight(Surface s, vec3 v);
// The coat's BRDF times n_c.l for one direction l, weighted by clearcoat (0 below the coat).
vec3 clearcoat_light(Surface s, vec3 v, vec3 l, bool punctual, float spread);
// The coat's reflection of the environment, weighted by clearcoat.
vec3 clearcoat_ibl(Surface s, vec3 v, bool with_suns);
#endif

#ifdef HAS_SHEEN
// The albedo scaling of the layers below the sheen for one direction l.
float sheen_base_weight(Surface s, vec3 n, vec3 v, vec3 l);
// The sheen BRDF times n.l for one direction l.
vec3 sheen_light(Surface s, vec3 n, vec3 v, vec3 l, bool punctual, float spread);
// The albedo scaling under the environment (depends on n.v only).
float sheen_base_weight_ibl(Surface s, vec3 n, vec3 v);
// The sheen's reflection of the environment.
vec3 sheen_ibl(Surface s, vec3 n, vec3 v, bool with_suns);
#endif

#ifdef HAS_ANISOTROPY
// The base's specular lobe D G F / (4 n.l n.v) for one direction l, stretched along
// s.anisotropy_direction (replaces the isotropic lobe; F is the Fresnel at v.h).
vec3 anisotropic_specular(Surface s, vec3 n, vec3 v, vec3 l, vec3 F, bool punctual, float spread);
// The prefiltered environment for the stretched lobe (replaces the isotropic lookup along d).
vec3 anisotropic_prefiltered_radiance(Surface s, vec3 n, vec3 v, vec3 d, bool with_suns);
// The factors on the BRDF LUT's (A, B) that give the stretched lobe's energy.
vec2 anisotropic_energy_ratio(Surface s, vec3 n, vec3 v);
#endif

#ifdef HAS_TRANSMISSION
// The transmitted part of the base for one direction l (either side of the surface), times
// |n.l|, with every weight included (transmission, 1 - metallic, the Fresnel and, with
// HAS_VOLUME, the attenuation). The base's diffuse lobe is scaled by 1 - transmission.
vec3 transmission_light(Surface s, vec3 n, vec3 v, vec3 l, bool punctual, float spread);
// The transmitted environment (or scene behind), with the same weights.
vec3 transmission_ibl(Surface s, vec3 n, vec3 v, bool with_suns);
#endif

#ifdef HAS_IRIDESCENCE
// The thin film's Fresnel at this view into s (once per shading point, before any light).
void iridescence_at_view(inout Surface s, vec3 n, vec3 v);
// The base's Fresnel F at v.h with the film mixed in: for the specular lobe, for the diffuse lobe.
vec3 iridescence_specular_fresnel(Surface s, vec3 F);
vec3 iridescence_diffuse_fresnel(Surface s, vec3 F);
// The split sum's diffuse weight and specular albedo with the film mixed in (lut: A, B).
void iridescence_ibl_weights(Surface s, vec4 lut, inout vec3 diffuse_weight, inout vec3 spec_albedo);
#endif

#ifdef HAS_DIFFUSE_TRANSMISSION
// What the base's front diffuse lobe keeps (1 - diffuse_transmission; common/diffuse_transmission.glsl).
float diffuse_transmission_front_weight(Surface s);
// The diffusely transmitted light for one direction l behind the surface, times |n.l|.
vec3 diffuse_transmission_light(Surface s, vec3 n, vec3 v, vec3 l);
// The diffusely transmitted environment (the irradiance about -n).
vec3 diffuse_transmission_ibl(Surface s, vec3 n, vec3 v, bool with_suns);
#endif

// ---- the stack ---------------------------------------------------------------------------

// The layers over the base for one direction l; base is the base's f |n.l| (transmission included).
vec3 layered_light(Surface s, vec3 n, vec3 v, vec3 l, vec3 base, bool punctual, float spread) {
    vec3 f = base;
#ifdef HAS_SHEEN
    f = f * sheen_base_weight(s, n, v, l) + sheen_light(s, n, v, l, punctual, spread);
#endif
#ifdef HAS_CLEARCOAT
    f = f * clearcoat_base_weight(s, v) + clearcoat_light(s, v, l, punctual, spread);
#endif
    return f;
}

// The layers over the base's image-based light (an IBL model's diffuse + specular).
vec3 layered_ibl(Surface s, vec3 n, vec3 v, vec3 base, bool with_suns) {
    vec3 radiance = base;
#ifdef HAS_TRANSMISSION
    radiance += transmission_ibl(s, n, v, with_suns);
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
    radiance += diffuse_transmission_ibl(s, n, v, with_suns);
#endif
#ifdef HAS_SHEEN
    radiance = radiance * sheen_base_weight_ibl(s, n, v) + sheen_ibl(s, n, v, with_suns);
#endif
#ifdef HAS_CLEARCOAT
    radiance = radiance * clearcoat_base_weight(s, v) + clearcoat_ibl(s, v, with_suns);
#endif
    return radiance;
}

// Emission seen through the coat (KHR_materials_clearcoat: the coat sits on top of emission).
vec3 layered_emission(Surface s, vec3 v) {
#ifdef HAS_CLEARCOAT
    return s.emissive * clearcoat_base_weight(s, v);
#else
    return s.emissive;
#endif
}
