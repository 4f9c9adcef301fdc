#version 450 core
// Projection of the environment onto the 9 real spherical harmonics of order <= 2
// (Ramamoorthi and Hanrahan 2001): each work group sums its texels' L Y_i dOmega and writes one
// partial sum; the few partial sums are added up on the CPU.
#include "common/brdf.glsl"
#include "common/equirect.glsl"
#include "common/sh9.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(std430, binding = 0) writeonly buffer Partials { vec4 u_partials[]; };  // 9 per group
uniform sampler2D u_equirect;
uniform int u_level;       // mip of the equirect to read: order 2 needs little resolution
uniform ivec2 u_level_size;

shared vec3 s_sum[64][9];

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    uint local = gl_LocalInvocationIndex;
    float coeffs[9];
    vec3 radiance = vec3(0.0);
    for (int i = 0; i < 9; ++i) coeffs[i] = 0.0;
    if (texel.x < u_level_size.x && texel.y < u_level_size.y) {
        vec2 uv = (vec2(texel) + 0.5) / vec2(u_level_size);
        vec3 d = equirect_uv_to_direction(uv);
        float omega = (2.0 * PI / float(u_level_size.x)) * (PI / float(u_level_size.y)) * sin(uv.y * PI);
        radiance = texelFetch(u_equirect, texel, u_level).rgb * omega;
        sh9_basis(d, coeffs);
    }
    for (int i = 0; i < 9; ++i) s_sum[local][i] = radiance * coeffs[i];
    barrier();
    for (uint stride = 32u; stride > 0u; stride >>= 1) {
        if (local < stride) {
            for (int i = 0; i < 9; ++i) s_sum[local][i] += s_sum[local + stride][i];
        }
        barrier();
    }
    if (local == 0u) {
        uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
        for (int i = 0; i < 9; ++i) u_partials[group * 9u + uint(i)] = vec4(s_sum[0][i], 0.0);
    }
}
