// Exposure, tone mapping and the sRGB curve. Numpy twins: app/core/shading.py.

// TONEMAP_NONE, TONEMAP_ACES, ...: app/core/shader_names.py Tonemap (generated).

// Exposed radiance is limited to this before a curve: both curves are white (to 1/255) far
// below it, so no pixel changes, and the ACES fit's v*v stays finite in float32 (a 1e30 texel,
// or 1e10 at +32 EV, made it inf/inf = NaN: a black PNG).
const float TONEMAP_INPUT_MAX = 1.0e6;

// Stephen Hill's fit of the ACES RRT+ODT (BakingLab 2016), sRGB primaries in and out.
vec3 tonemap_aces_fitted(vec3 c) {
    c = min(c, vec3(TONEMAP_INPUT_MAX));
    const mat3 m_in = mat3(0.59719, 0.07600, 0.02840,
                           0.35458, 0.90834, 0.13383,
                           0.04823, 0.01566, 0.83777);
    const mat3 m_out = mat3(1.60475, -0.10208, -0.00327,
                            -0.53108, 1.10813, -0.07276,
                            -0.07367, -0.00605, 1.07602);
    vec3 v = m_in * c;
    vec3 a = v * (v + 0.0245786) - 0.000090537;
    vec3 b = v * (0.983729 * v + 0.4329510) + 0.238081;
    return clamp(m_out * (a / b), 0.0, 1.0);
}

// Khronos PBR Neutral (Khronos 3D Commerce 2024): keeps base colours true up to 0.8.
vec3 tonemap_pbr_neutral(vec3 c) {
    c = min(c, vec3(TONEMAP_INPUT_MAX));
    const float start = 0.8 - 0.04;
    const float desaturation = 0.15;
    float x = min(c.r, min(c.g, c.b));
    float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    c -= offset;
    float peak = max(c.r, max(c.g, c.b));
    if (peak < start) return c;
    const float d = 1.0 - start;
    float new_peak = 1.0 - d * d / (peak + d - start);
    c *= new_peak / peak;
    float g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(c, vec3(new_peak), g);
}

// The curve a pass applies is compiled in (app/render/renderer.py sets TONEMAP_MODE from the
// display): llvmpipe runs both sides of a branch, so a uniform mode paid for both curves at
// every pixel. (The default serves only programs compiled to check them, as the hot reload does.)
#ifndef TONEMAP_MODE
#define TONEMAP_MODE TONEMAP_ACES
#endif

vec3 tonemap(vec3 c, int mode) {
    if (mode == TONEMAP_ACES) return tonemap_aces_fitted(c);
    if (mode == TONEMAP_NEUTRAL) return tonemap_pbr_neutral(c);
    return clamp(c, 0.0, 1.0);
}

// The sRGB transfer function (IEC 61966-2-1).
vec3 linear_to_srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
