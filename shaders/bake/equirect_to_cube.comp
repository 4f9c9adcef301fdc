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
            // Same face table as cube_texel_direction, at a sub-texel position.
            vec3 d;
            switch (texel.z) {
                case 0: d = vec3(1.0, -st.y, -st.x); break;
                case 1: d = vec3(-1.0, -st.y, st.x); break;
                case 2: d = vec3(st.x, 1.0, st.y); break;
                case 3: d = vec3(st.x, -1.0, -st.y); break;
                case 4: d = vec3(st.x, -st.y, 1.0); break;
                default: d = vec3(-st.x, -st.y, -1.0); break;
            }
            sum += textureLod(u_equirect, direction_to_equirect_uv(normalize(d)), 0.0).rgb;
        }
    }
    imageStore(u_cube, texel, vec4(sum / float(u_subsamples * u_subsamples), 1.0));
}
