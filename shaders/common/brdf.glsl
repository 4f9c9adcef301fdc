// The Cook-Torrance terms of the lecture, one function per term (after Filament's brdf.fs).
// Numpy twins: app/core/shading.py (same names). Conventions: docs/conventions.md.

const float PI = 3.14159265358979323846;

// Quality and robustness choices, in one place:
// Roughness floor for punctual lights: GGX with alpha -> 0 is a delta that a point light can
// never hit exactly, and D(1) = 1/(pi alpha^2) overflows half floats (Filament uses 0.045).
const float MIN_PUNCTUAL_ROUGHNESS = 0.045;
// n.v floor: keeps G/(4 n.l n.v) finite at silhouettes, where interpolated normals face away.
const float MIN_N_DOT_V = 1e-4;

// Trowbridge-Reitz GGX normal distribution, alpha = roughness^2 (Walter et al. 2007).
float D_GGX(float n_dot_h, float roughness) {
    float a = roughness * roughness;
    float a2 = a * a;
    float d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

// Schlick-GGX k for punctual lights (Karis 2013, "Real Shading in Unreal Engine 4").
float k_direct(float roughness) {
    float r = roughness + 1.0;
    return r * r / 8.0;
}

// Schlick-GGX k for image-based lighting (Karis 2013).
float k_ibl(float roughness) {
    return roughness * roughness / 2.0;
}

// Schlick's approximation of Smith masking for one direction (Schlick 1994).
float G1_SchlickGGX(float n_dot_x, float k) {
    return n_dot_x / (n_dot_x * (1.0 - k) + k);
}

// Separable Smith geometry: masking of v times shadowing of l (Smith 1967).
float G_Smith(float n_dot_v, float n_dot_l, float k) {
    return G1_SchlickGGX(n_dot_v, k) * G1_SchlickGGX(n_dot_l, k);
}

// Schlick's Fresnel approximation (Schlick 1994).
vec3 F_Schlick(float v_dot_h, vec3 f0) {
    float x = clamp(1.0 - v_dot_h, 0.0, 1.0);
    float x2 = x * x;
    return f0 + (1.0 - f0) * (x2 * x2 * x);
}

// Schlick's Fresnel with a reflectance f90 at grazing incidence other than 1 (Schlick 1994's
// form, as KHR_materials_specular's F90 = specularFactor uses it): f0 + (f90 - f0)(1 - v.h)^5.
vec3 F_Schlick(float v_dot_h, vec3 f0, float f90) {
    float x = clamp(1.0 - v_dot_h, 0.0, 1.0);
    float x2 = x * x;
    return f0 + (f90 - f0) * (x2 * x2 * x);
}

// The lecture's roughness-aware Fresnel for ambient light (Lagarde 2011, after Schlick).
vec3 F_SchlickRoughness(float n_dot_v, vec3 f0, float roughness) {
    float x = clamp(1.0 - n_dot_v, 0.0, 1.0);
    float x2 = x * x;
    return f0 + (max(vec3(1.0 - roughness), f0) - f0) * (x2 * x2 * x);
}

// Lambertian diffuse (Lambert 1760).
vec3 Fd_Lambert(vec3 base_color) {
    return base_color / PI;
}
