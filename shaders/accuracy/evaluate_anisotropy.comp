#version 450 core
// Evaluates anisotropy.glsl's functions per row of inputs, so tests can compare each with its
// numpy twin in app/core/layers/anisotropy.py (tests/test_anisotropy.py). Not used for rendering.
// Compiled with HAS_ANISOTROPY. The frame is n = +Z, the mesh tangent +X, bitangent +Y.
#include "common/shading.glsl"
#include "common/material_layers.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 u_inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 u_outputs[]; };
uniform int u_count;
uniform int u_term;
uniform vec3 u_view;          // TERM_PUNCTUAL, TERM_SPECULAR: v
uniform vec3 u_base_color;    // TERM_PUNCTUAL: a dielectric's or metal's base colour
uniform float u_metallic;
uniform float u_spread;       // TERM_SPECULAR: a compact source's spread

const int TERM_ALPHA = 0;         // a = (roughness, strength)
const int TERM_D = 1;             // a = (t.h, b.h, alpha_t, alpha_b); n.h from |h| = 1
const int TERM_PROJECTED = 2;     // a = (t.x, b.x, alpha_t, alpha_b)
const int TERM_PUNCTUAL = 3;      // a = (l.x, l.y, roughness, strength): punctual_light, radiance 1
const int TERM_SPECULAR = 4;      // a = (l.x, l.y, roughness, strength): the exact lobe (punctual false), F = 1

vec3 light_from(vec2 xy) {
    return vec3(xy, sqrt(max(0.0, 1.0 - dot(xy, xy))));
}

Surface anisotropic_surface(float roughness, float strength) {
    Surface s = surface_base(u_base_color, u_metallic, roughness, vec3(0.04), vec3(0.0), 1.0);
    apply_material_layers(s, vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0));
    s.anisotropy_strength = strength;
    return s;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(u_count)) return;
    vec4 a = u_inputs[i];
    vec4 o = vec4(0.0);
    vec3 n = vec3(0.0, 0.0, 1.0);
    switch (u_term) {
        case TERM_ALPHA: o.xy = anisotropic_alpha(a.x, a.y); break;
        case TERM_D: o.x = D_GGX_anisotropic(a.x, a.y, sqrt(max(0.0, 1.0 - a.x * a.x - a.y * a.y)), a.z, a.w); break;
        case TERM_PROJECTED: o.x = projected_alpha(a.x, a.y, a.z, a.w); break;
        case TERM_PUNCTUAL: {
            Surface s = anisotropic_surface(a.z, a.w);
            o.xyz = punctual_light(s, n, u_view, light_from(a.xy), vec3(1.0));
            break;
        }
        case TERM_SPECULAR: {
            Surface s = anisotropic_surface(a.z, a.w);
            o.xyz = anisotropic_specular(s, n, u_view, light_from(a.xy), vec3(1.0), false, u_spread);
            break;
        }
    }
    u_outputs[i] = o;
}
