// Image-based lighting: the lecture's split sum (Karis 2013) and the models that improve on
// it, measured against docs/conventions.md's ground truth (app/core/ibl_models.py lists them).
// Maps are baked in the environment map's own frame; lookups rotate world directions into it.
// Compact bright sources (the sun) are not in the irradiance and prefiltered maps (app/ibl/sun.py):
// every model adds them here, exactly, in world space.

#include "common/suns.glsl"

// The model: IBL_MODEL is one of the IBL_MODEL_* names generated from app/core/ibl_models.py's
// IBL_MODELS (app/core/shader_names.py IblModel), set by app/render/renderer.py (ibl_model below), so
// only the chosen model is compiled.
#ifndef IBL_MODEL
#define IBL_MODEL IBL_MODEL_ALIGHT
#endif

uniform samplerCube u_irradiance;            // E/pi: the cosine-weighted mean radiance
uniform samplerCube u_environment;           // source radiance with box mips: the mirror (r = 0)
uniform samplerCube u_prefiltered_radiance;  // grid A: mip m holds alpha = 2^(m - max_mip)
uniform samplerCube u_prefiltered_radiance_mid;  // grid B: mip j holds alpha_A(j + 1) / sqrt(2)
uniform sampler2D u_brdf_lut;                // (A, B, t_A, t_B) over (n.v, roughness): brdf_lut.comp
uniform float u_prefiltered_max_mip;         // last mip of grid A (roughness 1)
uniform vec2 u_env_rotation;                 // (cos, sin) of minus the rotation angle
uniform float u_env_intensity;

// What a delta source adds to each roughness step of the prefiltered map, per unit
// P (d.l) D(h) (app/ibl/bake.py records it from the step's sample set; prefilter.glsl says why).
const int MAX_GRID_STEPS = 32;
uniform float u_sun_prefilter_scale[MAX_GRID_STEPS];

// ---- the roughness grid of the prefiltered map ---------------------------------------------

// Prefiltered radiance lives on a grid of roughness steps where alpha = r^2 grows by sqrt(2)
// per step, alternating between two cubes: even steps are grid A's mips, odd steps grid B's.
// Each A mip halves the resolution as alpha doubles; B fills the gaps, so blending neighbours
// costs two bilinear fetches (as one trilinear fetch would) but with steps half as coarse.
// app/ibl/bake.py's grid_roughness() gives the roughness of each step; this is its inverse.
float roughness_to_grid_step(float roughness) {
    return 2.0 * (2.0 * log2(max(roughness, 1e-4)) + u_prefiltered_max_mip);
}

float grid_step_roughness(int step) {
    return exp2(float(step) / 4.0 - 0.5 * u_prefiltered_max_mip);
}

// The compact sources as a grid step of the prefiltered map would hold them (world space d).
vec3 suns_prefiltered_step(vec3 d, int step) {
    float roughness = grid_step_roughness(step);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < u_sun_count; ++i) {
        float d_dot_l = dot(d, u_sun_direction[i]);
        if (d_dot_l > 0.0) {
            float n_dot_h = dot(d, normalize(u_sun_direction[i] + d));
            sum += D_GGX(n_dot_h, roughness) * d_dot_l * u_sun_power[i];
        }
    }
    return u_sun_prefilter_scale[step] * sum;
}

// IBL_BELOW_GRID 0 compiles out the fade into the source cube below grid A's first step: the
// renderer sets it when no roughness the pass can shade (factors of every layer, maps) lies below
// that step (app/render/renderer.py _below_grid_defines). llvmpipe runs both sides of a branch, so
// the fade otherwise costs a trilinear cube fetch and a log2 at every pixel (11% of the editor's
// scene pass).
#ifndef IBL_BELOW_GRID
#define IBL_BELOW_GRID 1
#endif

// The prefiltered radiance around world direction r for a roughness, blended between grid steps.
// with_suns adds the compact sources (their power carries the intensity already) as the map
// would hold them had they been baked in: the lecture's maps filter the whole environment.
// Neighbouring steps are one even (grid A) and one odd (grid B), so each cube is read once.
// Below grid A's first step (r0 = 2^(-max_mip/2)) the source cube's box mips, whose texel
// matches the lobe width alpha, fade into that step: app/render/renderer.py binds the cube as seen
// (with its sun) for the lecture's models, the cube without compact sources for the others.
vec3 prefiltered_radiance_at(vec3 r, float roughness, bool with_suns) {
    vec3 d = rotate_world_to_map(r, u_env_rotation);
    float step = roughness_to_grid_step(roughness);
    float last = 2.0 * u_prefiltered_max_mip;
    float clamped = clamp(step, 0.0, last);
    int lo = int(floor(clamped));
    int hi = min(lo + 1, int(last));
    float t = clamped - float(lo);
    bool lo_is_a = (lo & 1) == 0;
    vec3 a = textureLod(u_prefiltered_radiance, d, float((lo_is_a ? lo : hi) >> 1)).rgb;
    vec3 b = textureLod(u_prefiltered_radiance_mid, d, float((lo_is_a ? hi : lo) >> 1)).rgb;
    vec3 radiance = u_env_intensity * (lo_is_a ? mix(a, b, t) : mix(b, a, t));
    if (with_suns && u_sun_count > 0) {
        radiance += mix(suns_prefiltered_step(r, lo), suns_prefiltered_step(r, hi), t);
    }
#if IBL_BELOW_GRID
    if (step < 0.0) {
        float r0 = exp2(-0.5 * u_prefiltered_max_mip);
        float texel_angle = 0.5 * PI / float(textureSize(u_environment, 0).x);
        float lod = max(log2(roughness * roughness / texel_angle), 0.0);
        float w = (roughness / r0) * (roughness / r0);
        radiance = mix(u_env_intensity * textureLod(u_environment, d, lod).rgb, radiance, w);
    }
#endif
    return radiance;
}

// E/pi at normal n; with_suns adds the compact sources' P max(n.l, 0) / pi.
vec3 irradiance_at(vec3 n, bool with_suns) {
    // Explicit LOD 0 (the cube has one level): no screen derivatives to compute.
    vec3 e = u_env_intensity * textureLod(u_irradiance, rotate_world_to_map(n, u_env_rotation), 0.0).rgb;
    return with_suns ? e + suns_irradiance_over_pi(n) : e;
}

// Occlusion of these lookups by the mesh itself (HAS_VISIBILITY; else they pass through).
#include "common/occlusion.glsl"

vec4 brdf_lut_at(float n_dot_v, float roughness) {
    return textureLod(u_brdf_lut, vec2(n_dot_v, roughness), 0.0);   // one level: no derivatives
}

// ---- terms the improved models share -------------------------------------------------------

// The Fresnel part of the diffuse lobe under uniform light: (1/pi) times the integral of
// (1 - v.h)^5 (n.l) over the hemisphere. It depends on n.v only (h = normalize(l + v)), peaks
// at 0.028 at grazing, and this quartic in 1 - n.v fits it within 1e-5
// (app/accuracy/converged.py's diffuse_fresnel_converged integrates it).
float diffuse_fresnel(float n_dot_v) {
    float x = 1.0 - n_dot_v;
    return 8.233601e-05 + x * (0.002021979 + x * (0.009310647 + x * (0.007795988 + x * 0.0089526)));
}

// The specular lobe's mean direction for this material (brdf_lut.comp): t_A for the part scaled
// by F0, t_B for the bias, mixed by their weights so one fetch serves both.
vec3 specular_dominant_direction(vec3 n, vec3 r, vec3 f0, vec4 lut) {
    float weight_a = dot(f0, vec3(0.2126, 0.7152, 0.0722)) * lut.x;
    float t = (weight_a * lut.z + lut.y * lut.w) / max(weight_a + lut.y, 1e-6);
    return normalize(mix(n, r, t));
}

#if IBL_MODEL == IBL_MODEL_STRETCHED
// ---- the stretched lobe (model `stretched`) -------------------------------------------------

// app/core/stretched_lobe.json over (n.v, roughness) at texel centres, for the lobe's F0-scaled
// part (a) and its bias part (b): (a_lo, a_hi, w_hi, beta), two round fetches at signed angles
// from the lobe's mean direction in the plane of incidence (toward the horizon positive), the
// second weighted w_hi, both at roughness r sqrt(beta). tools/fit_stretched_lobe.py fits them in
// lobe space (no environment map): the real lobe is narrower across the plane of incidence than
// the round one the prefiltered map holds, and reaches further toward n.
// Below STRETCHED_ROUGHNESS_START (r 0.2: the table's first fitted row) the lobe is the single
// round fetch at its mean, blending into the two fetches by STRETCHED_ROUGHNESS_FULL (r 0.3: where
// the probe's gold fails the lecture's half with one fetch; benchmarks/results/stretched_pair_from_r02.md).
// Both come from app/core/stretched_lobe.py (ROUGHNESS_START, ROUGHNESS_FULL) through app/render/variants.py.
#ifndef STRETCHED_ROUGHNESS_START
#define STRETCHED_ROUGHNESS_START 0.2
#define STRETCHED_ROUGHNESS_FULL 0.3
#endif
// STRETCHED_SPAN (app/render/variants.py stretched_span_defines): 0 the single fetch only (every
// roughness at or below the start), 2 the two fetches only (all at or above the full), 1 both.
#ifndef STRETCHED_SPAN
#define STRETCHED_SPAN 1
#endif
uniform sampler2D u_stretched_lobe_a;
uniform sampler2D u_stretched_lobe_b;

// The fetches' angles' share at n.v (the table has `columns` texel centres over n.v): 1 up to
// the last column's centre, falling to 0 at n.v = 1 as sqrt(1 - n.v) ~ theta, the lobe's asymmetry near the pole (stretched_lobe.py pole_fade).
float pole_fade(float n_dot_v, float columns) {
    return sqrt(clamp((1.0 - n_dot_v) * 2.0 * columns, 0.0, 1.0));
}

// The prefiltered radiance for the real lobe around its mean direction d: the two fitted
// fetches, the parts' fits mixed by their weights as specular_dominant_direction mixes t_A, t_B.
vec3 stretched_prefiltered_radiance(vec3 n, vec3 v, vec3 f0, vec4 lut, float roughness, vec3 d, bool with_suns) {
#if STRETCHED_SPAN == 0
    return prefiltered_radiance_at(d, roughness, with_suns);
#else
#if STRETCHED_SPAN == 1
    float weight = smoothstep(STRETCHED_ROUGHNESS_START, STRETCHED_ROUGHNESS_FULL, roughness);
    vec3 single = weight < 1.0 ? prefiltered_radiance_at(d, roughness, with_suns) : vec3(0.0);
    if (weight <= 0.0) return single;
#endif
    vec2 coord = vec2(max(dot(n, v), 0.0), roughness);
    float weight_a = dot(f0, vec3(0.2126, 0.7152, 0.0722)) * lut.x;
    vec4 fit = (weight_a * texture(u_stretched_lobe_a, coord) + lut.y * texture(u_stretched_lobe_b, coord))
               / max(weight_a + lut.y, 1e-6);
    vec3 toward_horizon = d * dot(n, d) - n;
    toward_horizon = dot(toward_horizon, toward_horizon) > 1e-10 ? normalize(toward_horizon) : vec3(0.0);
    float fetch_roughness = roughness * sqrt(fit.w);
    // Toward normal incidence the lobe turns round about n, and "toward the horizon" turns about
    // the pole with the view: offsets held at the last column's would draw a pinch there (a star
    // at the front of a rough metal ball), so they shrink to 0 at n.v = 1 (in proportion to theta: the offset vector is then smooth).
    vec2 offsets = fit.xy * pole_fade(coord.x, float(textureSize(u_stretched_lobe_a, 0).x));
    vec3 d_lo = cos(offsets.x) * d + sin(offsets.x) * toward_horizon;
    vec3 d_hi = cos(offsets.y) * d + sin(offsets.y) * toward_horizon;
    vec3 stretched = mix(prefiltered_radiance_at(d_lo, fetch_roughness, with_suns),
                         prefiltered_radiance_at(d_hi, fetch_roughness, with_suns), fit.z);
#if STRETCHED_SPAN == 1
    return mix(single, stretched, weight);
#else
    return stretched;
#endif
#endif
}
#endif

// A compact source as the ground truth sees it: the Cook-Torrance BRDF with the IBL k and the
// Fresnel per direction, per unit power (f n.l; sun_layered adds the layers and the power P).
// The source is not a point: its RMS angular radius
// widens the normal distribution to alpha' = sqrt(alpha^2 + spread^2) (D stays normalised), so a
// mirror shows a spot of the source's size and power (after Karis 2013's sphere lights; it
// matters only where alpha is near the source's size, e.g. royal_esplanade's 2-degree lamps).
vec3 sun_light(Surface s, vec3 n, vec3 v, vec3 l, float spread) {
    LobeAngles a;
    a.n_dot_l = dot(n, l);
    if (a.n_dot_l <= 0.0) return vec3(0.0);
    a.n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    vec3 h = normalize(l + v);
    a.n_dot_h = max(dot(n, h), 0.0);
    a.v_dot_h = max(dot(v, h), 0.0);
    float alpha = s.roughness * s.roughness;
    float widened = max(sqrt(sqrt(alpha * alpha + spread * spread)), MIN_PUNCTUAL_ROUGHNESS);
    LobeChoice c = LobeChoice(widened, k_ibl(max(s.roughness, MIN_PUNCTUAL_ROUGHNESS)), false, spread);
    return base_lobes(s, surface_f0(s), n, v, l, a, c);
}

// A compact source through the base and its layers (common/layers.glsl).
vec3 sun_layered(Surface s, vec3 n, vec3 v, vec3 l, vec3 power, float spread) {
#ifdef HAS_TRANSMISSION
    vec3 transmitted = transmission_light(s, n, v, l, false, spread);
#else
    vec3 transmitted = vec3(0.0);
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
    transmitted += diffuse_transmission_light(s, n, v, l);
#endif
    return layered_light(s, n, v, l, transmitted + sun_light(s, n, v, l, spread), false, spread) * power;
}

vec3 suns_exact(Surface s, vec3 n, vec3 v) {
    vec3 sum = vec3(0.0);
    for (int i = 0; i < u_sun_count; ++i) {
#ifdef HAS_SHADOWS
        // The light first: where it is 0 (the shading normal turned from the sun, on most of a
        // mesh's far side) the shadow's search loops run no tap, and a block of pixels all
        // turned away skips them (benchmarks/results/helmet_frame.md). 0 times any shadow is 0,
        // so the picture is the same.
        vec3 light = sun_layered(s, n, v, u_sun_direction[i], u_sun_power[i], u_sun_spread[i]);
        float visible = sun_shadow_where(i, u_sun_direction[i], any(notEqual(light, vec3(0.0))));
        if (visible <= 0.0) continue;
        sum += visible * light;
#else
        sum += sun_layered(s, n, v, u_sun_direction[i], u_sun_power[i], u_sun_spread[i]);
#endif
    }
    return sum;
}

// Diffuse and specular image-based light from the split sum's parts. spec_weight is the
// specular factor on the prefiltered radiance (F A + B or F0 A + B), diffuse_weight the factor
// on the diffuse albedo. With MULTIPLE_SCATTERING, Fdez-Aguera 2019 ("A Multiple-Scattering
// Microfacet Model for Real-Time Image-based Lighting") adds the energy single scattering loses.
vec3 ibl_combine(Surface s, vec3 f0, vec3 diffuse_weight, vec3 spec_weight, vec4 lut,
                 vec3 irradiance, vec3 prefiltered) {
    vec3 albedo = s.base_color * (1.0 - s.metallic);
#ifdef HAS_TRANSMISSION
    albedo *= 1.0 - s.transmission;   // the rest of the diffuse lobe is transmitted (transmission.glsl)
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
    albedo *= diffuse_transmission_front_weight(s);   // the rest leaves through the back (diffuse_transmission.glsl)
#endif
#ifdef MULTIPLE_SCATTERING
    float e_ss = lut.x + lut.y;
    float e_ms = 1.0 - e_ss;
    vec3 f_avg = f0 + (surface_f90(s) - f0) / 21.0;
    vec3 f_ms = spec_weight * f_avg / (1.0 - e_ms * f_avg);
    vec3 e_dss = 1.0 - (spec_weight + f_ms * e_ms);
    return spec_weight * prefiltered + (f_ms * e_ms + albedo * e_dss) * irradiance;
#else
    return diffuse_weight * albedo * irradiance + spec_weight * prefiltered;
#endif
}

// ---- the models ----------------------------------------------------------------------------
// Each model is a small function named after it; the shared split sums below take constant
// flags, which the compiler folds, so a model pays only for its own choices.

// The lecture's split sum with the Fresnel F at n.v it is given: kd = 1 - F, specular F A + B.
vec3 lecture_split_sum(Surface s, vec3 n, vec3 v, vec3 F) {
    float n_dot_v = max(dot(n, v), 0.0);
    vec4 lut = brdf_lut_at(n_dot_v, s.roughness);
#ifdef HAS_ANISOTROPY
    lut.xy *= anisotropic_energy_ratio(s, n, v);
    vec3 prefiltered = anisotropic_prefiltered_radiance(s, n, v, reflect(-v, n), true);
#else
    vec3 prefiltered = prefiltered_radiance_at(reflect(-v, n), s.roughness, true);
#endif
    vec3 irradiance = irradiance_at(n, true);
    vec3 spec_albedo = F * lut.x + surface_f90(s) * lut.y;
    vec3 diffuse_weight = 1.0 - F;
#ifdef HAS_IRIDESCENCE
    iridescence_ibl_weights(s, lut, diffuse_weight, spec_albedo);
#endif
    occlude_environment(s, n, reflect(-v, n), spec_albedo, true, irradiance, prefiltered);
    return ibl_combine(s, surface_f0(s), diffuse_weight, spec_albedo, lut, irradiance, prefiltered);
}

// Karis' split as published: the LUT's A and B already hold the Fresnel, so the specular factor
// is F0 A + B (the lecture's F A + B counts Fresnel twice at grazing); the diffuse weight is the
// ground truth's (1 - F0)(1 - Fc) averaged over the cosine lobe. toward_lobe_mean fetches at the
// lobe's mean direction (brdf_lut.comp) instead of R; with_suns as in prefiltered_radiance_at.
vec3 karis_split_sum(Surface s, vec3 n, vec3 v, bool toward_lobe_mean, bool with_suns) {
    float n_dot_v = max(dot(n, v), 0.0);
    vec3 f0 = surface_f0(s);
    float f90 = surface_f90(s);
    vec4 lut = brdf_lut_at(n_dot_v, s.roughness);
    vec3 r = reflect(-v, n);
    // The lobe's two parts weigh F0 A and F90 B; the mean direction and the stretched fit mix
    // them by the ratio alone, so they take F0 / F90 (KHR_materials_specular's F90 < 1 scales B:
    // with F0 as it is, a specularFactor of 0.5 leaned the lobe toward B, no longer half of 1's).
    vec3 f0_over_f90 = f0 / max(f90, 1e-6);
    vec3 d = toward_lobe_mean ? specular_dominant_direction(n, r, f0_over_f90, lut) : r;
#ifdef HAS_ANISOTROPY
    lut.xy *= anisotropic_energy_ratio(s, n, v);
    vec3 prefiltered = anisotropic_prefiltered_radiance(s, n, v, d, with_suns);
#elif IBL_MODEL == IBL_MODEL_STRETCHED
    vec3 prefiltered = stretched_prefiltered_radiance(n, v, f0_over_f90, lut, s.roughness, d, with_suns);
#else
    vec3 prefiltered = prefiltered_radiance_at(d, s.roughness, with_suns);
#endif
    vec3 irradiance = irradiance_at(n, with_suns);
    // With F90 = 1 the diffuse weight is (1 - F0)(1 - Fc); KHR_materials_specular's F90 makes it
    // 1 - F0 - (F90 - F0) Fc, and the split sum's B scales by F90.
    vec3 spec_albedo = f0 * lut.x + f90 * lut.y;
    vec3 diffuse_weight = 1.0 - f0 - (f90 - f0) * diffuse_fresnel(n_dot_v);
#ifdef HAS_IRIDESCENCE
    iridescence_ibl_weights(s, lut, diffuse_weight, spec_albedo);
#endif
    occlude_environment(s, n, d, spec_albedo, with_suns, irradiance, prefiltered);
    return ibl_combine(s, f0, diffuse_weight, spec_albedo, lut, irradiance, prefiltered);
}

// The lecture's cook_torrance_IBL: kd and F from the roughness-aware Fresnel at n.v.
vec3 ibl_lecture(Surface s, vec3 n, vec3 v) {
    vec3 F = F_SchlickRoughness(max(dot(n, v), 0.0), surface_f0(s), s.roughness);
    return layered_ibl(s, n, v, lecture_split_sum(s, n, v, F), true) * ibl_outer_occlusion(s);
}

// The lecture with plain Schlick at n.v for kd and F (the diffuse weight ignores roughness).
vec3 ibl_lecture_schlick(Surface s, vec3 n, vec3 v) {
    vec3 F = F_Schlick(max(dot(n, v), 0.0), surface_f0(s), surface_f90(s));
    return layered_ibl(s, n, v, lecture_split_sum(s, n, v, F), true) * ibl_outer_occlusion(s);
}

vec3 ibl_karis(Surface s, vec3 n, vec3 v) {
    return layered_ibl(s, n, v, karis_split_sum(s, n, v, false, true), true) * ibl_outer_occlusion(s);
}

// Karis' split fetched at the lobe's mean direction instead of R.
vec3 ibl_dominant(Surface s, vec3 n, vec3 v) {
    return layered_ibl(s, n, v, karis_split_sum(s, n, v, true, true), true) * ibl_outer_occlusion(s);
}

// alight's model: ibl_dominant for the environment without its compact sources, and those
// sources through the exact BRDF and its layers at every roughness (below the prefiltered grid
// too, where app/render/renderer.py binds the source cube without them).
vec3 ibl_alight(Surface s, vec3 n, vec3 v) {
    vec3 suns = u_sun_count > 0 ? suns_exact(s, n, v) : vec3(0.0);
    return (layered_ibl(s, n, v, karis_split_sum(s, n, v, true, false), false) + suns) * ibl_outer_occlusion(s);
}

// alight's model with the lobe's shape from two round fetches fitted to the real lobe in lobe
// space (stretched_prefiltered_radiance) instead of one at its mean direction.
vec3 ibl_stretched(Surface s, vec3 n, vec3 v) {
    return ibl_alight(s, n, v);
}

// The model the forward pass uses (IBL_MODEL, above), so only the chosen model is compiled.
vec3 ibl_model(Surface s, vec3 n, vec3 v) {
#if IBL_MODEL == IBL_MODEL_LECTURE
    return ibl_lecture(s, n, v);
#elif IBL_MODEL == IBL_MODEL_LECTURE_SCHLICK
    return ibl_lecture_schlick(s, n, v);
#elif IBL_MODEL == IBL_MODEL_KARIS
    return ibl_karis(s, n, v);
#elif IBL_MODEL == IBL_MODEL_DOMINANT
    return ibl_dominant(s, n, v);
#elif IBL_MODEL == IBL_MODEL_ALIGHT
    return ibl_alight(s, n, v);
#else
    return ibl_stretched(s, n, v);
#endif
}
