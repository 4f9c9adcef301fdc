// KHR_materials_sheen: the Charlie sheen BRDF (Estevez and Kulla 2017) over the base, which it
// scales by its albedo (common/layers.glsl declares these; exact definition:
// docs/layer_sheen.md). Numpy twin: app/core/layers/sheen.py (same names).
//     layered = f_sheen + base min(1 - max(sheen_color) E(n.v), 1 - max(sheen_color) E(n.l))
// E, the lobe's directional albedo, comes from the sheen LUT (ibl/sheen_lut.comp), which also
// holds where the lobe points and how wide it is, for the image-based light. E is capped at 1
// (the lobe divided by max(E, 1)): with the fitted masking it exceeds 1 at grazing view for low
// sheen roughness, where the sheen would otherwise reflect more than it receives.
#include "common/sheen_terms.glsl"
#ifdef HAS_SHEEN

uniform sampler2D u_sheen_lut;   // (E, sin phi, rho, 0) over (n.v, sheen roughness)

vec4 sheen_lut_at(float n_dot_v, float roughness) {
    return texture(u_sheen_lut, vec2(n_dot_v, roughness));
}

// 1 - max(sheen_color) min(E, 1): what the sheen leaves of the layers below.
float sheen_scaling(Surface s, float e) {
    return 1.0 - max(max(s.sheen_color.r, s.sheen_color.g), s.sheen_color.b) * min(e, 1.0);
}

float sheen_base_weight(Surface s, vec3 n, vec3 v, vec3 l) {
    float e_v = sheen_lut_at(clamp(dot(n, v), 0.0, 1.0), s.sheen_roughness).x;
    float e_l = sheen_lut_at(clamp(abs(dot(n, l)), 0.0, 1.0), s.sheen_roughness).x;
    return min(sheen_scaling(s, e_v), sheen_scaling(s, e_l));
}

// The lobe is wide (its width dwarfs any compact source's), so spread is ignored, and it has no
// punctual variant beyond the roughness floor it always has.
vec3 sheen_light(Surface s, vec3 n, vec3 v, vec3 l, bool punctual, float spread) {
    float n_dot_v = dot(n, v);
    float lobe = sheen_lobe(dot(n, l), n_dot_v, dot(n, normalize(l + v)), s.sheen_roughness);
    float e_v = sheen_lut_at(clamp(n_dot_v, 0.0, 1.0), s.sheen_roughness).x;
    return s.sheen_color * (lobe / max(e_v, 1.0));
}

float sheen_base_weight_ibl(Surface s, vec3 n, vec3 v) {
    return sheen_scaling(s, sheen_lut_at(clamp(dot(n, v), 0.0, 1.0), s.sheen_roughness).x);
}

// The lobe under the environment: its albedo min(E, 1) times the prefiltered radiance at its
// mean direction (angle phi from n toward v's side, from the LUT) with the roughness whose
// kernel is as wide (docs/layer_sheen.md measures what this leaves).
vec3 sheen_ibl(Surface s, vec3 n, vec3 v, bool with_suns) {
    float n_dot_v = clamp(dot(n, v), 0.0, 1.0);
    vec4 lut = sheen_lut_at(n_dot_v, s.sheen_roughness);
    vec3 toward_v = v - n * dot(n, v);
    float len2 = dot(toward_v, toward_v);
    // At n.v = 1 the lobe is symmetric about n (sin phi = 0), so any tangent serves.
    vec3 t = len2 > 1e-12 ? toward_v * inversesqrt(len2) : vec3(0.0);
    vec3 d = normalize(n * sqrt(max(1.0 - lut.y * lut.y, 0.0)) + t * lut.y);
    return s.sheen_color * min(lut.x, 1.0) * occluded_layer_radiance(s, n, d, lut.z, prefiltered_radiance_at(d, lut.z, with_suns));
}

#endif
