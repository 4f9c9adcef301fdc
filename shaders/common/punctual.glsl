// Point, spot and directional lights through the reflectance equation (a delta light: no
// integral). Spot cones and range windows are compiled in only for scenes that have them
// (PUNCTUAL_SPOT, PUNCTUAL_RANGE): llvmpipe runs both sides of a branch.

// LIGHT_POINT, LIGHT_DIRECTIONAL, LIGHT_SPOT: app/core/shader_names.py LightKind (generated).
const int MAX_LIGHTS = 16;

// xyz: position (point, spot) or direction the light travels (directional); w: LIGHT_* type.
// rgb of u_light_radiance: colour times intensity (W/sr-like for points and spots, divided by
// the squared distance; irradiance for directional lights). u_light_spot: the direction a spot
// points (xyz). u_light_cone: the cone's scale and offset (KHR_lights_punctual), the range
// (0: none).
layout(std140, binding = 0) uniform Lights {
    vec4 u_light_vector[MAX_LIGHTS];
    vec4 u_light_radiance[MAX_LIGHTS];
    ivec4 u_light_count;
    vec4 u_light_spot[MAX_LIGHTS];
    vec4 u_light_cone[MAX_LIGHTS];
};

// The base's f(l, v) (n.l) for one light, with the lecture's punctual k = (r+1)^2/8; with
// HAS_TRANSMISSION also the transmitted part, for light from either side (common/layers.glsl).
vec3 punctual_base(Surface s, vec3 n, vec3 v, vec3 l) {
#ifdef HAS_TRANSMISSION
    vec3 transmitted = transmission_light(s, n, v, l, true, 0.0);
#else
    vec3 transmitted = vec3(0.0);
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
    transmitted += diffuse_transmission_light(s, n, v, l);
#endif
    LobeAngles a;
    a.n_dot_l = dot(n, l);
    if (a.n_dot_l <= 0.0) return transmitted;
    a.n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    vec3 h = normalize(l + v);
    a.n_dot_h = max(dot(n, h), 0.0);
    a.v_dot_h = max(dot(v, h), 0.0);
    float roughness = max(s.roughness, MIN_PUNCTUAL_ROUGHNESS);
    LobeChoice c = LobeChoice(roughness, k_direct(roughness), true, 0.0);
    return transmitted + base_lobes(s, surface_f0(s), n, v, l, a, c);
}

// f(l, v) L_in (n.l) for one light: the base with the layers over it (common/layers.glsl).
vec3 punctual_light(Surface s, vec3 n, vec3 v, vec3 l, vec3 radiance_in) {
    return layered_light(s, n, v, l, punctual_base(s, n, v, l), true, 0.0) * radiance_in;
}

// A spot's angular falloff (KHR_lights_punctual's recommended implementation): a linear ramp
// in cos(angle) from the outer to the inner cone, squared.
float spot_attenuation(vec3 spot_direction, vec3 l, vec2 scale_offset) {
    float t = clamp(dot(spot_direction, -l) * scale_offset.x + scale_offset.y, 0.0, 1.0);
    return t * t;
}

// The range window of KHR_lights_punctual (after Karis 2013): 1 near the light, 0 at range.
float range_attenuation(float distance_squared, float range) {
    if (range <= 0.0) return 1.0;
    float x = distance_squared / (range * range);
    float w = clamp(1.0 - x * x, 0.0, 1.0);
    return w * w;
}

vec3 punctual_lights(Surface s, vec3 n, vec3 v, vec3 position) {
    vec3 sum = vec3(0.0);
    for (int i = 0; i < min(u_light_count.x, MAX_LIGHTS); ++i) {
        vec4 vec = u_light_vector[i];
        vec3 l;
        vec3 radiance_in = u_light_radiance[i].rgb;
        if (int(vec.w) == LIGHT_DIRECTIONAL) {
            l = -normalize(vec.xyz);
        } else {
            vec3 to_light = vec.xyz - position;
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
#ifdef HAS_SHADOWS
        radiance_in *= light_shadow(i, int(vec.w), l, vec.xyz);   // (common/shadows.glsl)
#endif
        sum += punctual_light(s, n, v, l, radiance_in);
    }
    return sum;
}
