// Image-based lighting by the split sum (Karis 2013), as the seed lecture's cook_torrance_IBL.
// Maps are baked in the environment map's own frame; lookups rotate world directions into it.

uniform samplerCube u_irradiance;            // E/pi: the cosine-weighted mean radiance
uniform samplerCube u_environment;           // source radiance with box mips: the mirror (r = 0)
uniform samplerCube u_prefiltered_radiance;  // grid A: mip m holds alpha = 2^(m - max_mip)
uniform samplerCube u_prefiltered_radiance_mid;  // grid B: mip j holds alpha_A(j + 1) / sqrt(2)
uniform sampler2D u_brdf_lut;                // (scale A, bias B) over (n.v, roughness)
uniform float u_prefiltered_max_mip;         // last mip of grid A (roughness 1)
uniform vec2 u_env_rotation;                 // (cos, sin) of minus the rotation angle
uniform float u_env_intensity;

// Prefiltered radiance lives on a grid of roughness steps where alpha = r^2 grows by sqrt(2)
// per step, alternating between two cubes: even steps are grid A's mips, odd steps grid B's.
// Each A mip halves the resolution as alpha doubles; B fills the gaps, so blending neighbours
// costs two bilinear fetches (as one trilinear fetch would) but with steps half as coarse.
// app/bake.py's grid_roughness() gives the roughness of each step; this is its inverse.
float roughness_to_grid_step(float roughness) {
    return 2.0 * (2.0 * log2(max(roughness, 1e-4)) + u_prefiltered_max_mip);
}

vec3 prefiltered_grid(vec3 d, int step) {
    float mip = float(step >> 1);
    return (step & 1) == 0 ? textureLod(u_prefiltered_radiance, d, mip).rgb
                           : textureLod(u_prefiltered_radiance_mid, d, mip).rgb;
}

vec3 irradiance_at(vec3 n) {
    return u_env_intensity * texture(u_irradiance, rotate_world_to_map(n, u_env_rotation)).rgb;
}

vec3 prefiltered_radiance_at(vec3 r, float roughness) {
    vec3 d = rotate_world_to_map(r, u_env_rotation);
    float step = roughness_to_grid_step(roughness);
    vec3 radiance;
    if (step < 0.0) {
        // Below grid A's first step (r = 2^(-max_mip/2)): the source cube's box mips whose texel
        // matches the lobe width alpha, fading into the first prefiltered step.
        float r0 = exp2(-0.5 * u_prefiltered_max_mip);
        float texel_angle = 0.5 * PI / float(textureSize(u_environment, 0).x);
        float lod = max(log2(roughness * roughness / texel_angle), 0.0);
        float t = (roughness / r0) * (roughness / r0);
        radiance = mix(textureLod(u_environment, d, lod).rgb, prefiltered_grid(d, 0), t);
    } else {
        float last = 2.0 * u_prefiltered_max_mip;
        step = min(step, last);
        int lo = int(floor(step));
        radiance = mix(prefiltered_grid(d, lo), prefiltered_grid(d, min(lo + 1, int(last))), step - float(lo));
    }
    return u_env_intensity * radiance;
}

vec2 brdf_lut_at(float n_dot_v, float roughness) {
    return texture(u_brdf_lut, vec2(n_dot_v, roughness)).rg;
}

// The lecture's cook_torrance_IBL: kd from the roughness-aware Fresnel at n.v, Lambert times the
// irradiance map, and the prefiltered radiance times the LUT's (F * A + B).
vec3 ibl_lecture(Surface s, vec3 n, vec3 v) {
    float n_dot_v = max(dot(n, v), 0.0);
    vec3 f0 = surface_f0(s);
    vec3 F = F_SchlickRoughness(n_dot_v, f0, s.roughness);
    vec3 kd = (1.0 - F) * (1.0 - s.metallic);
    vec3 diffuse = kd * s.base_color * irradiance_at(n);
    vec2 ab = brdf_lut_at(n_dot_v, s.roughness);
    vec3 specular = prefiltered_radiance_at(reflect(-v, n), s.roughness) * (F * ab.x + ab.y);
    return (diffuse + specular) * s.occlusion;
}

// The model the forward pass uses: IBL_MODEL is the position of its name in app/ibl_models.py's
// IBL_MODELS, set by app/renderer.py, so only the chosen model is compiled.
#ifndef IBL_MODEL
#define IBL_MODEL 0
#endif
vec3 ibl_model(Surface s, vec3 n, vec3 v) {
    return ibl_lecture(s, n, v);
}
