// KHR_materials_dispersion's term (docs/layer_dispersion.md): each colour channel refracts at
// its own index about the material's ior (n_d). dispersion = 20 / V_d with the Abbe number
// V_d = (n_d - 1) / (n_F - n_C), so the red (C) and blue (F) indices lie (ior - 1) dispersion / 40
// either side of it, as the Khronos glTF Sample Viewer spreads them.
// Numpy twin: app/core/layers/dispersion.py (same name).

// Half of n_F - n_C per unit of (ior - 1) dispersion.
const float HALF_SPREAD_PER_DISPERSION = 1.0 / 40.0;

// The red, green and blue channels' indices of refraction.
vec3 dispersion_iors(float ior, float dispersion) {
    float half_spread = (ior - 1.0) * HALF_SPREAD_PER_DISPERSION * dispersion;
    return vec3(ior - half_spread, ior, ior + half_spread);
}
