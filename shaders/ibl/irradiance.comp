#version 450 core
// Diffuse irradiance by the lecture's hemisphere convolution: a regular (phi, theta) grid over
// the hemisphere of n, each sample weighted by cos(theta) sin(theta). Midpoints of the grid
// cells and normalising by the weights' own sum make a constant environment give exactly 1.
// Stores E/pi, the cosine-weighted mean radiance (what the lecture calls irradiance), of the
// environment without its compact sources: the forward pass adds those exactly (ibl.glsl).
#include "common/brdf.glsl"
#include "common/sampling.glsl"
#include "common/cubemap.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform writeonly imageCube u_irradiance;
uniform samplerCube u_environment;
uniform int u_size;
uniform int u_phi_steps;
uniform int u_theta_steps;
uniform float u_source_mip;   // a blurred source is enough: irradiance is smooth

void main() {
    ivec3 texel = ivec3(gl_GlobalInvocationID);
    if (texel.x >= u_size || texel.y >= u_size) return;
    vec3 n = cube_texel_direction(texel, u_size);
    mat3 frame = tangent_frame(n);
    vec3 sum = vec3(0.0);
    float weight_sum = 0.0;
    float d_phi = 2.0 * PI / float(u_phi_steps);
    float d_theta = 0.5 * PI / float(u_theta_steps);
    for (int t = 0; t < u_theta_steps; ++t) {
        float theta = (float(t) + 0.5) * d_theta;
        float w = cos(theta) * sin(theta);
        for (int p = 0; p < u_phi_steps; ++p) {
            float phi = (float(p) + 0.5) * d_phi;
            vec3 local = vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
            sum += w * textureLod(u_environment, frame * local, u_source_mip).rgb;
        }
        weight_sum += w * float(u_phi_steps);
    }
    imageStore(u_irradiance, texel, vec4(sum / weight_sum, 1.0));
}
