// The material model of docs/conventions.md at one shading point, with the glTF layers
// (docs/layers.md). A layer's fields exist only when its HAS_* define is set
// (app/core/layers/__init__.py: layer_defines), so a material without layers compiles to the
// base model alone and pays nothing for them.

struct Surface {
    vec3 base_color;   // linear albedo; F0 of metals
    float metallic;
    float roughness;   // perceptual; alpha = roughness^2
    vec3 specular_f0;  // F0 of the dielectric part
    float specular_f90; // F90 of the dielectric part: KHR_materials_specular's specularFactor, else 1
    vec3 emissive;     // linear radiance added on top
    float occlusion;   // ambient occlusion, scales image-based light only
#ifdef HAS_CLEARCOAT
    float clearcoat;            // KHR_materials_clearcoat: the coat's weight
    float clearcoat_roughness;  // perceptual; alpha = clearcoat_roughness^2
    vec3 clearcoat_normal;      // world space: n, unless the coat has its own normal map
#endif
#ifdef HAS_SHEEN
    vec3 sheen_color;           // KHR_materials_sheen, linear
    float sheen_roughness;      // perceptual; the Charlie distribution's alpha = sheen_roughness^2
#endif
#ifdef HAS_ANISOTROPY
    float anisotropy_strength;  // KHR_materials_anisotropy
    vec3 anisotropy_direction;  // world-space unit tangent along which the lobe stretches
    vec3 anisotropy_bitangent;  // cross(n, anisotropy_direction)
#endif
#ifdef HAS_TRANSMISSION
    float transmission;         // KHR_materials_transmission
    float ior;                  // KHR_materials_ior: the refraction's index
#endif
#ifdef HAS_IRIDESCENCE
    float iridescence;           // KHR_materials_iridescence: the thin film's weight (0: no film)
    float iridescence_ior;       // the film's index
    float iridescence_thickness; // nm
    vec3 iridescence_fresnel;    // the film's Fresnel at the view's n.v (common/iridescence.glsl)
#endif
#ifdef HAS_VOLUME
    float thickness;            // KHR_materials_volume, in world units at this point
    vec3 attenuation_color;
    float attenuation_distance; // +inf (a huge number) for none
#endif
#ifdef HAS_DISPERSION
    float dispersion;           // KHR_materials_dispersion: 20 / Abbe number
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
    float diffuse_transmission;       // KHR_materials_diffuse_transmission
    vec3 diffuse_transmission_color;  // linear
#endif
};

// A normal map's spread lost by its mip filtering, added to GGX's alpha^2 (numpy twin:
// app/core/shading.py). Toksvig 2005 ("Mipmapping Normal Maps"): the mean normal's length |Na|
// gives the variance sigma^2 = (1 - |Na|) / |Na|; variances add (Hill 2011, "Specular Showdown
// in the Wild West"). Added with the factor 1: bench_helmet_split.py --toksvig read 11.6% with it
// and 14.9% with 2 (results/helmet_split.md); to first order in 1 - |Na| it is also the von
// Mises-Fisher estimate 1/kappa (Neubelt and Pettineo 2013). ``widening`` is the texel's A
// (alight.render.normal_spread): sigma^2 = A^4.
float normal_map_roughness(float roughness, float widening) {
    float a = roughness * roughness;
    float w = widening * widening;
    return sqrt(sqrt(a * a + w * w));
}

// F0 = mix(specular_f0, base_color, metallic).
vec3 surface_f0(Surface s) {
    return mix(s.specular_f0, s.base_color, s.metallic);
}

// F90 = mix(specular_f90, 1, metallic): KHR_materials_specular scales the dielectric Fresnel at
// grazing incidence too (its specularFactor), a metal's F90 stays 1.
float surface_f90(Surface s) {
    return mix(s.specular_f90, 1.0, s.metallic);
}

// A Surface with the base model's fields; every compiled-in layer starts off (glTF's defaults).
// The layers' own values come from common/material_layers.glsl (uniforms and maps).
Surface surface_base(vec3 base_color, float metallic, float roughness, vec3 specular_f0, vec3 emissive,
                     float occlusion) {
    Surface s;
    s.base_color = base_color;
    s.metallic = metallic;
    s.roughness = roughness;
    s.specular_f0 = specular_f0;
    s.specular_f90 = 1.0;
    s.emissive = emissive;
    s.occlusion = occlusion;
#ifdef HAS_CLEARCOAT
    s.clearcoat = 0.0;
    s.clearcoat_roughness = 0.0;
    s.clearcoat_normal = vec3(0.0, 0.0, 1.0);
#endif
#ifdef HAS_SHEEN
    s.sheen_color = vec3(0.0);
    s.sheen_roughness = 0.0;
#endif
#ifdef HAS_ANISOTROPY
    s.anisotropy_strength = 0.0;
    s.anisotropy_direction = vec3(1.0, 0.0, 0.0);
    s.anisotropy_bitangent = vec3(0.0, 1.0, 0.0);
#endif
#ifdef HAS_TRANSMISSION
    s.transmission = 0.0;
    s.ior = 1.5;
#endif
#ifdef HAS_IRIDESCENCE
    s.iridescence = 0.0;
    s.iridescence_ior = 1.3;
    s.iridescence_thickness = 400.0;
    s.iridescence_fresnel = vec3(0.0);
#endif
#ifdef HAS_VOLUME
    s.thickness = 0.0;
    s.attenuation_color = vec3(1.0);
    s.attenuation_distance = 3.0e38;
#endif
#ifdef HAS_DISPERSION
    s.dispersion = 0.0;
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
    s.diffuse_transmission = 0.0;
    s.diffuse_transmission_color = vec3(1.0);
#endif
    return s;
}
