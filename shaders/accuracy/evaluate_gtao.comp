#version 450 core
// Evaluates common/gtao.glsl's functions per row of inputs (tests/gpu.py's evaluate, with
// shader="accuracy/evaluate_gtao.comp"), for tests/test_gtao.py to compare with their numpy
// twins (app/core/gtao.py). Not used for rendering.
#include "common/gtao.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 u_inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 u_outputs[]; };
uniform int u_count;
uniform int u_term;

const int TERM_SLICE_VISIBILITY = 0;  // (cos h1, cos h2, gamma, |n_p|)
const int TERM_BAND_WEIGHT = 1;       // (cos from, cos to, gamma, side), |n_p| 0.8
const int TERM_FACING_LIGHT = 2;      // (by_occluders r, as_point r, occluders' V, V): g, b = 2 r, 0.5 r
                                      // of each; ramp (-0.1, 0.05)
const int TERM_FALLOFF_WEIGHT = 3;    // (delta x, y, z, radius), v = (0, 0.6, 0.8), thickness 0.3, thin 4

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(u_count)) return;
    vec4 a = u_inputs[i];
    vec4 o = vec4(0.0);
    switch (u_term) {
        case TERM_SLICE_VISIBILITY:
            o.x = gtao_slice_visibility(a.x, a.y, a.z, a.w);
            break;
        case TERM_BAND_WEIGHT:
            o.x = gtao_band_weight(a.x, a.y, a.z, a.w, 0.8);
            break;
        case TERM_FACING_LIGHT:
            o.xyz = gtao_facing_light(a.x * vec3(1.0, 2.0, 0.5), a.y * vec3(1.0, 2.0, 0.5), a.z, a.w,
                                      vec2(-0.1, 0.05));
            break;
        case TERM_FALLOFF_WEIGHT:
            o.x = gtao_falloff_weight(a.xyz, vec3(0.0, 0.6, 0.8), a.w, 0.3, 4.0);
            break;
    }
    u_outputs[i] = o;
}
