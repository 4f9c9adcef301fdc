#version 450 core
// The sheen LUT over n.v (x) and sheen roughness (y) at texel centres (app/core/layers/sheen.py:
// lut_row is its numpy twin; docs/layer_sheen.md):
//   R: E, the directional albedo of the Charlie sheen lobe D V (n.l) (Estevez and Kulla 2017):
//      the albedo scaling of the layers below and the lobe's weight under the environment;
//   G: sin(phi), phi the angle of the lobe's mean direction from n toward v's side;
//   B: the prefilter roughness whose kernel has the lobe's mean cosine about that direction.
// Under the environment the sheen reads the prefiltered radiance at that direction and roughness
// (common/sheen.glsl: sheen_ibl): the lobe sits near the horizon, far from R, so the split
// sum's R would look the wrong way. A midpoint rule over (theta_l, phi_l), nothing sampled.
#include "common/brdf.glsl"
#include "common/sheen_terms.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform writeonly image2D u_lut;
uniform int u_size;
uniform int u_steps;   // midpoint steps per angle (app/core/layers/sheen.py: _QUADRATURE)

// The mean cosine of the prefilter's kernel at roughness rho (prefilter.glsl's weight
// D(h) max(d.l, 0), n = v = d), by a midpoint rule in c = d.l.
float prefilter_mean_cosine(float rho) {
    const int STEPS = 256;
    float a2m1 = rho * rho * rho * rho - 1.0;
    float num = 0.0;
    float den = 0.0;
    for (int i = 0; i < STEPS; ++i) {
        float c = (float(i) + 0.5) / float(STEPS);
        float d = 0.5 * (1.0 + c) * a2m1 + 1.0;
        float w = c / (d * d);
        num += c * w;
        den += w;
    }
    return num / den;
}

// The roughness whose kernel has mean cosine cbar (bisection; the mean cosine falls with rho).
float prefilter_roughness_for(float cbar) {
    float lo = 0.05;
    float hi = 1.0;
    for (int i = 0; i < 24; ++i) {
        float mid = 0.5 * (lo + hi);
        if (prefilter_mean_cosine(mid) > cbar) lo = mid; else hi = mid;
    }
    return 0.5 * (lo + hi);
}

vec4 sheen_lut_texel(float n_dot_v, float roughness) {
    float mu = max(n_dot_v, MIN_N_DOT_V);
    vec2 v = vec2(sqrt(1.0 - mu * mu), mu);   // (x, z); v.y = 0
    float d_theta = 0.5 * PI / float(u_steps);
    float d_phi = PI / float(u_steps);
    float e = 0.0;
    vec2 m = vec2(0.0);
    for (int i = 0; i < u_steps; ++i) {
        float theta = (float(i) + 0.5) * d_theta;
        float st = sin(theta);
        float ct = cos(theta);
        float row_e = 0.0;
        vec2 row_m = vec2(0.0);
        for (int j = 0; j < u_steps; ++j) {
            float phi = (float(j) + 0.5) * d_phi;
            vec3 l = vec3(st * cos(phi), st * sin(phi), ct);
            vec3 h = l + vec3(v.x, 0.0, v.y);
            float n_dot_h = h.z * inversesqrt(dot(h, h));
            float f = sheen_lobe(l.z, mu, n_dot_h, roughness);
            row_e += f;
            row_m += f * l.xz;
        }
        float w = st * d_theta * d_phi * 2.0;   // phi in [0, pi) stands for both halves
        e += row_e * w;
        m += row_m * w;
    }
    float len = length(m);
    if (e <= 0.0 || len <= 0.0) return vec4(max(e, 0.0), 0.0, 1.0, 0.0);
    return vec4(e, m.x / len, prefilter_roughness_for(len / e), 0.0);
}

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (texel.x >= u_size || texel.y >= u_size) return;
    vec2 coord = (vec2(texel) + 0.5) / float(u_size);
    imageStore(u_lut, texel, sheen_lut_texel(coord.x, coord.y));
}
