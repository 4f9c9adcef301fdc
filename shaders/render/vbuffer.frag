#version 450 core
// The visibility pass of a mesh shaded from the visibility buffer (app/render/vbuffer.py): per
// sample, which triangle of which part is nearest, as (gl_PrimitiveID + 1, part + 1) in an
// integer target cleared to 0 (no surface). Nothing is shaded here but an alphaMode MASK
// part's alpha test (glTF 2.0 section 3.9.4), at the pixel as the forward pass tests it.
#if defined(ALPHA_MODE) && ALPHA_MODE == ALPHA_MODE_MASK
#include "common/mesh_material.glsl"
#else
layout(early_fragment_tests) in;
#endif

uniform uint u_part;   // the part's index + 1

layout(location = 0) out uvec2 out_id;

void main() {
#if defined(ALPHA_MODE) && ALPHA_MODE == ALPHA_MODE_MASK
#ifdef ALPHA_TO_COVERAGE
    int kept_samples = alpha_coverage_mask(material_alpha());   // (the forward pass's samples)
    if (kept_samples == 0) discard;
    gl_SampleMask[0] = kept_samples;
#else
    if (material_alpha() < u_alpha_cutoff) discard;
#endif
#endif
    out_id = uvec2(uint(gl_PrimitiveID) + 1u, u_part);
}
