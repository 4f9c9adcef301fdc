// KHR_materials_anisotropy: the base's GGX lobe stretched along a tangent direction
// (common/layers.glsl declares the hooks; docs/layer_anisotropy.md defines the BRDF exactly).
// Numpy twin: app/core/layers/anisotropy.py (same names).
#ifdef HAS_ANISOTROPY

// Quality choices, in one place: the image-based lookup's fetches along the stretched lobe
// (ANISOTROPY_FETCHES, 1 to 8; docs/layer_anisotropy.md measures each count against the exact answer).
#ifndef ANISOTROPY_FETCHES
#define ANISOTROPY_FETCHES 5
#endif

// ---- the BRDF's terms ------------------------------------------------------------------------

// (alpha_t, alpha_b): alpha = r^2 along the direction grows to 1 with strength^2, across it
// stays (KHR_materials_anisotropy, "Individual lighting contributions").
vec2 anisotropic_alpha(float roughness, float strength) {
    float alpha = roughness * roughness;
    return vec2(mix(alpha, 1.0, strength * strength), alpha);
}

// Trowbridge-Reitz GGX with a roughness per tangent axis (Burley 2012, "Physically-Based Shading
// at Disney", eq. 13; the extension's D), in the scaled-vector form that keeps float32 finite.
float D_GGX_anisotropic(float t_dot_h, float b_dot_h, float n_dot_h, float alpha_t, float alpha_b) {
    float a2 = alpha_t * alpha_b;
    vec3 d = vec3(alpha_b * t_dot_h, alpha_t * b_dot_h, a2 * n_dot_h);
    float w2 = a2 / dot(d, d);
    return a2 * w2 * w2 / PI;
}

// The alpha a direction x sees: the lobe's alpha projected on x's azimuth (Heitz 2014,
// "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs", sec. 5.3). Smith
// masking of an anisotropic lobe is the isotropic masking at this alpha, so the base's
// Schlick-GGX G (CONVENTIONS.md) carries over unchanged. At x = n the azimuth is undefined and
// G1 = 1 whatever alpha: alpha_b is returned.
float projected_alpha(float t_dot_x, float b_dot_x, float alpha_t, float alpha_b) {
    float sin2 = t_dot_x * t_dot_x + b_dot_x * b_dot_x;
    if (sin2 < 1e-12) return alpha_b;
    return sqrt((t_dot_x * t_dot_x * alpha_t * alpha_t + b_dot_x * b_dot_x * alpha_b * alpha_b) / sin2);
}

// Schlick-GGX masking of one direction at its projected alpha: k = (sqrt(alpha) + 1)^2 / 8 for
// punctual lights, alpha / 2 for the environment (brdf.glsl's k_direct, k_ibl).
float G1_anisotropic(float n_dot_x, float projected, bool punctual) {
    float r = sqrt(projected);
    return G1_SchlickGGX(n_dot_x, punctual ? k_direct(r) : k_ibl(r));
}

// D G F / (4 n.l n.v) with the lobe stretched along s.anisotropy_direction. punctual: the
// roughness floored at MIN_PUNCTUAL_ROUGHNESS and k_direct; otherwise CONVENTIONS.md's k_ibl,
// and a compact source's angular spread widens both axes (as sun_light widens the round lobe).
vec3 anisotropic_specular(Surface s, vec3 n, vec3 v, vec3 l, vec3 F, bool punctual, float spread) {
    float n_dot_l = max(dot(n, l), 1e-8);
    float n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    vec3 h = normalize(l + v);
    vec3 t = s.anisotropy_direction;
    vec3 b = s.anisotropy_bitangent;
    float r = punctual ? max(s.roughness, MIN_PUNCTUAL_ROUGHNESS) : s.roughness;
    vec2 alpha = anisotropic_alpha(r, s.anisotropy_strength);
    vec2 widened = alpha;
    if (!punctual) {
        float floor_alpha = MIN_PUNCTUAL_ROUGHNESS * MIN_PUNCTUAL_ROUGHNESS;
        widened = max(sqrt(alpha * alpha + spread * spread), vec2(floor_alpha));
        alpha = anisotropic_alpha(max(s.roughness, MIN_PUNCTUAL_ROUGHNESS), s.anisotropy_strength);
    }
    float D = D_GGX_anisotropic(dot(t, h), dot(b, h), max(dot(n, h), 0.0), widened.x, widened.y);
    float G = G1_anisotropic(n_dot_v, projected_alpha(dot(t, v), dot(b, v), alpha.x, alpha.y), punctual)
            * G1_anisotropic(n_dot_l, projected_alpha(dot(t, l), dot(b, l), alpha.x, alpha.y), punctual);
    return D * G * F / (4.0 * n_dot_l * n_dot_v);
}

// ---- image-based light: the stretched lobe ---------------------------------------------------

vec3 anisotropic_prefiltered_radiance(Surface s, vec3 n, vec3 v, vec3 d, bool with_suns) {
    return prefiltered_radiance_at(d, s.roughness, with_suns);
}

#endif
