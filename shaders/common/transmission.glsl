// KHR_materials_transmission and KHR_materials_volume: the base's diffuse lobe shared with a
// microfacet BTDF, thin-walled or refracting into a volume with Beer-Lambert attenuation
// (common/layers.glsl declares these hooks; the definition is docs/layer_transmission.md).
// Numpy twins: app/core/layers/transmission.py (transmission_light) and
// app/accuracy/converged.py (transmission_ibl_converged). KHR_materials_dispersion (HAS_DISPERSION)
// refracts each colour channel at its own index (transmitted_btdf, dispersed_radiance).
#include "common/btdf.glsl"
#include "common/transmission_lut.glsl"
#include "common/dispersion_terms.glsl"
#ifdef HAS_TRANSMISSION

#ifdef HAS_VOLUME
uniform sampler3D u_transmission_lut;   // ibl/transmission_lut.comp: E, bend, roughness
#endif

// Without HAS_VOLUME every transmissive surface is thin-walled (KHR_materials_volume absent or
// thickness 0).
bool thin_walled(Surface s) {
#ifdef HAS_VOLUME
    return s.thickness <= 0.0;
#else
    return true;
#endif
}

// How far the transmitted light travels inside before it leaves (0 for a thin wall): the
// thickness (KHR_materials_volume: "the thickness of the volume beneath the surface").
float volume_path(Surface s) {
#ifdef HAS_VOLUME
    return max(s.thickness, 0.0);
#else
    return 0.0;
#endif
}

// (1 - metallic) transmission T: what the transmitted light keeps before the base colour and
// the Fresnel (glTF: metals absorb what they do not reflect; T is Beer-Lambert over thickness).
vec3 transmission_weight(Surface s) {
    vec3 weight = vec3((1.0 - s.metallic) * s.transmission);
#ifdef HAS_VOLUME
    weight *= beer_lambert(s.attenuation_color, s.attenuation_distance, s.thickness);
#endif
    return weight;
}

// The transmitted lobe's alpha widened for a source of RMS angular radius `spread` (ibl.glsl's
// sun_light widens the reflection lobe the same way): the thin-walled lobe is the reflection
// lobe mirrored, alpha' = sqrt(alpha^2 + spread^2); the refracted lobe is (1 - 1/ior) as wide
// as a reflection lobe of twice its alpha, so the spread counts 2 / (1 - 1/ior) times more.
float widened_transmission_roughness(Surface s, float roughness, float spread) {
    float alpha = roughness * roughness;
    float scale = thin_walled(s) ? 1.0 : 2.0 / max(1.0 - 1.0 / s.ior, 1e-3);
    float widened_alpha = sqrt(alpha * alpha + spread * spread * scale * scale);
    return min(sqrt(widened_alpha), 1.0);
}

// (1 - F(v.h)) btdf at index `ior` for l behind the surface (the Fresnel at the BTDF's own half
// vector; F0 stays the material's).
vec3 transmitted_btdf_at(Surface s, vec3 n, vec3 v, vec3 l, float roughness, float k, float ior) {
    float v_dot_h;
    float btdf = transmission_btdf(n, v, l, roughness, k, ior, thin_walled(s), v_dot_h);
    return (1.0 - F_Schlick(v_dot_h, surface_f0(s), surface_f90(s))) * btdf;
}

// (1 - F) btdf per channel: with KHR_materials_dispersion each channel at its own index
// (common/dispersion_terms.glsl; a thin wall bends nothing, so it has no dispersion).
vec3 transmitted_btdf(Surface s, vec3 n, vec3 v, vec3 l, float roughness, float k) {
#ifdef HAS_DISPERSION
    if (!thin_walled(s) && s.dispersion > 0.0) {
        vec3 iors = dispersion_iors(s.ior, s.dispersion);
        return vec3(transmitted_btdf_at(s, n, v, l, roughness, k, iors.r).r,
                    transmitted_btdf_at(s, n, v, l, roughness, k, iors.g).g,
                    transmitted_btdf_at(s, n, v, l, roughness, k, iors.b).b);
    }
#endif
    return transmitted_btdf_at(s, n, v, l, roughness, k, s.ior);
}

// The transmitted part of the base for one direction l behind the surface, times |n.l|:
// (1 - metallic) t T base (1 - F(v.h)) btdf; 0 for l in front (the diffuse lobe's share,
// 1 - transmission, is applied by the base). punctual: k = (r+1)^2/8 and the roughness floor.
vec3 transmission_light(Surface s, vec3 n, vec3 v, vec3 l, bool punctual, float spread) {
    float n_dot_l = dot(n, l);
    if (n_dot_l >= 0.0) return vec3(0.0);
    float roughness = punctual ? max(s.roughness, MIN_PUNCTUAL_ROUGHNESS) : s.roughness;
    float k = punctual ? k_direct(roughness) : k_ibl(roughness);
    if (spread > 0.0) roughness = max(widened_transmission_roughness(s, s.roughness, spread), MIN_PUNCTUAL_ROUGHNESS);
    return transmission_weight(s) * s.base_color * transmitted_btdf(s, n, v, l, roughness, k) * -n_dot_l;
}

// ---- image-based light ---------------------------------------------------------------------

// The transmitted lobe in the prefiltered map's terms: one fetch along `direction` at
// `roughness` stands for it, and `energy` is its integral of btdf (1 - Fc) |n.l| (so the
// transmitted radiance is weight base (1 - F0) energy L).
struct TransmittedLobe {
    vec3 direction;
    float roughness;
    float energy;
};

// Thin-walled: the reflection lobe mirrored through the surface. Its (1 - Fc) part has the BRDF
// LUT's energy A and mean direction t_A (brdf_lut.comp), mirrored: no LUT of its own.
TransmittedLobe thin_walled_lobe(Surface s, vec3 n, vec3 v) {
    float n_dot_v = max(dot(n, v), 0.0);
    vec4 lut = brdf_lut_at(n_dot_v, s.roughness);
    vec3 mean = normalize(mix(n, reflect(-v, n), lut.z));
    return TransmittedLobe(mirror_through_surface(mean, n), s.roughness, lut.x);
}

#ifdef HAS_VOLUME
// Refracting: the transmission LUT's energy, mean direction (the sine of its angle from -n,
// leaning toward -v's tangential part, is bend times the view's sine) and the prefiltered
// roughness of the same mean cosine.
TransmittedLobe refracted_lobe(Surface s, vec3 n, vec3 v) {
    float n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    vec4 lut = texture(u_transmission_lut, vec3(n_dot_v, s.roughness, lut_axis_of_ior(s.ior)));
    vec3 tangential = v - n * dot(n, v);   // length: the view's sine
    float sin_mean = clamp(lut.y * length(tangential), 0.0, 1.0);
    vec3 side = -tangential / max(length(tangential), 1e-8);
    vec3 direction = -n * sqrt(1.0 - sin_mean * sin_mean) + side * sin_mean;
    return TransmittedLobe(direction, lut.z, lut.x);
}
#endif

#ifdef TRANSMISSION_SCENE
// What is behind the surface in the scene (app/render/renderer.py draws the opaque parts, copies
// them into this mipmapped texture with alpha = coverage, then draws the transmissive parts;
// the Khronos Sample Viewer's approach). Only a fragment shader has gl_FragCoord.
uniform sampler2D u_scene_behind;
uniform mat4 u_behind_view_projection;
uniform float u_behind_pixels_per_radian;   // image rows per radian at the centre: (H/2) / tan(fov/2)

// The copy's premultiplied radiance and coverage where the lobe's exit point lands on screen,
// blurred to the lobe's width seen from here (as if what is behind were far away: the copy has
// no depth, so nearby objects behind get the blur of distant ones).
vec4 scene_behind(vec3 displacement, float roughness) {
    vec2 size = vec2(textureSize(u_scene_behind, 0));
    vec4 clip = vec4(2.0 * gl_FragCoord.xy / size - 1.0, 2.0 * gl_FragCoord.z - 1.0, 1.0) / gl_FragCoord.w;
    clip += u_behind_view_projection * vec4(displacement, 0.0);
    vec2 uv = clip.xy / max(clip.w, 1e-6) * 0.5 + 0.5;
    // The lobe reaches about 2 alpha from its axis (GGX's D is down to a tenth there); a mip
    // level of 2^lod pixels spans that diameter.
    float diameter = 4.0 * roughness * roughness * u_behind_pixels_per_radian;
    return textureLod(u_scene_behind, uv, log2(max(diameter, 1.0)));
}
#endif

// The radiance the lobe gathers: the environment (prefiltered along its direction) or, with
// TRANSMISSION_SCENE, the scene's opaque parts over it.
vec3 behind_radiance(TransmittedLobe lobe, Surface s, bool with_suns) {
    vec3 environment = prefiltered_radiance_at(lobe.direction, lobe.roughness, with_suns);
#ifdef TRANSMISSION_SCENE
    vec4 scene = scene_behind(lobe.direction * volume_path(s), lobe.roughness);
    return scene.rgb + (1.0 - scene.a) * environment;
#else
    return environment;
#endif
}

TransmittedLobe transmitted_lobe(Surface s, vec3 n, vec3 v) {
#ifdef HAS_VOLUME
    return thin_walled(s) ? thin_walled_lobe(s, n, v) : refracted_lobe(s, n, v);
#else
    return thin_walled_lobe(s, n, v);
#endif
}

// The lobe's energy times what it gathers (the environment, or with scene_only the opaque scene
// behind alone).
vec3 gathered_radiance(Surface s, vec3 n, vec3 v, bool with_suns, bool scene_only) {
    TransmittedLobe lobe = transmitted_lobe(s, n, v);
#ifdef TRANSMISSION_SCENE
    if (scene_only) return lobe.energy * scene_behind(lobe.direction * volume_path(s), lobe.roughness).rgb;
#endif
    return lobe.energy * behind_radiance(lobe, s, with_suns);
}

// gathered_radiance per channel: with KHR_materials_dispersion each channel's lobe refracts at
// its own index (the Sample Viewer's three rays); a thin wall has one lobe.
vec3 dispersed_radiance(Surface s, vec3 n, vec3 v, bool with_suns, bool scene_only) {
#ifdef HAS_DISPERSION
    if (!thin_walled(s) && s.dispersion > 0.0) {
        vec3 iors = dispersion_iors(s.ior, s.dispersion);
        Surface channel = s;
        vec3 radiance;
        channel.ior = iors.r;
        radiance.r = gathered_radiance(channel, n, v, with_suns, scene_only).r;
        channel.ior = iors.g;
        radiance.g = gathered_radiance(channel, n, v, with_suns, scene_only).g;
        channel.ior = iors.b;
        radiance.b = gathered_radiance(channel, n, v, with_suns, scene_only).b;
        return radiance;
    }
#endif
    return gathered_radiance(s, n, v, with_suns, scene_only);
}

vec3 transmission_ibl(Surface s, vec3 n, vec3 v, bool with_suns) {
    vec3 f0 = surface_f0(s);
    return transmission_weight(s) * s.base_color * (1.0 - f0) * dispersed_radiance(s, n, v, with_suns, false);
}

#ifdef TRANSMISSION_SCENE
// Without an environment (IBL off) the opaque scene behind still shows through.
vec3 transmission_scene_only(Surface s, vec3 n, vec3 v) {
    return transmission_weight(s) * s.base_color * (1.0 - surface_f0(s)) * dispersed_radiance(s, n, v, false, true);
}
#endif

#endif
