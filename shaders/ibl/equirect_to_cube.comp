#version 450 core
// Equirectangular map -> level 0 of the source cubemap, each texel the mean of a few
// sub-texel samples so a finer map does not alias.
#include "common/brdf.glsl"
#include "common/equirect.glsl"
#include "common/cubemap.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform writeonly imageCube u_cube;
uniform sampler2D u_equirect;
uniform int u_size;
uniform int u_subsamples;   // per axis

void main() {
    ivec3 texel = ivec3(gl_GlobalInvocationID);
    if (texel.x >= u_size || texel.y >= u_size) return;
    vec3 sum = vec3(0.0);
    for (int j = 0; j < u_subsamples; ++j) {
        for (int i = 0; i < u_subsamples; ++i) {
            vec2 offset = (vec2(i, j) + 0.5) / float(u_subsamples) - 0.5;
            vec2 st = 2.0 * (vec2(texel.xy) + 0.5 + offset) / float(u_size) - 1.0;
            vec3 d = normalize(cube_face_direction(texel.z, st));
            sum += textureLod(u_equirect, direction_to_equirect_uv(d), 0.0).rgb;
        }
    }
    imageStore(u_cube, texel, vec4(sum / float(u_subsamples * u_subsamples), 1.0));
}
