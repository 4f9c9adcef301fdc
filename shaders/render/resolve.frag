#version 450 core
// The last pass of a multisampled frame, in one: the MSAA resolve (the mean of each pixel's
// samples), the background composited under the surfaces, and the outputs the caller reads:
// linear radiance (RADIANCE_OUTPUT) and the tone-mapped sRGB image (DISPLAY_OUTPUT, the maths
// of render/tonemap.frag). It replaces a background pass that wrote every uncovered sample, the
// resolve's float image and the tone map pass that read it back.
#include "common/brdf.glsl"
#include "common/background.glsl"
#include "common/tonemapping.glsl"

#ifndef SCENE_SAMPLES
#define SCENE_SAMPLES 4
#endif

in vec3 v_ray;    // render/background.vert: world-space, not normalised

// The surfaces' radiance and alpha (coverage), cleared to 0 where none was drawn: the multisampled
// target, or with SCENE_SAMPLES 1 a single-sample one holding the coverage-weighted mean already
// (the built-in sphere's impostor: common/mesh_material.glsl SPHERE_IMPOSTOR).
#if SCENE_SAMPLES == 1
uniform sampler2D u_scene;
#else
uniform sampler2DMS u_scene;
#endif
uniform float u_exposure_scale;  // 2^EV
uniform bool u_opaque;           // false: keep the coverage as alpha (transparent background)

#ifdef RADIANCE_OUTPUT
layout(location = 0) out vec4 out_radiance;
#endif
#ifdef DISPLAY_OUTPUT
layout(location = DISPLAY_OUTPUT) out vec4 out_display;
#endif

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    // Shaded once per pixel, as the background pass shades it (at the pixel centre).
    vec3 background = background_radiance(v_ray);
    vec4 sum = vec4(0.0);
#ifndef NO_SURFACES   // (outside the mesh's screen rectangle no sample was drawn: renderer.py _resolve)
#if SCENE_SAMPLES == 1
    sum = texelFetch(u_scene, p, 0);
#else
    for (int i = 0; i < SCENE_SAMPLES; ++i) sum += texelFetch(u_scene, p, i);
#endif
#endif
    // Porter-Duff 'under', summed over the samples: each sample's radiance is its surfaces' (alpha
    // 1 where opaque) and the background fills what they leave; an uncovered sample, cleared to
    // (0, 0, 0, 0), is the background alone. Linear, so the mean of the samples composites once.
    vec4 mean = sum / float(SCENE_SAMPLES);
    vec4 hdr = vec4(mean.rgb + (1.0 - mean.a) * background, mean.a);
#ifdef RADIANCE_OUTPUT
    out_radiance = hdr;
#endif
#ifdef DISPLAY_OUTPUT
    // As render/tonemap.frag: with a transparent background the radiance is premultiplied by
    // coverage and a PNG's alpha is straight (PNG specification 12.8), so divide before the curve.
    vec3 straight = u_opaque ? hdr.rgb : (hdr.a > 0.0 ? hdr.rgb / hdr.a : vec3(0.0));
    out_display = vec4(linear_to_srgb(tonemap(straight * u_exposure_scale, TONEMAP_MODE)), u_opaque ? 1.0 : hdr.a);
#endif
}
