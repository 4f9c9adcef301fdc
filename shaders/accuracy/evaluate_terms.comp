#version 450 core
// Evaluates one shared GLSL function per row of inputs, so tests can compare each function with
// its numpy twin in app/core/shading.py (tests/test_glsl_twins.py). Not used for rendering.
#include "common/shading.glsl"
#include "common/sampling.glsl"
#include "common/cubemap.glsl"
#include "common/tonemapping.glsl"
#include "common/sphere_surface.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 u_inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 u_outputs[]; };
uniform int u_count;
uniform int u_term;

const int TERM_D_GGX = 0;
const int TERM_G1 = 1;
const int TERM_G_SMITH = 2;
const int TERM_F_SCHLICK = 3;
const int TERM_F_SCHLICK_ROUGHNESS = 4;
const int TERM_DIRECTION_TO_EQUIRECT = 5;
const int TERM_EQUIRECT_TO_DIRECTION = 6;
const int TERM_ROTATE_WORLD_TO_MAP = 7;
const int TERM_HAMMERSLEY = 8;
const int TERM_IMPORTANCE_SAMPLE_GGX = 9;
const int TERM_ACES = 10;
const int TERM_NEUTRAL = 11;
const int TERM_SRGB = 12;
const int TERM_K = 13;
const int TERM_GRID_STEP = 14;
const int TERM_CUBE_TEXEL_DIRECTION = 15;
const int TERM_PUNCTUAL = 16;
const int TERM_SPOT_RANGE = 17;
const int TERM_SPHERE_SURFACE = 18;
const int TERM_SPHERE_UV = 19;
const int TERM_F_SCHLICK_F90 = 20;
const int TERM_NORMAL_MAP_ROUGHNESS = 21;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(u_count)) return;
    vec4 a = u_inputs[i];
    vec4 o = vec4(0.0);
    switch (u_term) {
        case TERM_D_GGX: o.x = D_GGX(a.x, a.y); break;
        case TERM_G1: o.x = G1_SchlickGGX(a.x, a.y); break;
        case TERM_G_SMITH: o.x = G_Smith(a.x, a.y, a.z); break;
        case TERM_F_SCHLICK: o.xyz = F_Schlick(a.x, vec3(a.y, a.z, a.w)); break;
        case TERM_F_SCHLICK_ROUGHNESS: o.xyz = F_SchlickRoughness(a.x, vec3(a.y), a.z); break;
        case TERM_DIRECTION_TO_EQUIRECT: o.xy = direction_to_equirect_uv(a.xyz); break;
        case TERM_EQUIRECT_TO_DIRECTION: o.xyz = equirect_uv_to_direction(a.xy); break;
        case TERM_ROTATE_WORLD_TO_MAP: {
            float t = radians(-a.w);
            o.xyz = rotate_world_to_map(a.xyz, vec2(cos(t), sin(t)));
            break;
        }
        case TERM_HAMMERSLEY: o.xy = hammersley(uint(a.x), uint(a.y)); break;
        case TERM_IMPORTANCE_SAMPLE_GGX: o.xyz = importance_sample_ggx_tangent(a.xy, a.z); break;
        case TERM_ACES: o.xyz = tonemap_aces_fitted(a.xyz); break;
        case TERM_NEUTRAL: o.xyz = tonemap_pbr_neutral(a.xyz); break;
        case TERM_SRGB: o.xyz = linear_to_srgb(a.xyz); break;
        case TERM_K: o.xy = vec2(k_direct(a.x), k_ibl(a.x)); break;
        case TERM_GRID_STEP: o.x = roughness_to_grid_step(a.x); break;
        case TERM_CUBE_TEXEL_DIRECTION: o.xyz = cube_texel_direction(ivec3(a.xyz), int(a.w)); break;
        case TERM_PUNCTUAL: {
            // One light straight along n; a = (n.l, roughness, metallic, base grey).
            Surface s = surface_base(vec3(a.w), a.z, a.y, vec3(0.04), vec3(0.0), 1.0);
            vec3 n = vec3(0.0, 0.0, 1.0);
            vec3 l = vec3(sqrt(max(0.0, 1.0 - a.x * a.x)), 0.0, a.x);
            o.xyz = punctual_light(s, n, n, l, vec3(1.0));
            break;
        }
        case TERM_SPOT_RANGE: {
            // a = (cos of the angle off the spot's axis, cone scale, cone offset, d^2 / range^2).
            vec3 l = -vec3(sqrt(max(0.0, 1.0 - a.x * a.x)), 0.0, a.x);   // toward the light
            o.x = spot_attenuation(vec3(0.0, 0.0, 1.0), l, a.yz);
            o.y = range_attenuation(a.w, 1.0);
            break;
        }
        // a = (facet point, the eye's distance on +z); the unit sphere.
        case TERM_SPHERE_SURFACE: o.xyz = sphere_surface_point(vec3(0.0, 0.0, a.w), a.xyz, 1.0); break;
        // a = a point on the sphere; o = (its uv, its tangent's x and z).
        case TERM_SPHERE_UV: o = vec4(sphere_uv(a.xyz), sphere_tangent(a.xyz).xz); break;
        // a = (v.h, grey f0, f90).
        case TERM_F_SCHLICK_F90: o.xyz = F_Schlick(a.x, vec3(a.y), a.z); break;
        // a = (roughness, the normal map's widening A).
        case TERM_NORMAL_MAP_ROUGHNESS: o.x = normal_map_roughness(a.x, a.y); break;
    }
    u_outputs[i] = o;
}
