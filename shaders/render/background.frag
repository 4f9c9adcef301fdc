#version 450 core
// What lies behind the object (common/background.glsl), drawn on the far plane after the
// surfaces, so the depth test keeps it to the pixels they left uncovered.
// Alpha is 0 everywhere here: only surfaces count as hits (docs/conventions.md, image outputs).
#include "common/brdf.glsl"
#include "common/background.glsl"
#include "common/output_encoding.glsl"

in vec3 v_ray;    // render/background.vert: world-space, not normalised

layout(location = 0) out vec4 out_radiance;

void main() {
    out_radiance = encode_output(background_radiance(v_ray), 0.0);
}
