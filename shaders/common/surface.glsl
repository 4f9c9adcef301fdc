// The material model of CONVENTIONS.md at one shading point.

struct Surface {
    vec3 base_color;   // linear albedo; F0 of metals
    float metallic;
    float roughness;   // perceptual; alpha = roughness^2
    vec3 specular_f0;  // F0 of the dielectric part
    vec3 emissive;     // linear radiance added on top
    float occlusion;   // ambient occlusion, scales image-based light only
};

// F0 = mix(specular_f0, base_color, metallic).
vec3 surface_f0(Surface s) {
    return mix(s.specular_f0, s.base_color, s.metallic);
}
