#version 450 core
// The probe view of docs/conventions.md: a unit sphere, orthographic, filling a square image, with
// the exact normal n = (x, y, sqrt(1 - x^2 - y^2)) per pixel and v = (0, 0, 1).
#include "common/shading.glsl"
#include "common/material_layers.glsl"

uniform float u_size;
uniform vec2 u_pixel_origin;   // a tile's bottom-left pixel in the image (alight.render.tiles); else 0
uniform vec3 u_base_color;
uniform float u_metallic;
uniform float u_roughness;
uniform vec3 u_specular_f0;
uniform vec3 u_emissive;

layout(location = 0) out vec4 out_radiance;

void main() {
    // GL's window origin is the bottom-left; the written file's row 0 is the top, so
    // y = 1 - 2 (row + 0.5) / W becomes 2 gl_FragCoord.y / W - 1. Adding a tile's whole-pixel
    // origin is exact: every pixel gets the same xy as in one pass over the image.
    vec2 xy = 2.0 * (gl_FragCoord.xy + u_pixel_origin) / u_size - 1.0;
    float r2 = dot(xy, xy);
    if (r2 >= 1.0) discard;
    vec3 n = vec3(xy, sqrt(1.0 - r2));
    Surface s = surface_base(u_base_color, u_metallic, u_roughness, u_specular_f0, u_emissive, 1.0);
#if defined(HAS_CLEARCOAT) || defined(HAS_SHEEN) || defined(HAS_ANISOTROPY) || defined(HAS_TRANSMISSION) || defined(HAS_VOLUME) || defined(HAS_DIFFUSE_TRANSMISSION)
    vec3 t, b;
    probe_tangent_frame(n, t, b);
    apply_material_layers(s, n, t, b);
#endif
#ifdef HAS_IRIDESCENCE
    apply_material_iridescence(s);
#endif
    out_radiance = vec4(shade(s, n, vec3(0.0, 0.0, 1.0), n), 1.0);
    gl_FragDepth = 0.0;  // in front of the background, which is drawn after on the far plane
}
