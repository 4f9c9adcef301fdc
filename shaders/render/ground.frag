#version 450 core
// The ground as a shadow catcher (as model-viewer's shadow and Marmoset's shadow catcher): it
// is not seen itself; what it takes away from what lies behind it is the share of the light
// reaching it that the model blocks, 1 - E_shadowed / E (E: the irradiance at its up normal
// from the environment, the suns and the punctual lights). Written as (0, 0, 0, that share),
// blended with (ZERO, ONE_MINUS_SRC_ALPHA; ONE, ONE_MINUS_SRC_ALPHA) over the background: the
// background darkened by it, or over a transparent one a black shadow in alpha.
// The environment's broad light is not occluded here (only the suns' and lights' shadows are).
#include "common/shading.glsl"

in vec3 v_position;

uniform vec4 u_ground;          // as ground.vert
uniform float u_ground_fade;    // distance from the centre where the shadow has faded out (world)

layout(location = 0) out vec4 out_color;

// The irradiance / pi at the ground from the punctual lights: (without shadows, with them).
vec2 lights_on_ground(vec3 n) {
    vec2 e = vec2(0.0);
    for (int i = 0; i < min(u_light_count.x, MAX_LIGHTS); ++i) {
        vec4 vec = u_light_vector[i];
        vec3 l;
        float radiance_in = dot(u_light_radiance[i].rgb, vec3(1.0 / 3.0));
        if (int(vec.w) == LIGHT_DIRECTIONAL) {
            l = -normalize(vec.xyz);
        } else {
            vec3 to_light = vec.xyz - v_position;
            float d2 = max(dot(to_light, to_light), 1e-8);
            l = to_light * inversesqrt(d2);
            radiance_in /= d2;
#ifdef PUNCTUAL_RANGE
            radiance_in *= range_attenuation(d2, u_light_cone[i].z);
#endif
#ifdef PUNCTUAL_SPOT
            if (int(vec.w) == LIGHT_SPOT) radiance_in *= spot_attenuation(u_light_spot[i].xyz, l, u_light_cone[i].xy);
#endif
        }
        float e_i = radiance_in * max(dot(n, l), 0.0) / PI;
        e += vec2(e_i, e_i * light_shadow(i, int(vec.w), l, vec.xyz));
    }
    return e;
}

void main() {
    vec3 n = vec3(0.0, 1.0, 0.0);
    set_shadow_receiver(v_position, n);
    vec2 e = lights_on_ground(n);
    if (u_ibl_enabled) {
        float sky = dot(irradiance_at(n, false), vec3(1.0 / 3.0));
        e += vec2(sky);
        for (int i = 0; i < u_sun_count; ++i) {
            float e_i = dot(u_sun_power[i], vec3(1.0 / 3.0)) * max(dot(n, u_sun_direction[i]), 0.0) / PI;
            e += vec2(e_i, e_i * sun_shadow(i, u_sun_direction[i]));
        }
    }
    float share = e.x > 0.0 ? clamp(1.0 - e.y / e.x, 0.0, 1.0) : 0.0;
    // Faded out toward the square's edge, so the ground has no visible border.
    float r = length(v_position.xz - u_ground.xz);
    share *= 1.0 - smoothstep(0.6 * u_ground_fade, u_ground_fade, r);
    out_color = vec4(0.0, 0.0, 0.0, share);
}
