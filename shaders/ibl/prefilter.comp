#version 450 core
// Specular prefiltering, one roughness per grid step, as the lecture: N = V = R, half
// vectors by GGX importance sampling of Hammersley points, each reflected sample weighted by n.l,
// with filtered importance sampling (Krivanek and Colbert 2008, GPU Gems 3 ch. 20).
#include "common/brdf.glsl"
#include "common/cubemap.glsl"
#include "common/prefilter.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform writeonly imageCube u_prefiltered;
uniform int u_size;
uniform int u_face_offset;   // a dispatch may cover fewer faces (the editor's bake in steps)

void main() {
    ivec3 texel = ivec3(gl_GlobalInvocationID) + ivec3(0, 0, u_face_offset);
    if (texel.x >= u_size || texel.y >= u_size) return;
    imageStore(u_prefiltered, texel, vec4(prefilter_radiance(cube_texel_direction(texel, u_size)), 1.0));
}
