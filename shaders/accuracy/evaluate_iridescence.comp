#version 450 core
// Evaluates KHR_materials_iridescence's GLSL functions per row of inputs (tests/gpu.py's
// evaluate, with shader="accuracy/evaluate_iridescence.comp" and HAS_IRIDESCENCE defined), for
// tests/test_glsl_twins.py to compare with the numpy twins (app/core/layers/iridescence.py,
// app/core/layers/stack.py). The film's factors are uniforms (common/material_iridescence.glsl);
// u_params = (outside ior, metallic, roughness, 0). Not used for rendering.
#include "accuracy/ground_truth.glsl"
#include "common/material_layers.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 u_inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 u_outputs[]; };
uniform int u_count;
uniform int u_term;
uniform vec4 u_params;

const int TERM_SENSITIVITY = 0;   // a = (opd nm, shift rgb): o.xyz
const int TERM_FRESNEL = 1;       // a = (cos theta1, thickness nm, film ior, substrate F0 grey): o.xyz
const int TERM_BASE_BRDF = 2;     // a = (n.v, l): brdf_ground_truth's o.xyz, the film from the uniforms
const int TERM_IBL_WEIGHTS = 3;   // a = (n.v, A, B): (spec_albedo.xyz, diffuse_weight.x) of karis_split_sum

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(u_count)) return;
    vec4 a = u_inputs[i];
    vec4 o = vec4(0.0);
    vec3 n = vec3(0.0, 0.0, 1.0);
    vec3 v = vec3(sqrt(max(1.0 - a.x * a.x, 0.0)), 0.0, a.x);
    Surface s = surface_base(vec3(0.8, 0.5, 0.3), u_params.y, u_params.z, vec3(0.04), vec3(0.0), 1.0);
    apply_material_iridescence(s);
    iridescence_at_view(s, n, v);
    switch (u_term) {
        case TERM_SENSITIVITY: o.xyz = iridescence_sensitivity(a.x, a.yzw); break;
        case TERM_FRESNEL: o.xyz = iridescence_fresnel(u_params.x, a.z, a.x, a.y, vec3(a.w)); break;
        case TERM_BASE_BRDF: o.xyz = brdf_ground_truth(s, surface_f0(s), n, v, max(a.x, MIN_N_DOT_V), a.yzw); break;
        case TERM_IBL_WEIGHTS: {
            vec3 f0 = surface_f0(s);
            vec3 spec_albedo = f0 * a.y + a.z;
            vec3 diffuse_weight = 1.0 - f0 - (1.0 - f0) * diffuse_fresnel(a.x);
            iridescence_ibl_weights(s, vec4(a.y, a.z, 0.0, 0.0), diffuse_weight, spec_albedo);
            o = vec4(spec_albedo, diffuse_weight.x);
            break;
        }
    }
    u_outputs[i] = o;
}
