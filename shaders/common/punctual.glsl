// Point and directional lights through the reflectance equation (a delta light: no integral).

const int LIGHT_POINT = 0;
const int LIGHT_DIRECTIONAL = 1;
const int MAX_LIGHTS = 16;

// xyz: position (point) or direction the light travels (directional); w: LIGHT_* type.
// rgb of u_light_radiance: colour times intensity (W/sr-like for points, irradiance for suns).
layout(std140, binding = 0) uniform Lights {
    vec4 u_light_vector[MAX_LIGHTS];
    vec4 u_light_radiance[MAX_LIGHTS];
    ivec4 u_light_count;
};

// The base's f(l, v) (n.l) for one light, with the lecture's punctual k = (r+1)^2/8; with
// HAS_TRANSMISSION also the transmitted part, for light from either side (common/layers.glsl).
vec3 punctual_base(Surface s, vec3 n, vec3 v, vec3 l) {
#ifdef HAS_TRANSMISSION
    vec3 transmitted = transmission_light(s, n, v, l, true, 0.0);
#else
    vec3 transmitted = vec3(0.0);
#endif
    float n_dot_l = dot(n, l);
    if (n_dot_l <= 0.0) return transmitted;
    float n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    vec3 h = normalize(l + v);
    float n_dot_h = max(dot(n, h), 0.0);
    float v_dot_h = max(dot(v, h), 0.0);
    float roughness = max(s.roughness, MIN_PUNCTUAL_ROUGHNESS);
    vec3 F = F_Schlick(v_dot_h, surface_f0(s));
    vec3 kd = (1.0 - F) * (1.0 - s.metallic);
#ifdef HAS_TRANSMISSION
    kd *= 1.0 - s.transmission;
#endif
#ifdef HAS_ANISOTROPY
    vec3 specular = anisotropic_specular(s, n, v, l, F, true, 0.0);
#else
    float D = D_GGX(n_dot_h, roughness);
    float G = G_Smith(n_dot_v, n_dot_l, k_direct(roughness));
    vec3 specular = D * G * F / (4.0 * n_dot_l * n_dot_v);
#endif
    return transmitted + (kd * Fd_Lambert(s.base_color) + specular) * n_dot_l;
}

// f(l, v) L_in (n.l) for one light: the base with the layers over it (common/layers.glsl).
vec3 punctual_light(Surface s, vec3 n, vec3 v, vec3 l, vec3 radiance_in) {
    return layered_light(s, n, v, l, punctual_base(s, n, v, l), true, 0.0) * radiance_in;
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
        }
        sum += punctual_light(s, n, v, l, radiance_in);
    }
    return sum;
}
