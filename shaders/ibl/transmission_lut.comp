#version 450 core
// The refracted lobe of KHR_materials_volume's BTDF over n.v (x), roughness (y) and the ior
// (z = (1 - 1/ior) / IOR_AXIS_MAX, common/transmission_lut.glsl), at texel centres, k = r^2/2 (docs/layer_transmission.md, "Real-time"):
//   R: E, the lobe's energy: the integral of btdf (1 - Fc(v.h)) |n.l| over l;
//   G: bend, the sine of its mean direction's angle from -n (leaning toward -v's tangential
//      part) over the view's sine: 1/ior for a smooth surface; a ratio so that it vanishes
//      with the view's sine at n.v = 1 (the last texel centre is n.v = 0.984, not 1);
//   B: the prefiltered roughness whose kernel has the lobe's mean cosine about that direction,
//      so that one prefiltered fetch along the mean stands for the whole lobe;
//   A: 0.
// h is drawn with pdf D(h)(n.h) and refracted: l = refract(-v, h, 1/ior) (Walter et al. 2007);
// the BTDF |n.l| / pdf(l) is then G (v.h) / ((n.h)(n.v)), as for the BRDF LUT.
// Numpy twin: app/accuracy/converged.py's transmission_lut_converged.
#include "common/brdf.glsl"
#include "common/sampling.glsl"
#include "common/transmission_lut.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform writeonly image3D u_lut;
uniform ivec3 u_size;
uniform uint u_samples;

// Midpoints of the GGX inverse CDF for the prefilter kernel's mean cosine (1D: v = n).
const int KERNEL_STEPS = 1024;
// Bisection steps for the roughness: 2^-20 of the roughness range.
const int BISECTION_STEPS = 20;

// Mean cosine about d of the prefiltered map's kernel D(h) max(d.l, 0) at a roughness
// (v = n = d, l = reflect(-n, h), so n.l = 2 (n.h)^2 - 1).
float prefilter_kernel_mean_cosine(float roughness) {
    float a = roughness * roughness;
    float a2 = a * a;
    float second = 0.0;
    float first = 0.0;
    for (int i = 0; i < KERNEL_STEPS; ++i) {
        float u = (float(i) + 0.5) / float(KERNEL_STEPS);
        float n_dot_l = max(2.0 * (1.0 - u) / (1.0 + (a2 - 1.0) * u) - 1.0, 0.0);
        second += n_dot_l * n_dot_l;
        first += n_dot_l;
    }
    return a2 > 0.0 ? second / max(first, 1e-30) : 1.0;
}

float roughness_for_mean_cosine(float mean_cosine) {
    float lo = 0.0;
    float hi = 1.0;
    for (int i = 0; i < BISECTION_STEPS; ++i) {
        float mid = 0.5 * (lo + hi);
        if (prefilter_kernel_mean_cosine(mid) < mean_cosine) hi = mid; else lo = mid;
    }
    return 0.5 * (lo + hi);
}

vec4 integrate_btdf(float n_dot_v, float roughness, float ior) {
    vec3 v = vec3(sqrt(1.0 - n_dot_v * n_dot_v), 0.0, n_dot_v);
    float k = k_ibl(roughness);
    float energy = 0.0;
    vec2 mean = vec2(0.0);   // (x, z) of the weighted directions; y averages out
    for (uint i = 0u; i < u_samples; ++i) {
        vec3 h = importance_sample_ggx_tangent(hammersley(i, u_samples), roughness);
        float v_dot_h = dot(v, h);
        vec3 l = refract(-v, h, 1.0 / ior);
        if (l.z < 0.0 && v_dot_h > 0.0) {
            float fc = pow(1.0 - min(v_dot_h, 1.0), 5.0);
            float w = (1.0 - fc) * G_Smith(n_dot_v, -l.z, k) * v_dot_h / (max(h.z, 1e-8) * n_dot_v);
            energy += w;
            mean += w * l.xz;
        }
    }
    float length_mean = length(mean);
    float sin_v = sqrt(max(1.0 - n_dot_v * n_dot_v, 0.0));
    float bend = length_mean > 0.0 && sin_v > 0.0 ? -mean.x / length_mean / sin_v : 1.0 / ior;
    float mean_cosine = energy > 0.0 ? length_mean / energy : 1.0;
    return vec4(energy / float(u_samples), bend, roughness_for_mean_cosine(mean_cosine), 0.0);
}

void main() {
    ivec3 texel = ivec3(gl_GlobalInvocationID.xy, gl_WorkGroupID.z);
    if (any(greaterThanEqual(texel, u_size))) return;
    vec3 coord = (vec3(texel) + 0.5) / vec3(u_size);
    float n_dot_v = max(coord.x, 1e-4);
    imageStore(u_lut, texel, integrate_btdf(n_dot_v, coord.y, ior_of_lut_axis(coord.z)));
}
