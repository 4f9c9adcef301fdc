// KHR_materials_clearcoat: a GGX coat over the base, layered by the coat's Fresnel
// (common/layers.glsl declares these; docs/layers.md). Numpy twin: app/core/layers/clearcoat.py.
#ifdef HAS_CLEARCOAT

float clearcoat_base_weight(Surface s, vec3 v) {
    return 1.0;
}

vec3 clearcoat_light(Surface s, vec3 v, vec3 l, bool punctual, float spread) {
    return vec3(0.0);
}

vec3 clearcoat_ibl(Surface s, vec3 v, bool with_suns) {
    return vec3(0.0);
}

#endif
