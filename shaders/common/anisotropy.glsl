// KHR_materials_anisotropy: the base's GGX lobe stretched along a tangent direction
// (common/layers.glsl declares the hooks; docs/layer_anisotropy.md defines the BRDF exactly).
// Numpy twin: app/core/layers/anisotropy.py (same names).
#ifdef HAS_ANISOTROPY
#include "common/anisotropic_ggx.glsl"

// Quality choices, in one place: the image-based lookup's round fetches along the stretched lobe
// (docs/layer_anisotropy.md, worst error over 12 cases on royal_esplanade: 6 fetches 23.8%,
// 8: 21.3%, 16: 19.4%), and the lookup itself: 0 the stretched lobe (the default), 1 the round
// lobe at the material's roughness, 2 the Khronos sample viewer's bent normal. 1 and 2 are kept
// to be measured against (benchmarks/bench_anisotropy.py): for metals their worst error per map
// is 4-6x (round) and 4-15x (bent) the stretched lobe's.
#ifndef ANISOTROPY_FETCHES
#define ANISOTROPY_FETCHES 8
#endif
#ifndef ANISOTROPY_LOOKUP
#define ANISOTROPY_LOOKUP 0
#endif

// D G F / (4 n.l n.v) with the lobe stretched along s.anisotropy_direction. punctual: the
// roughness floored at MIN_PUNCTUAL_ROUGHNESS and k_direct; otherwise docs/conventions.md's k_ibl,
// and a compact source's angular spread widens both axes (as sun_light widens the round lobe).
vec3 anisotropic_specular(Surface s, vec3 n, vec3 v, vec3 l, vec3 F, bool punctual, float spread) {
    float n_dot_l = max(dot(n, l), 1e-8);
    float n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    vec3 h = normalize(l + v);
    vec3 t = s.anisotropy_direction;
    vec3 b = s.anisotropy_bitangent;
    float r = punctual ? max(s.roughness, MIN_PUNCTUAL_ROUGHNESS) : s.roughness;
    vec2 alpha = anisotropic_alpha(r, s.anisotropy_strength);
    vec2 widened = alpha;
    if (!punctual) {
        float floor_alpha = MIN_PUNCTUAL_ROUGHNESS * MIN_PUNCTUAL_ROUGHNESS;
        widened = max(sqrt(alpha * alpha + spread * spread), vec2(floor_alpha));
        alpha = anisotropic_alpha(max(s.roughness, MIN_PUNCTUAL_ROUGHNESS), s.anisotropy_strength);
    }
    float D = D_GGX_anisotropic(dot(t, h), dot(b, h), max(dot(n, h), 0.0), widened.x, widened.y);
    float G = G1_anisotropic(n_dot_v, projected_alpha(dot(t, v), dot(b, v), alpha.x, alpha.y), punctual)
            * G1_anisotropic(n_dot_l, projected_alpha(dot(t, l), dot(b, l), alpha.x, alpha.y), punctual);
    return D * G * F / (4.0 * n_dot_l * n_dot_v);
}

// ---- image-based light: the stretched lobe ---------------------------------------------------

// ibl/anisotropy_lut.comp: the stretched lobe's A and B over the round lobe's, per (n.v,
// roughness, strength), the view's azimuth from the direction at 0, 30, 60, 90 degrees in RGBA.
uniform sampler3D u_anisotropy_ratio_a;
uniform sampler3D u_anisotropy_ratio_b;

// The factors on the BRDF LUT's (A, B) that make them the stretched lobe's energy: linear in
// the view's azimuth between the table's four.
vec2 anisotropic_energy_ratio(Surface s, vec3 n, vec3 v) {
    vec3 size = vec3(textureSize(u_anisotropy_ratio_a, 0));
    float strength = (s.anisotropy_strength * (size.z - 1.0) + 0.5) / size.z;
    vec3 coord = vec3(max(dot(n, v), 0.0), s.roughness, strength);
    vec4 a = texture(u_anisotropy_ratio_a, coord);
    vec4 b = texture(u_anisotropy_ratio_b, coord);
    float azimuth = atan(abs(dot(s.anisotropy_bitangent, v)), abs(dot(s.anisotropy_direction, v)));
    float x = clamp(azimuth / radians(30.0), 0.0, 3.0);
    vec4 w = max(1.0 - abs(vec4(x) - vec4(0.0, 1.0, 2.0, 3.0)), 0.0);
    return vec2(dot(a, w), dot(b, w));
}

// The stretched lobe's prefiltered radiance, from ANISOTROPY_FETCHES round lookups. The lobe's
// normals spread along the direction with alpha_t and across it with alpha_b; a round lookup
// of the material's roughness (alpha_b) already holds the spread across, so the fetches' normals
// h_k = normalize(n - x_k t) spread along t only, by what the round lobe leaves:
// sqrt(alpha_t^2 - alpha_b^2), at the quantiles of GGX's slope marginal
// (x = q / sqrt(1 - q^2) for q = 2 (k + 1/2) / K - 1, equal mass each). Each fetch is drawn
// toward its own lobe's mean as the isotropic lookup is (specular_dominant_direction) and
// weighted by what the BRDF gives that normal under uniform light, G1(n.l) v.h / n.h (the
// energy itself comes from anisotropic_energy_ratio). At strength 0 every fetch is the
// isotropic lookup at d. Measured against the exact answer (docs/layer_anisotropy.md): this
// cuts the round lookup's worst error 4-6x for metals; the Khronos sample viewer's bent normal
// is worse than ignoring the stretch.
vec3 anisotropic_prefiltered_radiance(Surface s, vec3 n, vec3 v, vec3 d, bool with_suns) {
#if ANISOTROPY_LOOKUP == 1
    return prefiltered_radiance_at(d, s.roughness, with_suns);
#elif ANISOTROPY_LOOKUP == 2
    // The Khronos glTF sample viewer's (ibl.glsl, getIBLRadianceAnisotropy): n bent toward the
    // plane of the direction and v by (1 - strength (1 - r))^4, the round lobe along its reflection.
    vec3 anisotropic_normal = cross(cross(s.anisotropy_direction, v), s.anisotropy_direction);
    float bend = 1.0 - s.anisotropy_strength * (1.0 - s.roughness);
    bend *= bend;
    vec3 bent = normalize(mix(anisotropic_normal, n, bend * bend));
    return prefiltered_radiance_at(reflect(-v, bent), s.roughness, with_suns);
#endif
    vec2 alpha = anisotropic_alpha(s.roughness, s.anisotropy_strength);
    float spread = sqrt(max(alpha.x * alpha.x - alpha.y * alpha.y, 0.0));
    if (spread < 1e-6) return prefiltered_radiance_at(d, s.roughness, with_suns);
    vec3 t = s.anisotropy_direction;
    vec3 b = s.anisotropy_bitangent;
    vec3 f0 = surface_f0(s);
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int k = 0; k < ANISOTROPY_FETCHES; ++k) {
        float q = (2.0 * float(k) + 1.0) / float(ANISOTROPY_FETCHES) - 1.0;
        vec3 h = normalize(n - spread * q * inversesqrt(1.0 - q * q) * t);
        float v_dot_h = max(dot(h, v), 0.0);
        vec3 l = reflect(-v, h);
        vec3 dk = specular_dominant_direction(h, l, f0, brdf_lut_at(v_dot_h, s.roughness));
        float projected = projected_alpha(dot(t, dk), dot(b, dk), alpha.x, alpha.y);
        float weight = G1_anisotropic(max(dot(n, dk), 0.0), projected, false) * v_dot_h / max(dot(n, h), 1e-4);
        sum += weight * prefiltered_radiance_at(dk, s.roughness, with_suns);
        total += weight;
    }
    return total > 0.0 ? sum / total : prefiltered_radiance_at(d, s.roughness, with_suns);
}

#endif
