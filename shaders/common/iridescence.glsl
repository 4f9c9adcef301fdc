// KHR_materials_iridescence: a thin film whose Fresnel replaces the base's, mixed by the factor
// (common/layers.glsl declares the hooks; docs/layer_iridescence.md defines the BRDF exactly).
// As the Khronos glTF Sample Viewer does, the film is evaluated once per shading point, at the
// view's n.v, over the base's F0. Numpy twin: app/core/layers/iridescence.py (same names).
#ifdef HAS_IRIDESCENCE
#include "common/iridescence_terms.glsl"

// Fill s.iridescence_fresnel for this view; a film of no thickness is no film.
void iridescence_at_view(inout Surface s, vec3 n, vec3 v) {
    float n_dot_v = clamp(dot(n, v), MIN_N_DOT_V, 1.0);
    s.iridescence_fresnel = iridescence_fresnel(1.0, s.iridescence_ior, n_dot_v, s.iridescence_thickness, surface_f0(s));
    if (s.iridescence_thickness <= 0.0) s.iridescence = 0.0;
}

// The specular lobe's Fresnel: mix(F, F_film, iridescence).
vec3 iridescence_specular_fresnel(Surface s, vec3 F) {
    return mix(F, s.iridescence_fresnel, s.iridescence);
}

// The diffuse lobe's Fresnel: mix(F, max_rgb F_film, iridescence); the largest channel, so the
// diffuse lobe does not take the film's complementary colour.
vec3 iridescence_diffuse_fresnel(Surface s, vec3 F) {
    vec3 film = s.iridescence_fresnel;
    return mix(F, vec3(max(max(film.r, film.g), film.b)), s.iridescence);
}

// The split sum's weights with the film: F_film is constant over the lobe, so its specular
// albedo is F_film (A + B) and its diffuse weight 1 - max_rgb F_film, exactly.
void iridescence_ibl_weights(Surface s, vec4 lut, inout vec3 diffuse_weight, inout vec3 spec_albedo) {
    vec3 film = s.iridescence_fresnel;
    spec_albedo = mix(spec_albedo, film * (lut.x + lut.y), s.iridescence);
    diffuse_weight = mix(diffuse_weight, vec3(1.0 - max(max(film.r, film.g), film.b)), s.iridescence);
}
#endif
