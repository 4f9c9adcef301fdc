// KHR_materials_iridescence's pure terms: the thin film's Fresnel of Belcour and Barla 2017 ("A
// Practical Extension to Microfacet Theory for the Modeling of Varying Iridescence"), as the
// Khronos glTF Sample Viewer evaluates it. Numpy twin: app/core/layers/iridescence.py (same
// names); the model: docs/layer_iridescence.md.

// CIE XYZ to linear Rec. 709 (sRGB primaries, D65); GLSL matrices are column-major.
const mat3 XYZ_TO_REC709 = mat3(
     3.2404542, -0.9692660,  0.0556434,
    -1.5371385,  1.8760108, -0.2040259,
    -0.4985314,  0.0415560,  1.0572252);
// A film thinner than this (nm) fades to no film; a substrate F0 of 1 has no ior.
const float FILM_FADE_NM = 0.03;
const float MAX_SUBSTRATE_F0 = 0.9999;

// Normal-incidence reflectance of an interface: ((n_t - n_i) / (n_t + n_i))^2 (Fresnel 1823).
float ior_to_f0(float transmitted_ior, float incident_ior) {
    float r = (transmitted_ior - incident_ior) / (transmitted_ior + incident_ior);
    return r * r;
}

vec3 ior_to_f0(vec3 transmitted_ior, float incident_ior) {
    vec3 r = (transmitted_ior - incident_ior) / (transmitted_ior + incident_ior);
    return r * r;
}

// The inverse against air: (1 + sqrt(F0)) / (1 - sqrt(F0)).
vec3 f0_to_ior(vec3 f0) {
    vec3 s = sqrt(f0);
    return (1.0 + s) / (1.0 - s);
}

// Schlick 1994 with F90 = 1, for the film's interfaces: f0 + (1 - f0)(1 - cos)^5.
float fresnel_schlick_scalar(float f0, float cos_theta) {
    float x = clamp(1.0 - cos_theta, 0.0, 1.0);
    float x2 = x * x;
    return f0 + (1.0 - f0) * (x2 * x2 * x);
}

vec3 fresnel_schlick_scalar(vec3 f0, float cos_theta) {
    float x = clamp(1.0 - cos_theta, 0.0, 1.0);
    float x2 = x * x;
    return f0 + (1.0 - f0) * (x2 * x2 * x);
}

// The XYZ sensitivity at optical path difference opd (nm) and phase shift, in linear Rec. 709:
// Belcour and Barla's Gaussian fits in Fourier space (their supplemental code).
vec3 iridescence_sensitivity(float opd, vec3 shift) {
    float phase = 2.0 * PI * opd * 1.0e-9;
    const vec3 val = vec3(5.4856e-13, 4.4201e-13, 5.2481e-13);
    const vec3 pos = vec3(1.6810e+06, 1.7953e+06, 2.2084e+06);
    const vec3 var = vec3(4.3278e+09, 9.3046e+09, 6.6121e+09);
    vec3 xyz = val * sqrt(2.0 * PI * var) * cos(pos * phase + shift) * exp(-phase * phase * var);
    xyz.x += 9.7470e-14 * sqrt(2.0 * PI * 4.5282e+09) * cos(2.2399e+06 * phase + shift.x) * exp(-4.5282e+09 * phase * phase);
    return XYZ_TO_REC709 * (xyz / 1.0685e-7);
}

// The thin film's reflectance at cos theta1 for a film of film_ior and thickness (nm) over a
// substrate of F0 base_f0, seen from outside_ior: the Airy sum to the second order (Belcour and
// Barla 2017). Total internal reflection in the film gives 1.
vec3 iridescence_fresnel(float outside_ior, float film_ior, float cos_theta1, float thickness, vec3 base_f0) {
    float film = mix(outside_ior, film_ior, smoothstep(0.0, FILM_FADE_NM, thickness));
    float sin2_sq = (outside_ior / film) * (outside_ior / film) * (1.0 - cos_theta1 * cos_theta1);
    float cos2_sq = 1.0 - sin2_sq;
    if (cos2_sq < 0.0) return vec3(1.0);
    float cos2 = sqrt(cos2_sq);
    // The first interface (outside -> film): a phase flip of pi where the film is the lower index.
    float r12 = fresnel_schlick_scalar(ior_to_f0(film, outside_ior), cos_theta1);
    float t121 = 1.0 - r12;
    float phi12 = film < outside_ior ? PI : 0.0;
    float phi21 = PI - phi12;
    // The second interface (film -> substrate).
    vec3 base_ior = f0_to_ior(clamp(base_f0, 0.0, MAX_SUBSTRATE_F0));
    vec3 r23 = fresnel_schlick_scalar(ior_to_f0(base_ior, film), cos2);
    vec3 phi23 = vec3(base_ior.x < film ? PI : 0.0, base_ior.y < film ? PI : 0.0, base_ior.z < film ? PI : 0.0);
    float opd = 2.0 * film * thickness * cos2;
    vec3 phi = vec3(phi21) + phi23;
    vec3 r123 = clamp(r12 * r23, 1e-5, 0.9999);
    vec3 rs = t121 * t121 * r23 / (1.0 - r123);
    vec3 result = r12 + rs;               // m = 0: the incoherent sum
    vec3 cm = rs - t121;
    for (int m = 1; m <= 2; ++m) {        // m > 0: the interference terms
        cm *= sqrt(r123);
        result += cm * 2.0 * iridescence_sensitivity(float(m) * opd, float(m) * phi);
    }
    // Out-of-gamut colours clamp to [0, 1]: above 1 the film would reflect more than it receives
    // (the Sample Viewer clamps only below; app/core/layers/iridescence.py measures how often).
    return clamp(result, 0.0, 1.0);
}
