#version 450 core
// The lecture's integrate_brdf: the split sum's second factor as a scale A and a bias B on F0,
// over n.v (x) and roughness (y) at texel centres, k = r^2/2 (Karis 2013).
#include "common/brdf.glsl"
#include "common/sampling.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rg32f, binding = 0) uniform writeonly image2D u_lut;
uniform int u_size;
uniform uint u_samples;

vec2 integrate_brdf(float n_dot_v, float roughness) {
    vec3 v = vec3(sqrt(1.0 - n_dot_v * n_dot_v), 0.0, n_dot_v);
    float a = 0.0;
    float b = 0.0;
    float k = k_ibl(roughness);
    for (uint i = 0u; i < u_samples; ++i) {
        vec3 h = importance_sample_ggx_tangent(hammersley(i, u_samples), roughness);
        vec3 l = normalize(2.0 * dot(v, h) * h - v);
        float n_dot_l = max(l.z, 0.0);
        float n_dot_h = max(h.z, 0.0);
        float v_dot_h = max(dot(v, h), 0.0);
        if (n_dot_l > 0.0) {
            float g_vis = G_Smith(n_dot_v, n_dot_l, k) * v_dot_h / (n_dot_h * n_dot_v);
            float fc = pow(1.0 - v_dot_h, 5.0);
            a += (1.0 - fc) * g_vis;
            b += fc * g_vis;
        }
    }
    return vec2(a, b) / float(u_samples);
}

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (texel.x >= u_size || texel.y >= u_size) return;
    vec2 coord = (vec2(texel) + 0.5) / float(u_size);
    imageStore(u_lut, texel, vec4(integrate_brdf(coord.x, coord.y), 0.0, 0.0));
}
