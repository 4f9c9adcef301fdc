// The terms of KHR_materials_anisotropy's stretched GGX lobe, one function per term (no Surface:
// shared by common/anisotropy.glsl and ibl/anisotropy_lut.comp). Numpy twins:
// app/core/layers/anisotropy.py (same names). Needs common/brdf.glsl.

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
// Schlick-GGX G (docs/conventions.md) carries over unchanged. At x = n the azimuth is undefined and
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

// A half vector (tangent space: x along the direction, z = n) with pdf D(h) (n.h) for the
// stretched lobe: the unit GGX slope distribution scaled by (alpha_t, alpha_b) (Walter et al.
// 2007, sec. 5.2, per axis). At alpha_t = alpha_b it is sampling.glsl's
// importance_sample_ggx_tangent, sample for sample.
vec3 importance_sample_ggx_anisotropic(vec2 xi, float alpha_t, float alpha_b) {
    float phi = 2.0 * PI * xi.x;
    float radius = sqrt(xi.y / max(1.0 - xi.y, 1e-12));
    vec2 slope = radius * vec2(alpha_t * cos(phi), alpha_b * sin(phi));
    return normalize(vec3(slope, 1.0));
}
