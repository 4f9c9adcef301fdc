#version 450 core
// One mip of the source cube from the one above: each texel is the solid-angle-weighted mean of
// its 2x2 children, so every mip carries the same radiant power as level 0. (glGenerateMipmap's
// equal weights do not: children near face corners subtend less, and a small sun's power in the
// coarse mips that filtered importance sampling reads drifted by 3-20% with its position.)
#include "common/brdf.glsl"
#include "common/cubemap.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) readonly uniform imageCube u_finer;
layout(rgba32f, binding = 1) writeonly uniform imageCube u_coarser;
uniform int u_size;   // the coarser level's face size

void main() {
    ivec3 texel = ivec3(gl_GlobalInvocationID);
    if (texel.x >= u_size || texel.y >= u_size) return;
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int j = 0; j < 2; ++j) {
        for (int i = 0; i < 2; ++i) {
            ivec2 child = texel.xy * 2 + ivec2(i, j);
            float w = cube_texel_solid_angle_exact(child, 2 * u_size);
            sum += w * imageLoad(u_finer, ivec3(child, texel.z)).rgb;
            weight += w;
        }
    }
    imageStore(u_coarser, texel, vec4(sum / weight, 1.0));
}
