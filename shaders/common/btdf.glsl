// The transmission BTDF, one function per term (after Filament's brdf.fs): thin-walled
// (KHR_materials_transmission) and refracting (KHR_materials_volume), with Beer-Lambert
// attenuation. Numpy twins: app/core/btdf.py (same names). Definition: docs/layer_transmission.md.
// v points to the eye (outside, index 1); l toward the light, behind the surface (n.l < 0).
// Needs common/brdf.glsl.

// Quality and robustness choices, in one place:
// |v + ior l| floor: at ior 1 the straight-through direction has no refraction half vector.
const float MIN_HALF_LENGTH = 1e-7;

// A direction behind the surface mirrored to the front (KHR_materials_transmission's thin wall).
vec3 mirror_through_surface(vec3 l, vec3 n) {
    return l - 2.0 * dot(n, l) * n;
}

// KHR_materials_transmission's transmission half vector normalize(v + l - 2 (n.l) n).
vec3 half_vector_thin(vec3 n, vec3 v, vec3 l) {
    return normalize(v + mirror_through_surface(l, n));
}

// Walter et al. 2007's refraction half vector h_t = -normalize(v + ior l) (v outside, index 1).
vec3 half_vector_refraction(vec3 v, vec3 l, float ior) {
    vec3 s = v + ior * l;
    return -s / max(length(s), MIN_HALF_LENGTH);
}

// D G / (4 |n.l| n.v): KHR_materials_transmission's specular_btdf without Fresnel and tint.
float btdf_thin(float n_dot_v, float n_dot_l, float n_dot_h, float roughness, float k) {
    float nl = abs(n_dot_l);
    return D_GGX(max(n_dot_h, 0.0), roughness) * G_Smith(n_dot_v, nl, k) / (4.0 * max(nl, 1e-8) * n_dot_v);
}

// |l.h| |v.h| / (|n.l| n.v) ior^2 D G / (v.h + ior l.h)^2: Walter et al. 2007, eq. 21, as
// KHR_materials_volume writes it, without Fresnel and tint; zero unless the facet is seen from
// both sides the right way (n.h > 0, v.h > 0, l.h < 0).
float btdf_refraction(float n_dot_v, float n_dot_l, float n_dot_h, float v_dot_h, float l_dot_h,
                      float roughness, float ior, float k) {
    if (n_dot_h <= 0.0 || v_dot_h <= 0.0 || l_dot_h >= 0.0) return 0.0;
    float nl = abs(n_dot_l);
    float d = v_dot_h + ior * l_dot_h;
    return abs(l_dot_h) * v_dot_h / (max(nl, 1e-8) * n_dot_v) * ior * ior
         * D_GGX(n_dot_h, roughness) * G_Smith(n_dot_v, nl, k) / max(d * d, 1e-12);
}

// Transmittance over `distance` in a medium leaving attenuation_color of white light after
// attenuation_distance (KHR_materials_volume; Beer-Lambert): an infinite distance gives 1.
vec3 beer_lambert(vec3 attenuation_color, float attenuation_distance, float distance) {
    float ratio = distance / attenuation_distance;
    return ratio > 0.0 ? pow(attenuation_color, vec3(ratio)) : vec3(1.0);
}

// The BTDF at unit n, v, l without Fresnel and tint: thin-walled, or refracting at `ior`;
// zero unless l is behind the surface. v_dot_h returns its half vector's v.h for the Fresnel.
float transmission_btdf(vec3 n, vec3 v, vec3 l, float roughness, float k, float ior, bool thin,
                        out float v_dot_h) {
    float n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    float n_dot_l = dot(n, l);
    vec3 h = thin ? half_vector_thin(n, v, l) : half_vector_refraction(v, l, ior);
    v_dot_h = clamp(dot(v, h), 0.0, 1.0);
    if (n_dot_l >= 0.0) return 0.0;
    return thin ? btdf_thin(n_dot_v, n_dot_l, dot(n, h), roughness, k)
                : btdf_refraction(n_dot_v, n_dot_l, dot(n, h), dot(v, h), dot(l, h), roughness, ior, k);
}
