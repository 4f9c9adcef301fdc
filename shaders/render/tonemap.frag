#version 450 core
// Linear radiance -> exposure -> tone mapping -> sRGB, for people to look at.
#include "common/tonemapping.glsl"

in vec2 v_ndc;

uniform sampler2D u_radiance;
uniform float u_exposure_scale;  // 2^EV
uniform bool u_opaque;           // false: keep alpha (transparent background)

layout(location = 0) out vec4 out_color;

void main() {
    vec4 hdr = texelFetch(u_radiance, ivec2(gl_FragCoord.xy), 0);
    // The radiance image is premultiplied by coverage (anti-aliased edges, alphaMode BLEND over
    // nothing); a PNG's alpha is straight (PNG specification 12.8), so divide before the curve.
    if (!u_opaque) hdr.rgb = hdr.a > 0.0 ? hdr.rgb / hdr.a : vec3(0.0);
    vec3 c = linear_to_srgb(tonemap(hdr.rgb * u_exposure_scale, TONEMAP_MODE));
    out_color = vec4(c, u_opaque ? 1.0 : hdr.a);
}
