// Exposure, tone mapping and the sRGB curve. Numpy twins: app/core/shading.py.

// TONEMAP_NONE, TONEMAP_ACES, ...: app/core/shader_names.py Tonemap, generated from app/core/scene.py's
// TONEMAPS: the Khronos glTF Sample Viewer's curves by their names there, and AgX
// (docs/guides/users-files.md says which peer uses which).

// Exposed radiance is limited to this before a curve: every curve is white (to 1/255) far
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

// Krzysztof Narkowicz's fit of the ACES curve ("ACES Filmic Tone Mapping Curve", 2016), applied
// per channel as the Sample Viewer's toneMapACES_Narkowicz does (without his 0.6 pre-scale).
vec3 tonemap_aces_narkowicz(vec3 c) {
    c = min(c, vec3(TONEMAP_INPUT_MAX));
    const float A = 2.51;
    const float B = 0.03;
    const float C = 2.43;
    const float D = 0.59;
    const float E = 0.14;
    return clamp((c * (A * c + B)) / (c * (C * c + D) + E), 0.0, 1.0);
}

// Hill's fit after dividing by 0.6: the exposure boost three.js (mrdoob/three.js#19621),
// model-viewer and the Sample Viewer's "ACES Filmic (Hill - Exposure Boost)" apply, +0.74 EV.
vec3 tonemap_aces_hill_exposure_boost(vec3 c) {
    return tonemap_aces_fitted(min(c, vec3(TONEMAP_INPUT_MAX)) / 0.6);
}

// AgX (Troy Sobotka; Blender's default view since 4.0) as Filament and three.js implement it:
// Rec.2020 primaries, the inset matrix, a log2 encoding over [-12.47, 4.03] EV about 0.18, the
// 6th-order sigmoid fit (iolite-engine's minimal AgX, mean error^2 3.7e-6), the outset matrix,
// a 2.2 power back to linear, and back to sRGB primaries; no look.
vec3 agx_default_contrast_approx(vec3 x) {
    vec3 x2 = x * x;
    vec3 x4 = x2 * x2;
    return 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x - 0.00232;
}

vec3 tonemap_agx(vec3 c) {
    c = min(c, vec3(TONEMAP_INPUT_MAX));
    const mat3 srgb_to_rec2020 = mat3(0.6274, 0.0691, 0.0164,
                                      0.3293, 0.9195, 0.0880,
                                      0.0433, 0.0113, 0.8956);
    const mat3 rec2020_to_srgb = mat3(1.6605, -0.1246, -0.0182,
                                      -0.5876, 1.1329, -0.1006,
                                      -0.0728, -0.0083, 1.1187);
    const mat3 inset = mat3(0.856627153315983, 0.137318972929847, 0.11189821299995,
                            0.0951212405381588, 0.761241990602591, 0.0767994186031903,
                            0.0482516061458583, 0.101439036467562, 0.811302368396859);
    const mat3 outset = mat3(1.1271005818144368, -0.1413297634984383, -0.14132976349843826,
                             -0.11060664309660323, 1.157823702216272, -0.11060664309660294,
                             -0.016493938717834573, -0.016493938717834257, 1.2519364065950405);
    const float min_ev = -12.47393;   // log2(2^-10 * 0.18)
    const float max_ev = 4.026069;    // log2(2^6.5 * 0.18)
    c = inset * (srgb_to_rec2020 * c);
    c = clamp((log2(max(c, vec3(1e-10))) - min_ev) / (max_ev - min_ev), 0.0, 1.0);
    c = outset * agx_default_contrast_approx(c);
    c = pow(max(c, vec3(0.0)), vec3(2.2));
    return clamp(rec2020_to_srgb * c, 0.0, 1.0);
}

// The curve a pass applies is compiled in (app/render/passes.py sets TONEMAP_MODE from the
// display): llvmpipe runs both sides of a branch, so a uniform mode paid for every curve at
// every pixel. (The default serves only programs compiled to check them, as the hot reload does.)
#ifndef TONEMAP_MODE
#define TONEMAP_MODE TONEMAP_ACES
#endif

vec3 tonemap(vec3 c, int mode) {
    if (mode == TONEMAP_ACES || mode == TONEMAP_ACES_HILL) return tonemap_aces_fitted(c);
    if (mode == TONEMAP_NEUTRAL) return tonemap_pbr_neutral(c);
    if (mode == TONEMAP_ACES_NARKOWICZ) return tonemap_aces_narkowicz(c);
    if (mode == TONEMAP_ACES_HILL_EXPOSURE_BOOST) return tonemap_aces_hill_exposure_boost(c);
    if (mode == TONEMAP_AGX) return tonemap_agx(c);
    return clamp(c, 0.0, 1.0);
}

// The sRGB transfer function (IEC 61966-2-1).
vec3 linear_to_srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
