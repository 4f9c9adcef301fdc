// The prefilter's sum for one direction, shared by the compute pass (bake/prefilter.comp) and
// its fragment twin (bake/prefilter.frag, kept to measure compute against fragment shaders).
// The sample set depends only on the roughness, so app/bake.py computes it once per step
// (prefilter_sample_set): directions l in the tangent frame of n = v (samples below the horizon
// already dropped) and the source mip of filtered importance sampling for each.
#include "common/sampling.glsl"

layout(std430, binding = 1) readonly buffer SampleSet { vec4 u_sample_set[]; };  // xyz: l, w: lod
uniform samplerCube u_environment;
uniform int u_sample_count;      // samples kept (above the horizon)
uniform float u_sample_total;    // samples drawn, kept or not: the sum's normalisation
uniform float u_roughness;
#include "common/suns.glsl"

vec3 prefilter_radiance(vec3 n) {
    mat3 frame = tangent_frame(n);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int i = 0; i < u_sample_count; ++i) {
        vec4 s = u_sample_set[i];
        sum += textureLod(u_environment, frame * s.xyz, s.w).rgb * s.z;  // s.z = n.l
        weight += s.z;
    }
    // The sum estimates (N/4) * integral of L (n.l) D(h) over l, since l has pdf D(h)/4 when
    // v = n; a delta source of power P adds (N/4) P (n.l) D(h) to it exactly.
    for (int i = 0; i < u_sun_count; ++i) {
        float sun_n_dot_l = dot(n, u_sun_direction[i]);
        if (sun_n_dot_l > 0.0) {
            float n_dot_h = dot(n, normalize(u_sun_direction[i] + n));
            sum += 0.25 * u_sample_total * D_GGX(n_dot_h, u_roughness) * sun_n_dot_l * u_sun_power[i];
        }
    }
    return sum / max(weight, 1e-8);
}
