// What lies behind the surfaces along a view ray: the environment, a blurred environment, a
// solid colour, or nothing (a transparent background). Shared by render/background.frag (a pass
// of its own, under the surfaces by the depth test) and render/resolve.frag (composited under
// the resolved samples).
#include "common/equirect.glsl"

// BACKGROUND_ENV, _BLUR, _COLOR, _TRANSPARENT: app/core/shader_names.py BackgroundMode (generated).
// The mode is compiled in (app/render/renderer.py sets it): llvmpipe runs both sides of a branch, so a
// uniform mode would cost the sharp and the blurred fetch at every pixel.
#ifndef BACKGROUND_MODE
#define BACKGROUND_MODE BACKGROUND_ENV
#endif

uniform samplerCube u_environment;            // the source cube (sharp)
uniform samplerCube u_prefiltered_radiance;   // for the blurred background
uniform float u_blur_mip;
uniform vec2 u_env_rotation;
uniform float u_env_intensity;
uniform vec3 u_color;

// Radiance arriving along the world-space ray (any length: render/background.vert's v_ray).
vec3 background_radiance(vec3 ray) {
#if BACKGROUND_MODE == BACKGROUND_COLOR
    return u_color;
#elif BACKGROUND_MODE == BACKGROUND_TRANSPARENT
    return vec3(0.0);
#else
    vec3 d = rotate_world_to_map(normalize(ray), u_env_rotation);
#if BACKGROUND_MODE == BACKGROUND_BLUR
    return u_env_intensity * textureLod(u_prefiltered_radiance, d, u_blur_mip).rgb;
#else
    return u_env_intensity * textureLod(u_environment, d, 0.0).rgb;
#endif
#endif
}
