// What a scene pass writes: linear radiance, or with DISPLAY_OUTPUT (the editor drawing straight
// into its 8-bit view) exactly what render/tonemap.frag makes of that radiance, so the tone map
// pass and the float target's traffic are fused away. Same maths, same order: same pixels.
// SRGB_BY_FRAMEBUFFER (with DISPLAY_OUTPUT): the sRGB curve is left to the framebuffer's write
// stage (free on a GPU; within 1 LSB on llvmpipe), for the editor's window while it orbits.
// HALF_FLOAT_OUTPUT: radiance into a half-float target, clamped to its range.
#include "common/tonemapping.glsl"

uniform float u_exposure_scale;  // 2^EV

vec4 encode_output(vec3 radiance, float alpha) {
#if defined(DISPLAY_OUTPUT) && defined(SRGB_BY_FRAMEBUFFER)
    // The framebuffer encodes sRGB as it writes (renderer.py draw_display's into_encodes_srgb).
    return vec4(tonemap(radiance * u_exposure_scale, TONEMAP_MODE), 1.0);
#elif defined(DISPLAY_OUTPUT)
    return vec4(linear_to_srgb(tonemap(radiance * u_exposure_scale, TONEMAP_MODE)), 1.0);
#elif defined(HALF_FLOAT_OUTPUT)
    // A half-float target (renderer.py HALF_FLOAT_MAX): its largest value, not +inf, where the
    // radiance exceeds it (the tone map has saturated long before: HALF_FLOAT_MIN_EXPOSURE).
    return vec4(min(radiance, vec3(65504.0)), alpha);
#else
    return vec4(radiance, alpha);
#endif
}
