// The editor's debug views (Display > debug view). Compiled into pbr.frag only when DEBUG_VIEW
// is defined, so the normal shading path pays nothing for them. The data views
// (app/core/shader_names.py DATA_VIEWS) show values, not radiance: the editor displays them
// without exposure or tone mapping, and they are returned through srgb_to_linear_approx so that
// the tone map pass's sRGB encoding shows the raw value. The irradiance, the prefiltered radiance
// and the diffuse/specular splits are radiance and are shown as such; the splits are the
// lecture's, with the compact sources added (ibl.glsl).
// The guard is here, not around the #include: app/core/gpu.py's #line after an include must not sit
// inside a skipped conditional, or compile errors would name the wrong line.
#ifdef DEBUG_VIEW

uniform int u_debug_view;   // a DEBUG_VIEW_* value (app/core/shader_names.py DebugView)
uniform float u_debug_mip;  // view 10: the prefiltered cube's mip (grid A)

vec3 srgb_to_linear_approx(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c));
}

// D, G and F alone: for the first punctual light, or a light at the reflection direction when
// there is none (so the terms are seen at their peak there).
vec3 debug_light_direction(vec3 n, vec3 v, vec3 position) {
    if (u_light_count.x > 0) {
        vec4 vec = u_light_vector[0];
        return int(vec.w) == LIGHT_DIRECTIONAL ? -normalize(vec.xyz) : normalize(vec.xyz - position);
    }
    return reflect(-v, n);
}

vec3 debug_view(Surface s, vec3 n, vec3 v, vec3 position) {
    float n_dot_v = max(dot(n, v), 0.0);
    vec3 f0 = surface_f0(s);
    vec3 F_ibl = F_SchlickRoughness(n_dot_v, f0, s.roughness);
    vec3 l = debug_light_direction(n, v, position);
    vec3 h = normalize(l + v);
    float roughness = max(s.roughness, MIN_PUNCTUAL_ROUGHNESS);
    switch (u_debug_view) {
    case DEBUG_VIEW_BASE_COLOUR: return srgb_to_linear_approx(s.base_color);
    case DEBUG_VIEW_NORMAL: return srgb_to_linear_approx(n * 0.5 + 0.5);
    case DEBUG_VIEW_ROUGHNESS: return srgb_to_linear_approx(vec3(s.roughness));
    case DEBUG_VIEW_METALLIC: return srgb_to_linear_approx(vec3(s.metallic));
    case DEBUG_VIEW_F0: return srgb_to_linear_approx(f0);
    case DEBUG_VIEW_N_V: return srgb_to_linear_approx(vec3(n_dot_v));
    case DEBUG_VIEW_DIFFUSE_ONLY_IBL: return u_ibl_enabled ? (1.0 - F_ibl) * (1.0 - s.metallic) * s.base_color * irradiance_at(n, true) : vec3(0.0);
    case DEBUG_VIEW_SPECULAR_ONLY_IBL: {
        vec2 ab = brdf_lut_at(n_dot_v, s.roughness).xy;
        return u_ibl_enabled ? prefiltered_radiance_at(reflect(-v, n), s.roughness, true) * (F_ibl * ab.x + ab.y) : vec3(0.0);
    }
    case DEBUG_VIEW_IRRADIANCE: return u_ibl_enabled ? irradiance_at(n, true) : vec3(0.0);
    case DEBUG_VIEW_PREFILTERED_RADIANCE_AT_MIP: return u_ibl_enabled ? u_env_intensity * textureLod(u_prefiltered_radiance,
                 rotate_world_to_map(reflect(-v, n), u_env_rotation), u_debug_mip).rgb : vec3(0.0);
    case DEBUG_VIEW_BRDF_LUT: return srgb_to_linear_approx(vec3(brdf_lut_at(n_dot_v, s.roughness).xy, 0.0));
    // D can exceed 1 by far (1/(pi a^2) at the peak): shown as D / (1 + D) so the lobe's shape reads.
    case DEBUG_VIEW_D_FIRST_LIGHT: { float D = D_GGX(max(dot(n, h), 0.0), roughness); return srgb_to_linear_approx(vec3(D / (1.0 + D))); }
    case DEBUG_VIEW_G_FIRST_LIGHT: return srgb_to_linear_approx(vec3(G_Smith(max(n_dot_v, MIN_N_DOT_V), max(dot(n, l), 0.0), k_direct(roughness))));
    case DEBUG_VIEW_F_FIRST_LIGHT: return srgb_to_linear_approx(F_Schlick(max(dot(v, h), 0.0), f0));
    }
    return vec3(1.0, 0.0, 1.0);   // an unknown view: magenta
}
#endif
