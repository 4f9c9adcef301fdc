// The base's Cook-Torrance f(l, v) (n.l) for one light direction, written once and called by the
// punctual lights (punctual.glsl), the compact sources (ibl.glsl's sun_light) and the ground
// truth (accuracy/ground_truth.glsl), the way Filament's surfaceShading() composes its lobes:
// the caller finds the angles and chooses the lobe's roughness and Smith k, this file adds the
// Fresnel, the diffuse lobe and the specular lobe. Numpy twins: app/core/layers/stack.py
// (base_brdf_cos, the exact sum) and app/core/shading.py (punctual_light); the model:
// docs/conventions.md, docs/layers.md.
// Terms from common/brdf.glsl; the layers' hooks declared in common/layers.glsl.

// The angles of one direction l at a shading point (Filament's NoV, NoL, NoH, LoH), as the
// caller clamps them: n_dot_v floored at MIN_N_DOT_V, n_dot_l > 0.
struct LobeAngles {
    float n_dot_v;
    float n_dot_l;
    float n_dot_h;
    float v_dot_h;
};

// The caller's quality choice for the isotropic lobe: D's roughness (floored, or widened by a
// compact source's spread) and the Smith k (k_direct for punctual lights, k_ibl otherwise);
// punctual and spread pass the same choice to the anisotropic lobe (common/anisotropy.glsl).
struct LobeChoice {
    float d_roughness;
    float k;
    bool punctual;
    float spread;
};

// The Fresnel of the base's lobes at v.h (Schlick 1994, with KHR_materials_specular's F90); a
// thin film (HAS_IRIDESCENCE, common/iridescence.glsl) mixes its own into it.
vec3 base_fresnel(Surface s, vec3 f0, LobeAngles a) {
    return F_Schlick(a.v_dot_h, f0, surface_f90(s));
}

// Filament's specularLobe: D G F / (4 n.l n.v), stretched along the tangent with HAS_ANISOTROPY.
vec3 base_specular_lobe(Surface s, vec3 n, vec3 v, vec3 l, LobeAngles a, LobeChoice c, vec3 F) {
#ifdef HAS_ANISOTROPY
    return anisotropic_specular(s, n, v, l, F, c.punctual, c.spread);
#else
    float D = D_GGX(a.n_dot_h, c.d_roughness);
    float G = G_Smith(a.n_dot_v, a.n_dot_l, c.k);
    return D * G * F / (4.0 * a.n_dot_l * a.n_dot_v);
#endif
}

// Filament's diffuseLobe: kd Lambert, kd = (1 - F)(1 - metallic)(1 - transmission)(1 - diffuse_transmission);
// F is the diffuse lobe's Fresnel (with HAS_IRIDESCENCE the film's largest channel mixed in).
vec3 base_diffuse_lobe(Surface s, vec3 F) {
    vec3 kd = (1.0 - F) * (1.0 - s.metallic);
#ifdef HAS_TRANSMISSION
    kd *= 1.0 - s.transmission;   // the rest of the diffuse lobe is transmitted (transmission.glsl)
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
    kd *= diffuse_transmission_front_weight(s);   // the rest leaves through the back (diffuse_transmission.glsl)
#endif
    return kd * Fd_Lambert(s.base_color);
}

// Filament's surfaceShading without the light's colour: (diffuse + specular) n.l.
vec3 base_lobes(Surface s, vec3 f0, vec3 n, vec3 v, vec3 l, LobeAngles a, LobeChoice c) {
    vec3 F = base_fresnel(s, f0, a);
#ifdef HAS_IRIDESCENCE
    return (base_diffuse_lobe(s, iridescence_diffuse_fresnel(s, F))
            + base_specular_lobe(s, n, v, l, a, c, iridescence_specular_fresnel(s, F))) * a.n_dot_l;
#else
    return (base_diffuse_lobe(s, F) + base_specular_lobe(s, n, v, l, a, c, F)) * a.n_dot_l;
#endif
}
