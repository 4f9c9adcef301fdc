// The Charlie sheen BRDF's terms (Estevez and Kulla 2017, "Production Friendly Microfacet Sheen
// BRDF"; as KHR_materials_sheen gives them), one function per term. Shared by common/sheen.glsl
// (shading) and ibl/sheen_lut.comp (the LUT); numpy twins: app/core/layers/sheen.py.

// Below this perceptual sheen roughness the distribution degenerates (1/alpha -> inf): the
// floor is part of the definition (docs/layer_sheen.md).
const float MIN_SHEEN_ROUGHNESS = 0.07;

float sheen_alpha(float roughness) {
    float r = max(roughness, MIN_SHEEN_ROUGHNESS);
    return r * r;
}

// The Charlie distribution: (2 + 1/a) sin^(1/a)(theta_h) / (2 pi) (Estevez and Kulla 2017).
float D_Charlie(float n_dot_h, float alpha) {
    float inv = 1.0 / alpha;
    float sin2 = max(1.0 - n_dot_h * n_dot_h, 0.0);
    return (2.0 + inv) * pow(sin2, 0.5 * inv) / (2.0 * PI);
}

// Estevez and Kulla's fit l(x) of the masking exponent, interpolated in (1 - alpha)^2.
float sheen_l(float x, float alpha) {
    float t = (1.0 - alpha) * (1.0 - alpha);
    float a = mix(21.5473, 25.3245, t);
    float b = mix(3.82987, 3.32435, t);
    float c = mix(0.19823, 0.16801, t);
    float d = mix(-1.97760, -1.27393, t);
    float e = mix(-4.32054, -4.85967, t);
    return a / (1.0 + b * pow(x, c)) + d * x + e;
}

// Lambda(cos theta) of the Charlie masking: exp(l(x)) below 0.5, mirrored above.
float sheen_lambda(float cos_theta, float alpha) {
    float x = abs(cos_theta);
    return x < 0.5 ? exp(sheen_l(x, alpha)) : exp(2.0 * sheen_l(0.5, alpha) - sheen_l(1.0 - x, alpha));
}

// The Charlie visibility 1 / ((1 + Lambda(n.v) + Lambda(n.l)) 4 n.v n.l) (height-correlated).
float V_Charlie(float n_dot_v, float n_dot_l, float alpha) {
    return 1.0 / ((1.0 + sheen_lambda(n_dot_v, alpha) + sheen_lambda(n_dot_l, alpha)) * (4.0 * n_dot_v * n_dot_l));
}

// D V (n.l) for unit sheen colour; 0 where n.l <= 0. n.v is clamped to MIN_N_DOT_V.
float sheen_lobe(float n_dot_l, float n_dot_v, float n_dot_h, float roughness) {
    if (n_dot_l <= 0.0) return 0.0;
    float alpha = sheen_alpha(roughness);
    float nv = max(n_dot_v, MIN_N_DOT_V);
    return D_Charlie(clamp(n_dot_h, 0.0, 1.0), alpha) * V_Charlie(nv, n_dot_l, alpha) * n_dot_l;
}
