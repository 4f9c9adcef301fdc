#version 450 core
// Fills the irradiance cube from 9 SH coefficients, so the forward pass reads one kind of map.
#include "common/brdf.glsl"
#include "common/cubemap.glsl"
#include "common/sh9.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform writeonly imageCube u_irradiance;
uniform int u_size;
uniform vec3 u_coeffs[9];

void main() {
    ivec3 texel = ivec3(gl_GlobalInvocationID);
    if (texel.x >= u_size || texel.y >= u_size) return;
    vec3 c[9] = u_coeffs;
    imageStore(u_irradiance, texel, vec4(sh9_irradiance_over_pi(c, cube_texel_direction(texel, u_size)), 1.0));
}
