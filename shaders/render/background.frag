#version 450 core
// What lies behind the object: the environment, a blurred environment, or a solid colour.
// Alpha is 0 everywhere here: only surfaces count as hits (CONVENTIONS.md, image outputs).
#include "common/brdf.glsl"
#include "common/equirect.glsl"
#include "common/output_encoding.glsl"

#define BACKGROUND_ENV 0
#define BACKGROUND_BLUR 1
#define BACKGROUND_COLOR 2
// The mode is compiled in (app/render/renderer.py sets it): llvmpipe runs both sides of a branch, so a
// uniform mode would cost the sharp and the blurred fetch at every pixel.
#ifndef BACKGROUND_MODE
#define BACKGROUND_MODE BACKGROUND_ENV
#endif

in vec3 v_ray;    // render/background.vert: world-space, not normalised

uniform samplerCube u_environment;            // the source cube (sharp)
uniform samplerCube u_prefiltered_radiance;   // for the blurred background
uniform float u_blur_mip;
uniform vec2 u_env_rotation;
uniform float u_env_intensity;
uniform vec3 u_color;

layout(location = 0) out vec4 out_radiance;

void main() {
#if BACKGROUND_MODE == BACKGROUND_COLOR
    out_radiance = encode_output(u_color, 0.0);
#else
    vec3 d = rotate_world_to_map(normalize(v_ray), u_env_rotation);
#if BACKGROUND_MODE == BACKGROUND_BLUR
    vec3 radiance = textureLod(u_prefiltered_radiance, d, u_blur_mip).rgb;
#else
    vec3 radiance = textureLod(u_environment, d, 0.0).rgb;
#endif
    out_radiance = encode_output(u_env_intensity * radiance, 0.0);
#endif
}
