// KHR_materials_clearcoat: a GGX coat over the base, layered by the coat's Fresnel at n_c.v
// (common/layers.glsl declares these; exact definition: docs/layer_clearcoat.md). Numpy twin:
// app/core/layers/clearcoat.py (same names).
//     coated = base (1 - clearcoat F_c(n_c.v)) + clearcoat F_c(n_c.v) D G / (4 n_c.l n_c.v)
// Both weights use the same F_c, so the coat only moves energy from the base into its own lobe
// (whose albedo is at most 1): it never adds any.
#ifdef HAS_CLEARCOAT

// The coat's dielectric: ior 1.5, F0 = 0.04 (KHR_materials_clearcoat fixes it).
const float CLEARCOAT_F0 = 0.04;

// The coat's Fresnel weight at n_c.v (KHR_materials_clearcoat's fresnel_coat; Schlick 1994).
float clearcoat_fresnel(Surface s, vec3 v) {
    return F_Schlick(clamp(dot(s.clearcoat_normal, v), 0.0, 1.0), vec3(CLEARCOAT_F0)).x;
}

float clearcoat_base_weight(Surface s, vec3 v) {
    return 1.0 - s.clearcoat * clearcoat_fresnel(s, v);
}

// The coat's lobe D G / (4 n_c.l n_c.v) times n_c.l, without Fresnel: GGX (Walter et al. 2007)
// with Schlick-GGX masking (docs/conventions.md's terms), the punctual or the IBL k.
float clearcoat_lobe(Surface s, vec3 v, vec3 l, bool punctual, float spread) {
    vec3 n = s.clearcoat_normal;
    float n_dot_l = dot(n, l);
    if (n_dot_l <= 0.0) return 0.0;
    float n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    float n_dot_h = max(dot(n, normalize(l + v)), 0.0);
    float r = max(s.clearcoat_roughness, MIN_PUNCTUAL_ROUGHNESS);
    float alpha = s.clearcoat_roughness * s.clearcoat_roughness;
    // A compact source's angular size widens the lobe (ibl.glsl: sun_light); 0 for lights.
    float lobe = punctual ? r : max(sqrt(sqrt(alpha * alpha + spread * spread)), MIN_PUNCTUAL_ROUGHNESS);
    float D = D_GGX(n_dot_h, lobe);
    float G = G_Smith(n_dot_v, n_dot_l, punctual ? k_direct(r) : k_ibl(r));
    return D * G / (4.0 * n_dot_v);
}

vec3 clearcoat_light(Surface s, vec3 v, vec3 l, bool punctual, float spread) {
    return vec3(s.clearcoat * clearcoat_fresnel(s, v) * clearcoat_lobe(s, v, l, punctual, spread));
}

// The coat's lobe under the environment, by the split sum: the prefiltered radiance at the
// lobe's mean direction times its albedo A + B (brdf_lut.comp: A + B is the albedo of
// D G / (4 n.l n.v) n.l; the lobe's Fresnel is the constant F_c, so F0 = 1 picks the mean of
// the whole lobe, t = (A t_A + B t_B) / (A + B)).
vec3 clearcoat_ibl(Surface s, vec3 v, bool with_suns) {
    vec3 n = s.clearcoat_normal;
    float n_dot_v = max(dot(n, v), 0.0);
    vec4 lut = brdf_lut_at(n_dot_v, s.clearcoat_roughness);
    vec3 d = specular_dominant_direction(n, reflect(-v, n), vec3(1.0), lut);
    vec3 prefiltered = occluded_layer_radiance(s, n, d, s.clearcoat_roughness,
                                               prefiltered_radiance_at(d, s.clearcoat_roughness, with_suns));
    return s.clearcoat * clearcoat_fresnel(s, v) * (lut.x + lut.y) * prefiltered;
}

#endif
