// docs/conventions.md's ground truth for image-based lighting as a finite sum over the texels of an
// equirect map (numpy twin: app/accuracy/ground_truth.py):
//     L_o(n, v) = emissive + sum_t f(l_t, v) L(l_t) max(n.l_t, 0) dOmega_t
// with k = r^2/2 (the IBL k) and F (so kd) per direction at v.h. Nothing is sampled. A
// material's layers (docs/layers.md) enter through the same functions as in shading, with
// docs/conventions.md's exact choices (punctual = false, spread 0; common/layers.glsl).
#include "common/shading.glsl"

// f(l, v) max(n.l, 0) of docs/conventions.md: common/base_lobes.glsl with the exact choices. n_dot_v is already
// clamped to MIN_N_DOT_V (as app/accuracy/ground_truth.py does); h is the geometric half vector, with
// |l + v| floored at 1e-7 (l = -v).
vec3 brdf_ground_truth(Surface s, vec3 f0, vec3 n, vec3 v, float n_dot_v, vec3 l) {
#ifdef HAS_TRANSMISSION
    vec3 f = transmission_light(s, n, v, l, false, 0.0);
#else
    vec3 f = vec3(0.0);
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
    f += diffuse_transmission_light(s, n, v, l);
#endif
    LobeAngles a;
    a.n_dot_l = dot(n, l);
    if (a.n_dot_l > 0.0) {
        vec3 lv = l + v;
        vec3 h = lv / max(length(lv), 1e-7);
        a.n_dot_v = n_dot_v;
        a.n_dot_h = dot(n, h);
        a.v_dot_h = clamp(dot(v, h), 0.0, 1.0);
        LobeChoice c = LobeChoice(s.roughness, k_ibl(s.roughness), false, 0.0);
        f += base_lobes(s, f0, n, v, l, a, c);
    }
    return layered_light(s, n, v, l, f, false, 0.0);
}

// (sin phi, cos phi) of each column's centre, phi = (u - 0.5) 2 pi, filled by app/accuracy/reference.py
// in float64 (a table: no trig in the inner loop).
layout(std430, binding = 2) readonly buffer EquirectColumns {
    vec2 u_column_sin_cos[];
};

// The texel sum over rows [row_begin, row_end) of level `level` of an equirect texture
// (W x H at that level). n and v are in the map's frame (rotate them with rotate_world_to_map
// first). Texel (col, row) looks along its centre's direction (docs/conventions.md's mapping) and
// covers dOmega = (2 pi/W)(pi/H) sin(theta). Each row is summed on its own and then added to
// the total, so float32 rounding grows with W + H rather than W * H.
vec3 ground_truth_rows(sampler2D env, int level, int row_begin, int row_end, Surface s, vec3 n, vec3 v) {
    ivec2 size = textureSize(env, level);
    vec3 f0 = surface_f0(s);
    float n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    float d_phi = 2.0 * PI / float(size.x);
    float d_theta = PI / float(size.y);
    vec3 total = vec3(0.0);
    for (int row = row_begin; row < row_end; ++row) {
        float theta = (float(row) + 0.5) * d_theta;
        float sin_t = sin(theta);
        float cos_t = cos(theta);
        vec3 row_sum = vec3(0.0);
        for (int col = 0; col < size.x; ++col) {
            vec2 sc = u_column_sin_cos[col];
            vec3 l = vec3(sin_t * sc.x, cos_t, -sin_t * sc.y);
            row_sum += brdf_ground_truth(s, f0, n, v, n_dot_v, l) * texelFetch(env, ivec2(col, row), level).rgb;
        }
        total += row_sum * (d_phi * d_theta * sin_t);
    }
    return total;
}
