// KHR_materials_sheen: the Charlie sheen BRDF (Estevez and Kulla 2017) over the base, which it
// scales by its albedo (common/layers.glsl declares these; docs/layers.md).
// Numpy twin: app/core/layers/sheen.py.
#ifdef HAS_SHEEN

float sheen_base_weight(Surface s, vec3 n, vec3 v, vec3 l) {
    return 1.0;
}

vec3 sheen_light(Surface s, vec3 n, vec3 v, vec3 l, bool punctual, float spread) {
    return vec3(0.0);
}

float sheen_base_weight_ibl(Surface s, vec3 n, vec3 v) {
    return 1.0;
}

vec3 sheen_ibl(Surface s, vec3 n, vec3 v, bool with_suns) {
    return vec3(0.0);
}

#endif
