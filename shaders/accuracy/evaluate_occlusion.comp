#version 450 core
// Evaluates the occlusion functions of common/occlusion.glsl per row of inputs (tests/gpu.py's
// evaluate, with shader="accuracy/evaluate_occlusion.comp"), for tests/test_occlusion.py to
// compare with their numpy twins (app/core/visibility.py). Not used for rendering.
#include "common/shading.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 u_inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 u_outputs[]; };
uniform int u_count;
uniform int u_term;

const int TERM_CAPS_INTERSECTION = 0;   // (cos cap 1, cos cap 2, cos distance)
const int TERM_CONE_APERTURE = 1;       // (V)
const int TERM_SPECULAR_OCCLUSION = 2;  // (bent.r, n.r, V, roughness)
const int TERM_MAPPED_BENT_NORMAL = 3;  // (n, bent as polar, azimuth angles about the vertex normal +Z)
const int TERM_OCCLUDER_VISIBILITY = 4; // (bounce weight, V)
const int TERM_OCCLUDERS_REFLECTANCE = 5; // (hit albedo rgb, hit visibility)
const int TERM_SUNS_ON_OCCLUDERS = 6;     // (hit albedo rgb, hit visibility; first = 1, second = 1)
const int TERM_CONE = 7;                  // (V): cone_roughness, cone_blend
const int TERM_SKY_VISIBILITY = 8;        // (W r, W g, V_rays, V); W b = (W r + W g) / 2
const int TERM_VISIBLE_LOBE = 9;          // (W r, W g, V_rays, so); W b as above, E(n)/pi and the
                                          // prefiltered radiance the constants below
const int TERM_OCCLUDER_BASE_ALBEDO = 10;     // (base rgb, metallic), specular_f0 0.04
const int TERM_RECORDED_OCCLUDER_ALBEDO = 11; // (hit rgb, s): own = s OWN_ALBEDO, own_recorded = OWN_RECORDED
const int TERM_BOUNCE_IRRADIANCE = 12;        // (mean length, along r, against, along g): along
                                              // (r, g, g), against grey
const vec3 OWN_ALBEDO = vec3(0.3, 0.5, 0.7);
const vec3 OWN_RECORDED = vec3(0.25, 0.45, 0.6);
const vec3 LOBE_IRRADIANCE = vec3(0.8, 0.5, 0.3);
const vec3 LOBE_PREFILTERED = vec3(1.5, 0.2, 0.7);

vec3 polar_direction(float theta, float phi) {
    return vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(u_count)) return;
    vec4 a = u_inputs[i];
    vec4 o = vec4(0.0);
    switch (u_term) {
        case TERM_CAPS_INTERSECTION:
            o.x = spherical_caps_intersection(a.x, a.y, a.z);
            break;
        case TERM_CONE_APERTURE:
            o.x = cone_aperture_cos(a.x);
            break;
        case TERM_SPECULAR_OCCLUSION:
            o.x = specular_occlusion(a.x, a.y, a.z, a.w);
            break;
        case TERM_MAPPED_BENT_NORMAL:
            o.xyz = mapped_bent_normal(polar_direction(a.x, a.y), polar_direction(a.z, a.w), vec3(0.0, 0.0, 1.0));
            break;
        case TERM_OCCLUDER_VISIBILITY:
            o.x = occluder_visibility(a.x, a.y);
            break;
        case TERM_OCCLUDERS_REFLECTANCE:
            o.xyz = occluders_reflectance(a.xyz, a.w);
            break;
        case TERM_SUNS_ON_OCCLUDERS:
            o.xyz = suns_on_occluders(a.xyz, a.w, vec3(1.0), vec3(1.0));
            break;
        case TERM_CONE:
            o.x = cone_roughness(a.x);
            o.y = cone_blend(a.x);
            break;
        case TERM_SKY_VISIBILITY:
            o.xyz = sky_visibility(a.w, vec3(a.x, a.y, 0.5 * (a.x + a.y)), a.z);
            break;
        case TERM_VISIBLE_LOBE:
            o.xyz = visible_lobe_radiance(LOBE_PREFILTERED,
                visible_sky_radiance(vec3(a.x, a.y, 0.5 * (a.x + a.y)), a.z, LOBE_IRRADIANCE), a.w);
            break;
        case TERM_OCCLUDER_BASE_ALBEDO:
            o.xyz = occluder_base_albedo(a.xyz, a.w, vec3(0.04));
            break;
        case TERM_RECORDED_OCCLUDER_ALBEDO:
            o.xyz = recorded_occluder_albedo(a.w * OWN_ALBEDO, OWN_RECORDED, a.xyz);
            break;
        case TERM_BOUNCE_IRRADIANCE:
            o.xyz = bounce_irradiance(a.x, vec3(a.y, a.w, a.w), vec3(a.z, a.z, a.z));
            break;
    }
    u_outputs[i] = o;
}
