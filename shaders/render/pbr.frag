#version 450 core
// Forward PBR pass: a mesh with the metal-roughness material (factors times glTF textures).
// ALPHA_MODE (glTF 2.0 material.alphaMode; app/core/shader_names.py AlphaMode): unset or OPAQUE
// (alpha ignored, written as 1), MASK (fragments below the cutoff discarded; under MSAA,
// ALPHA_TO_COVERAGE = the sample count: the samples kept by alpha_coverage_mask), BLEND (alpha
// written; the renderer blends).
// UNLIT (KHR_materials_unlit): the base colour is the radiance.
// SPHERE_IMPOSTOR: the built-in sphere's proxy, coverage per pixel (common/mesh_material.glsl).
#include "common/shading.glsl"
#include "common/mesh_material.glsl"
#include "common/debug_views.glsl"
#include "common/output_encoding.glsl"

layout(location = 0) out vec4 out_radiance;

void main() {
#ifdef SPHERE_IMPOSTOR
    float coverage = sphere_coverage();
    if (coverage == 0.0) discard;
#endif
#if defined(ALPHA_MODE) && ALPHA_MODE != ALPHA_MODE_OPAQUE
    float alpha = material_alpha();
#if ALPHA_MODE == ALPHA_MODE_MASK
#ifdef ALPHA_TO_COVERAGE
    int kept_samples = alpha_coverage_mask(alpha);
    if (kept_samples == 0) discard;
    gl_SampleMask[0] = kept_samples;
#else
    if (alpha < u_alpha_cutoff) discard;
#endif
    alpha = 1.0;
#endif
#else
    const float alpha = 1.0;
#endif
#ifdef UNLIT
    out_radiance = encode_output(material_base_color().rgb, alpha);
#else
    vec3 n = shading_normal();
    vec3 v = normalize(u_camera_position - surface_position());
#ifdef HAS_SHADOWS
    set_shadow_receiver(surface_position(), geometric_normal());   // (common/shadows.glsl)
#endif
#ifdef DEBUG_VIEW
    out_radiance = encode_output(debug_view(material_surface(n), n, v, surface_position()), alpha);
#else
    out_radiance = encode_output(shade(material_surface(n), n, v, surface_position()), alpha);
#endif
#endif
#if defined(SPHERE_IMPOSTOR) && SPHERE_IMPOSTOR > 1
    // Premultiplied by coverage, as the mean of the samples an MSAA target would resolve to.
    out_radiance *= coverage;
#endif
}
