#version 450 core
// Samples one mip of a cube into an equirectangular image (docs/conventions.md's mapping), so that
// baked maps can be looked at and compared with the source map.
#include "common/brdf.glsl"
#include "common/equirect.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) writeonly uniform image2D u_equirect;
uniform samplerCube u_cube;
uniform float u_lod;
uniform ivec2 u_size;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= u_size.x || p.y >= u_size.y) return;
    vec3 d = equirect_uv_to_direction((vec2(p) + 0.5) / vec2(u_size));
    imageStore(u_equirect, p, vec4(textureLod(u_cube, d, u_lod).rgb, 1.0));
}
