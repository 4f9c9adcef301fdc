#version 450 core
// What lies behind the object: the environment, a blurred environment, or a solid colour.
// Alpha is 0 everywhere here: only surfaces count as hits (CONVENTIONS.md, image outputs).
#include "common/brdf.glsl"
#include "common/equirect.glsl"
#include "common/output_encoding.glsl"

const int BACKGROUND_ENV = 0;
const int BACKGROUND_BLUR = 1;
const int BACKGROUND_COLOR = 2;

in vec2 v_ndc;

uniform int u_mode;
uniform mat4 u_inverse_view_projection;
uniform samplerCube u_environment;            // the source cube (sharp)
uniform samplerCube u_prefiltered_radiance;   // for the blurred background
uniform float u_blur_mip;
uniform vec2 u_env_rotation;
uniform float u_env_intensity;
uniform vec3 u_color;

layout(location = 0) out vec4 out_radiance;

void main() {
    if (u_mode == BACKGROUND_COLOR) {
        out_radiance = encode_output(u_color, 0.0);
        return;
    }
    vec4 near = u_inverse_view_projection * vec4(v_ndc, -1.0, 1.0);
    vec4 far = u_inverse_view_projection * vec4(v_ndc, 1.0, 1.0);
    vec3 d = rotate_world_to_map(normalize(far.xyz / far.w - near.xyz / near.w), u_env_rotation);
    vec3 radiance = u_mode == BACKGROUND_BLUR
        ? textureLod(u_prefiltered_radiance, d, u_blur_mip).rgb
        : textureLod(u_environment, d, 0.0).rgb;
    out_radiance = encode_output(u_env_intensity * radiance, 0.0);
}
