// What a scene pass writes: linear radiance, or with DISPLAY_OUTPUT (the editor drawing straight
// into its 8-bit view) exactly what render/tonemap.frag makes of that radiance, so the tone map
// pass and the float target's traffic are fused away. Same maths, same order: same pixels.
// HALF_FLOAT_OUTPUT: radiance into a half-float target, clamped to its range.
#include "common/tonemapping.glsl"

uniform float u_exposure_scale;  // 2^EV

vec4 encode_output(vec3 radiance, float alpha) {
#ifdef DISPLAY_OUTPUT
    return vec4(linear_to_srgb(tonemap(radiance * u_exposure_scale, TONEMAP_MODE)), 1.0);
#elif defined(HALF_FLOAT_OUTPUT)
    // A half-float target (renderer.py HALF_FLOAT_MAX): its largest value, not +inf, where the
    // radiance exceeds it (the tone map has saturated long before: HALF_FLOAT_MIN_EXPOSURE).
    return vec4(min(radiance, vec3(65504.0)), alpha);
#else
    return vec4(radiance, alpha);
#endif
}
