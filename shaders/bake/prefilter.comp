#version 450 core
// Specular prefiltering, one roughness per grid step, as the seed lecture: N = V = R, half
// vectors by GGX importance sampling of Hammersley points, each reflected sample weighted by n.l.
// The sample set depends only on the roughness, so app/bake.py computes it once per step
// (prefilter_sample_set): directions l in the tangent frame of n (samples below the horizon
// already dropped) and, for filtered importance sampling (Krivanek and Colbert 2008, GPU Gems 3
// ch. 20), the source mip whose texel matches each sample's solid angle.
#include "common/brdf.glsl"
#include "common/sampling.glsl"
#include "common/cubemap.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform writeonly imageCube u_prefiltered;
layout(std430, binding = 1) readonly buffer SampleSet { vec4 u_sample_set[]; };  // xyz: l, w: lod
uniform samplerCube u_environment;
uniform int u_size;
uniform int u_sample_count;

void main() {
    ivec3 texel = ivec3(gl_GlobalInvocationID);
    if (texel.x >= u_size || texel.y >= u_size) return;
    mat3 frame = tangent_frame(cube_texel_direction(texel, u_size));
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int i = 0; i < u_sample_count; ++i) {
        vec4 s = u_sample_set[i];
        sum += textureLod(u_environment, frame * s.xyz, s.w).rgb * s.z;  // s.z = n.l
        weight += s.z;
    }
    imageStore(u_prefiltered, texel, vec4(sum / max(weight, 1e-8), 1.0));
}
