// The prefilter's sum for one direction, shared by the compute pass (ibl/prefilter.comp) and
// its fragment twin (ibl/prefilter.frag, kept to measure compute against fragment shaders).
// The sample set depends only on the roughness, so app/ibl/bake.py computes it once per step
// (prefilter_sample_set): directions l in the tangent frame of n = v (samples below the horizon
// already dropped) and the source mip of filtered importance sampling for each.
#include "common/sampling.glsl"

layout(std430, binding = 1) readonly buffer SampleSet { vec4 u_sample_set[]; };  // xyz: l, w: lod
uniform samplerCube u_environment;
uniform int u_sample_count;      // samples kept (above the horizon)

vec3 prefilter_radiance(vec3 n) {
    mat3 frame = tangent_frame(n);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int i = 0; i < u_sample_count; ++i) {
        vec4 s = u_sample_set[i];
        sum += textureLod(u_environment, frame * s.xyz, s.w).rgb * s.z;  // s.z = n.l
        weight += s.z;
    }
    // Compact sources are not in this environment (app/ibl/sun.py): the sum estimates
    // (N/4) * integral of L (n.l) D(h) over l (l has pdf D(h)/4 when v = n), so a delta source of
    // power P would add (N/4) P (n.l) D(h) / weight; ibl.glsl adds exactly that per pixel, with
    // the scale (N/4) / weight that app/ibl/bake.py records per roughness step.
    return sum / max(weight, 1e-8);
}
