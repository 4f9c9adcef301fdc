#version 450 core
// Evaluates the clearcoat's and the sheen's GLSL functions per row of inputs, so that
// tests/test_clearcoat.py and tests/test_sheen.py can compare them with their numpy twins
// (app/core/layers/clearcoat.py, sheen.py). Compiled with HAS_CLEARCOAT and HAS_SHEEN. The
// surface: n = n_c = +z, v = (sqrt(1 - a.x^2), 0, a.x); the layer's factors are uniforms
// (common/material_layers.glsl); u_punctual and u_spread pick the light's kind. Not used for rendering.
#include "common/shading.glsl"
#include "common/material_layers.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 u_inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 u_outputs[]; };
uniform int u_count;
uniform int u_term;
uniform bool u_punctual;
uniform float u_spread;

const int TERM_CLEARCOAT_LIGHT = 0;        // a = (n.v, l): o.x
const int TERM_CLEARCOAT_BASE_WEIGHT = 1;  // a = (n.v): o.x
const int TERM_SHEEN_LIGHT = 2;            // a = (n.v, l): o.xyz
const int TERM_SHEEN_BASE_WEIGHT = 3;      // a = (n.v, l): o.x
const int TERM_SHEEN_BASE_WEIGHT_IBL = 4;  // a = (n.v): o.x
const int TERM_CHARLIE = 5;                // a = (n.h, n.v, n.l, alpha): (D, V, Lambda(n.v), 0)

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(u_count)) return;
    vec4 a = u_inputs[i];
    vec3 n = vec3(0.0, 0.0, 1.0);
    vec3 v = vec3(sqrt(max(1.0 - a.x * a.x, 0.0)), 0.0, a.x);
    vec3 l = a.yzw;
    Surface s = surface_base(vec3(0.5), 0.0, 0.5, vec3(0.04), vec3(0.0), 1.0);
    vec3 t = vec3(1.0, 0.0, 0.0);
    apply_material_layers(s, n, t, cross(n, t));
    vec4 o = vec4(0.0);
    switch (u_term) {
        case TERM_CLEARCOAT_LIGHT: o.x = clearcoat_light(s, v, l, u_punctual, u_spread).x; break;
        case TERM_CLEARCOAT_BASE_WEIGHT: o.x = clearcoat_base_weight(s, v); break;
        case TERM_SHEEN_LIGHT: o.xyz = sheen_light(s, n, v, l, u_punctual, u_spread); break;
        case TERM_SHEEN_BASE_WEIGHT: o.x = sheen_base_weight(s, n, v, l); break;
        case TERM_SHEEN_BASE_WEIGHT_IBL: o.x = sheen_base_weight_ibl(s, n, v); break;
        case TERM_CHARLIE: o = vec4(D_Charlie(a.x, a.w), V_Charlie(a.y, a.z, a.w), sheen_lambda(a.y, a.w), 0.0); break;
    }
    u_outputs[i] = o;
}
