// What a scene pass writes: linear radiance, or with DISPLAY_OUTPUT (the editor drawing straight
// into its 8-bit view) exactly what render/tonemap.frag makes of that radiance, so the tone map
// pass and the float target's traffic are fused away. Same maths, same order: same pixels.
#include "common/tonemapping.glsl"

uniform float u_exposure_scale;  // 2^EV
uniform int u_tonemap;

vec4 encode_output(vec3 radiance, float alpha) {
#ifdef DISPLAY_OUTPUT
    return vec4(linear_to_srgb(tonemap(radiance * u_exposure_scale, u_tonemap)), 1.0);
#else
    return vec4(radiance, alpha);
#endif
}
