#version 450 core
// The split sum's energy for KHR_materials_anisotropy's stretched lobe, as a ratio to the round
// lobe's (brdf_lut.comp's A and B), over n.v (x), roughness (y) and strength (z), at texel
// centres (strength at k / (n - 1), so that strength 0 is a centre), k = alpha/2 at each
// direction's projected alpha (docs/layer_anisotropy.md):
//   u_ratio_a: A_stretched / A_round with the view's azimuth from the direction at 0, 30, 60, 90 degrees;
//   u_ratio_b: the same for B.
// Both lobes are integrated with the same Hammersley points through the same sampler
// (importance_sample_ggx_anisotropic reduces to the round one at strength 0), so the ratio is 1
// at strength 0 to float rounding: a zero-strength layer changes nothing. The stretched lobe
// loses far more energy than the round one (masking at grazing azimuths, a lobe reaching under
// the horizon): at r = 0.3, strength 1 its albedo is 0.40-0.69 where the round lobe's is
// 0.74-0.98, so the round lobe's LUT alone would be up to 2.4x too bright.
// Numpy twin: app/core/layers/anisotropy.py's anisotropy_lut_converged.
#include "common/brdf.glsl"
#include "common/sampling.glsl"
#include "common/anisotropic_ggx.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(rgba32f, binding = 0) uniform writeonly image3D u_ratio_a;
layout(rgba32f, binding = 1) uniform writeonly image3D u_ratio_b;
uniform ivec3 u_size;
uniform uint u_samples;

// (A, B) of the lobe (alpha_t, alpha_b) for the view v (tangent space, x along the direction).
vec2 integrate_energy(vec3 v, float alpha_t, float alpha_b) {
    float n_dot_v = v.z;
    float k_v = projected_alpha(v.x, v.y, alpha_t, alpha_b) / 2.0;
    vec2 sum = vec2(0.0);
    for (uint i = 0u; i < u_samples; ++i) {
        vec3 h = importance_sample_ggx_anisotropic(hammersley(i, u_samples), alpha_t, alpha_b);
        float v_dot_h = dot(v, h);
        vec3 l = 2.0 * v_dot_h * h - v;
        if (l.z > 0.0 && v_dot_h > 0.0) {
            // f (n.l) / pdf(l) without F (as brdf_lut.comp): G v.h / (n.h n.v).
            float k_l = projected_alpha(l.x, l.y, alpha_t, alpha_b) / 2.0;
            float g_vis = G1_SchlickGGX(n_dot_v, k_v) * G1_SchlickGGX(l.z, k_l) * v_dot_h / (h.z * n_dot_v);
            float fc = pow(1.0 - v_dot_h, 5.0);
            sum += vec2(1.0 - fc, fc) * g_vis;
        }
    }
    return sum / float(u_samples);
}

void main() {
    ivec3 texel = ivec3(gl_GlobalInvocationID.xyz);
    if (any(greaterThanEqual(texel, u_size))) return;
    vec2 coord = (vec2(texel.xy) + 0.5) / vec2(u_size.xy);
    float n_dot_v = coord.x;
    float strength = float(texel.z) / float(max(u_size.z - 1, 1));
    vec2 alpha = anisotropic_alpha(coord.y, strength);
    float round_alpha = alpha.y;
    float sin_v = sqrt(1.0 - n_dot_v * n_dot_v);
    vec4 ratio_a, ratio_b;
    for (int j = 0; j < 4; ++j) {
        float azimuth = radians(30.0 * float(j));
        vec3 v = vec3(sin_v * cos(azimuth), sin_v * sin(azimuth), n_dot_v);
        vec2 stretched = integrate_energy(v, alpha.x, alpha.y);
        vec2 round = integrate_energy(v, round_alpha, round_alpha);
        ratio_a[j] = round.x > 0.0 ? stretched.x / round.x : 1.0;
        ratio_b[j] = round.y > 0.0 ? stretched.y / round.y : 1.0;
    }
    imageStore(u_ratio_a, texel, ratio_a);
    imageStore(u_ratio_b, texel, ratio_b);
}
