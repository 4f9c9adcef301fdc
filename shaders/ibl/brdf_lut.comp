#version 450 core
// The split sum's second factor over n.v (x) and roughness (y) at texel centres, k = r^2/2:
//   R, G: the lecture's integrate_brdf, a scale A and a bias B on F0 (Karis 2013);
//   B, A: where the specular lobe points: t_A and t_B place the direction
//         normalize(mix(n, R, t)) on the mean direction of the lobe f (n.l) weighted by the
//         (1 - Fc) part (t_A, the F0-scaled term) and by the Fc part (t_B, the bias term).
// The prefiltered map was filtered for n = v = R, a lobe centred on its lookup direction; the
// real lobe leans from R toward n as roughness grows and the view grazes (Lagarde and de
// Rousiers 2014, "Moving Frostbite to PBR", the specular dominant direction). Fetching at the
// lobe's own mean direction instead of R is what ibl.glsl's non-lecture models do; the mean
// is measured here from the BRDF instead of fitted by hand. Numpy twin:
// app/accuracy/converged.py's lobe_directions_converged.
#include "common/brdf.glsl"
#include "common/sampling.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform writeonly image2D u_lut;
uniform int u_size;
uniform uint u_samples;

// The t with normalize(mix(n, R, t)) at angle atan(m.x', m.z) from n toward R, for the mean
// vector m of a lobe (x' measured toward R); 1 (R itself) where the direction does not matter.
float lerp_factor_toward_reflection(vec2 toward_r_and_n, float n_dot_v) {
    float sin_v = sqrt(max(1.0 - n_dot_v * n_dot_v, 0.0));
    if (sin_v < 1e-4 || toward_r_and_n.y <= 0.0) return 1.0;
    float tan_phi = max(toward_r_and_n.x, 0.0) / toward_r_and_n.y;
    // The angle phi of normalize((1 - t) n + t R) from n obeys tan(phi) = t sin / (1 - t + t cos).
    return clamp(tan_phi / (sin_v + tan_phi * (1.0 - n_dot_v)), 0.0, 1.0);
}

vec4 integrate_brdf(float n_dot_v, float roughness) {
    vec3 v = vec3(sqrt(1.0 - n_dot_v * n_dot_v), 0.0, n_dot_v);
    float a = 0.0;
    float b = 0.0;
    vec2 mean_a = vec2(0.0);  // (component toward R, i.e. -x; component along n)
    vec2 mean_b = vec2(0.0);
    float k = k_ibl(roughness);
    for (uint i = 0u; i < u_samples; ++i) {
        vec3 h = importance_sample_ggx_tangent(hammersley(i, u_samples), roughness);
        vec3 l = normalize(2.0 * dot(v, h) * h - v);
        float n_dot_l = max(l.z, 0.0);
        float n_dot_h = max(h.z, 0.0);
        float v_dot_h = max(dot(v, h), 0.0);
        if (n_dot_l > 0.0) {
            // f (n.l) / pdf(l) without F: the weight of this sample in the lobe.
            float g_vis = G_Smith(n_dot_v, n_dot_l, k) * v_dot_h / (n_dot_h * n_dot_v);
            float fc = pow(1.0 - v_dot_h, 5.0);
            a += (1.0 - fc) * g_vis;
            b += fc * g_vis;
            mean_a += (1.0 - fc) * g_vis * vec2(-l.x, l.z);
            mean_b += fc * g_vis * vec2(-l.x, l.z);
        }
    }
    return vec4(vec2(a, b) / float(u_samples),
                lerp_factor_toward_reflection(mean_a, n_dot_v),
                lerp_factor_toward_reflection(mean_b, n_dot_v));
}

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (texel.x >= u_size || texel.y >= u_size) return;
    vec2 coord = (vec2(texel) + 0.5) / float(u_size);
    imageStore(u_lut, texel, integrate_brdf(coord.x, coord.y));
}
