#version 450 core
// Evaluates one transmission function per row of inputs (tests/gpu.py's evaluate, with
// shader="accuracy/evaluate_transmission.comp" and HAS_TRANSMISSION, HAS_VOLUME (HAS_DISPERSION) defined), for
// tests/test_glsl_twins.py to compare with the numpy twins (app/core/btdf.py,
// app/core/layers/transmission.py). Not used for rendering.
#include "common/shading.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 u_inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 u_outputs[]; };
uniform int u_count;
uniform int u_term;
uniform vec4 u_params;   // per-term constants
uniform float u_spread;  // TERM_TRANSMISSION_LIGHT: a compact source's angular radius
uniform float u_dispersion_factor;  // TERM_TRANSMISSION_LIGHT with HAS_DISPERSION: the dispersion

const int TERM_BTDF_THIN = 0;
const int TERM_BTDF_REFRACTION = 1;
const int TERM_BEER_LAMBERT = 2;
const int TERM_TRANSMISSION_LIGHT = 3;
const int TERM_DISPERSION_IORS = 4;
const int TERM_DIFFUSE_BTDF_COS = 5;
const int TERM_DIFFUSE_TRANSMISSION_LIGHT = 6;

// Unit v and l about n = +Z: v in the xz plane at n.v; l at n.l (< 0: behind) and azimuth phi.
vec3 view_at(float n_dot_v) {
    return vec3(sqrt(max(0.0, 1.0 - n_dot_v * n_dot_v)), 0.0, n_dot_v);
}
vec3 light_at(float n_dot_l, float phi) {
    float s = sqrt(max(0.0, 1.0 - n_dot_l * n_dot_l));
    return vec3(s * cos(phi), s * sin(phi), n_dot_l);
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(u_count)) return;
    vec4 a = u_inputs[i];
    vec4 o = vec4(0.0);
    vec3 n = vec3(0.0, 0.0, 1.0);
    switch (u_term) {
        case TERM_BTDF_THIN:
            // a = (n.v, n.l, n.h, roughness): the IBL k and the punctual k.
            o.xy = vec2(btdf_thin(a.x, a.y, a.z, a.w, k_ibl(a.w)), btdf_thin(a.x, a.y, a.z, a.w, k_direct(a.w)));
            break;
        case TERM_BTDF_REFRACTION: {
            // a = (n.v, n.l, roughness, ior), l on the far side from v (azimuth pi).
            vec3 v = view_at(a.x);
            vec3 l = light_at(a.y, PI);
            vec3 h = half_vector_refraction(v, l, a.w);
            o.xy = vec2(btdf_refraction(a.x, a.y, dot(n, h), dot(v, h), dot(l, h), a.z, a.w, k_ibl(a.z)), dot(v, h));
            break;
        }
        case TERM_BEER_LAMBERT:
            // a = (attenuation colour, distance); u_params.x = attenuation distance.
            o.xyz = beer_lambert(a.xyz, u_params.x, a.w);
            break;
        case TERM_TRANSMISSION_LIGHT: {
            // a = (n.l, n.v, roughness, phi); u_params = (ior, thickness, metallic, punctual).
            Surface s = surface_base(vec3(0.9, 0.6, 0.3), u_params.z, a.z, vec3(0.05, 0.04, 0.03), vec3(0.0), 1.0);
            s.transmission = 0.8;
            s.ior = u_params.x;
            s.thickness = u_params.y;
            s.attenuation_color = vec3(1.0, 0.8, 0.5);
            s.attenuation_distance = 0.7;
#ifdef HAS_DISPERSION
            s.dispersion = u_dispersion_factor;
#endif
            o.xyz = transmission_light(s, n, view_at(a.y), light_at(a.x, a.w), u_params.w > 0.5, u_spread);
            break;
        }
        case TERM_DISPERSION_IORS:
            // a = (ior, dispersion).
            o.xyz = dispersion_iors(a.x, a.y);
            break;
        case TERM_DIFFUSE_BTDF_COS:
            // a = (colour, n.l).
            o.xyz = diffuse_btdf_cos(a.xyz, a.w);
            break;
#ifdef HAS_DIFFUSE_TRANSMISSION
        case TERM_DIFFUSE_TRANSMISSION_LIGHT: {
            // a = (n.l, n.v, transmission, phi); u_params = (ior, thickness, metallic, diffuse_transmission).
            Surface s = surface_base(vec3(0.9, 0.6, 0.3), u_params.z, 0.4, vec3(0.05, 0.04, 0.03), vec3(0.0), 1.0);
            s.transmission = a.z;
            s.ior = u_params.x;
            s.thickness = u_params.y;
            s.attenuation_color = vec3(1.0, 0.8, 0.5);
            s.attenuation_distance = 0.7;
            s.diffuse_transmission = u_params.w;
            s.diffuse_transmission_color = vec3(0.2, 0.9, 0.6);
            o.xyz = diffuse_transmission_light(s, n, view_at(a.y), light_at(a.x, a.w));
            o.w = diffuse_transmission_front_weight(s);
            break;
        }
#endif
    }
    u_outputs[i] = o;
}
