#version 450 core
// Evaluates tonemapping.glsl's tonemap(c, mode) per row of inputs (u_term = the TONEMAP_* mode),
// so tests/test_tonemaps.py can compare each curve with its numpy twin in app/core/shading.py.
// Not used for rendering.
#include "common/tonemapping.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 u_inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 u_outputs[]; };
uniform int u_count;
uniform int u_term;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(u_count)) return;
    u_outputs[i] = vec4(tonemap(u_inputs[i].xyz, u_term), 0.0);
}
