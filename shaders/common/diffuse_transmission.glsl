// KHR_materials_diffuse_transmission: a share dt of the base's diffuse lobe leaves through the
// back side as a Lambertian BTDF tinted by diffuse_transmission_color (the extension's
// mix(diffuse_brdf, diffuse_btdf, dt) under the Fresnel layer; common/layers.glsl declares
// these hooks; the definition is docs/layer_diffuse_transmission.md). As the Khronos glTF
// Sample Viewer does: light from behind through the BTDF, with the Fresnel at the half vector of
// l mirrored to the front; the environment through the irradiance about -n. With a volume
// (HAS_VOLUME) the light crosses the thickness with Beer-Lambert attenuation.
// Numpy twin: app/core/layers/diffuse_transmission.py.
#include "common/diffuse_transmission_terms.glsl"
#ifdef HAS_DIFFUSE_TRANSMISSION

// What the front diffuse lobe keeps: 1 - dt.
float diffuse_transmission_front_weight(Surface s) {
    return 1.0 - s.diffuse_transmission;
}

// dt c T (1 - metallic)(1 - transmission): the back lobe's weight before the Fresnel.
vec3 diffuse_transmission_weight(Surface s) {
    vec3 weight = s.diffuse_transmission * s.diffuse_transmission_color * (1.0 - s.metallic);
#ifdef HAS_TRANSMISSION
    weight *= 1.0 - s.transmission;
#endif
#ifdef HAS_VOLUME
    weight *= beer_lambert(s.attenuation_color, s.attenuation_distance, s.thickness);
#endif
    return weight;
}

// The back lobe times |n.l| for one direction l behind the surface (0 in front):
// weight (1 - F(v.h)) c / pi |n.l|, h = normalize(v + l mirrored to the front).
vec3 diffuse_transmission_light(Surface s, vec3 n, vec3 v, vec3 l) {
    float n_dot_l = dot(n, l);
    if (n_dot_l >= 0.0) return vec3(0.0);
    float v_dot_h = clamp(dot(v, half_vector_thin(n, v, l)), 0.0, 1.0);
    vec3 F = F_Schlick(v_dot_h, surface_f0(s), surface_f90(s));
    return diffuse_transmission_weight(s) * (1.0 - F) * diffuse_btdf_cos(vec3(1.0), n_dot_l);
}

// The back lobe under the environment: weight times the irradiance about -n (E/pi), with the
// front lobe's Fresnel weight under uniform light (the mirrored half vector makes the two equal),
// 1 - F0 - (F90 - F0) diffuse_fresnel(n.v).
vec3 diffuse_transmission_ibl(Surface s, vec3 n, vec3 v, bool with_suns) {
    vec3 f0 = surface_f0(s);
    vec3 fresnel = 1.0 - f0 - (surface_f90(s) - f0) * diffuse_fresnel(max(dot(n, v), MIN_N_DOT_V));
    return diffuse_transmission_weight(s) * fresnel * irradiance_at(-n, with_suns);
}

#endif
