// KHR_materials_anisotropy: the base's GGX lobe stretched along a tangent direction
// (common/layers.glsl declares these; docs/layers.md). Numpy twin: app/core/layers/anisotropy.py.
// Until it is written, the hooks give the isotropic lobe (what strength 0 must give).
#ifdef HAS_ANISOTROPY

vec3 anisotropic_specular(Surface s, vec3 n, vec3 v, vec3 l, vec3 F, bool punctual, float spread) {
    float n_dot_l = max(dot(n, l), 1e-8);
    float n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    vec3 h = normalize(l + v);
    float r = punctual ? max(s.roughness, MIN_PUNCTUAL_ROUGHNESS) : s.roughness;
    float alpha = r * r;
    float widened = max(sqrt(sqrt(alpha * alpha + spread * spread)), punctual ? 0.0 : MIN_PUNCTUAL_ROUGHNESS);
    float D = D_GGX(max(dot(n, h), 0.0), widened);
    float G = G_Smith(n_dot_v, n_dot_l, punctual ? k_direct(r) : k_ibl(max(r, punctual ? 0.0 : MIN_PUNCTUAL_ROUGHNESS)));
    return D * G * F / (4.0 * n_dot_l * n_dot_v);
}

vec3 anisotropic_prefiltered_radiance(Surface s, vec3 n, vec3 v, vec3 d, bool with_suns) {
    return prefiltered_radiance_at(d, s.roughness, with_suns);
}

#endif
