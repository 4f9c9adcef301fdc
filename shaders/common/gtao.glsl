// Ground-truth ambient occlusion's terms (Jimenez, Wu, Pesce and Jarabo 2016, "Practical
// Realtime Strategies for Accurate Indirect Occlusion"); numpy twins in app/core/gtao.py.

// The cosine-weighted visibility up to horizon angle h (from v, in the slice; negative on the
// slice's other side) for the projected normal at angle gamma: the paper's closed-form inner
// integral, int_0^h cos(theta - gamma) |sin theta| dtheta.
float gtao_inner_integral(float h, float gamma) {
    return 0.25 * (-cos(2.0 * h - gamma) + cos(gamma) + 2.0 * h * sin(gamma));
}

// One slice: the horizons (their cosines to v, h1 on the -phi side) clamped to the projected
// normal's hemisphere, weighted by the projected normal's length (paper, Algorithm 1).
float gtao_slice_visibility(float cos_h1, float cos_h2, float gamma, float projected_length) {
    const float HALF_PI = 1.5707963;
    float h1 = -acos(clamp(cos_h1, -1.0, 1.0));
    float h2 = acos(clamp(cos_h2, -1.0, 1.0));
    h1 = gamma + max(h1 - gamma, -HALF_PI);
    h2 = gamma + min(h2 - gamma, HALF_PI);
    return projected_length * (gtao_inner_integral(h1, gamma) + gtao_inner_integral(h2, gamma));
}

// The paper's fit of the interreflections between occluders of this albedo (its section 5):
// the visibility the light that bounces sees, never below V itself.
vec3 gtao_multi_bounce(float visibility, vec3 albedo) {
    vec3 a = 2.0404 * albedo - 0.3324;
    vec3 b = -4.7951 * albedo + 0.6417;
    vec3 c = 2.7552 * albedo + 0.6903;
    return max(vec3(visibility), ((visibility * a + b) * visibility + c) * visibility);
}

// int_0^theta (sin t, cos t) cos(t - gamma) |sin t| dt: the (slice direction, v) parts of the
// cosine-weighted directions from v up to the signed angle theta.
vec2 gtao_direction_antiderivative(float theta, float gamma) {
    float s = sin(theta), c = cos(theta);
    vec2 at_theta = vec2(cos(gamma) * s * s * s / 3.0 + sin(gamma) * (c * c * c / 3.0 - c),
                         -cos(gamma) * c * c * c / 3.0 + sin(gamma) * s * s * s / 3.0);
    vec2 at_zero = vec2(sin(gamma) * (1.0 / 3.0 - 1.0), -cos(gamma) / 3.0);
    return sign(theta) * (at_theta - at_zero);
}

// One slice's cosine-weighted sum of occluded directions, (along the slice direction, along v)
// times |n_p|: the normal's half-disc beyond the horizons. Summed over slices it points at the
// occluders, whose surfaces face back along it (occlude_environment reads E there, as the bake
// reads it along its bounce rays).
vec2 gtao_slice_occluded_direction(float cos_h1, float cos_h2, float gamma, float projected_length) {
    const float HALF_PI = 1.5707963;
    float h1 = -acos(clamp(cos_h1, -1.0, 1.0));
    float h2 = acos(clamp(cos_h2, -1.0, 1.0));
    h1 = gamma + max(h1 - gamma, -HALF_PI);
    h2 = gamma + min(h2 - gamma, HALF_PI);
    vec2 lo = gtao_direction_antiderivative(gamma - HALF_PI, gamma);
    vec2 hi = gtao_direction_antiderivative(gamma + HALF_PI, gamma);
    return projected_length * ((gtao_direction_antiderivative(h1, gamma) - lo)
                               + (hi - gtao_direction_antiderivative(h2, gamma)));
}

// The cosine-weighted share (times |n_p|) of the band of one slice's side between two horizon
// cosines to v, the lower one first (side +1: the +phi side, h = acos; -1: h = -acos), both
// clamped to the projected normal's hemisphere: the directions that see the sample that raised
// the horizon from the first to the second (render/gtao.frag: the occluders' light). Over a side
// the bands sum to what gtao_slice_visibility leaves out there.
float gtao_band_weight(float cos_from, float cos_to, float gamma, float side, float projected_length) {
    const float HALF_PI = 1.5707963;
    float a = side * acos(clamp(cos_from, -1.0, 1.0));
    float b = side * acos(clamp(cos_to, -1.0, 1.0));
    float limit = gamma + side * HALF_PI;
    a = side > 0.0 ? min(a, limit) : max(a, limit);
    b = side > 0.0 ? min(b, limit) : max(b, limit);
    return projected_length * (gtao_inner_integral(a, gamma) - gtao_inner_integral(b, gamma));
}

// The light / pi on the occluders that face the point (common/occlusion.glsl screen_facing_light,
// which says why): their own (by_occluders) where their V is above the point's, held to the
// point's (as_point) where below, smoothly over `ramp` (low, high) of their V less the point's.
vec3 gtao_facing_light(vec3 by_occluders, vec3 as_point, float occluder_visibility, float visibility, vec2 ramp) {
    return mix(min(by_occluders, as_point), by_occluders, smoothstep(ramp.x, ramp.y, occluder_visibility - visibility));
}

// How much an occluder at `delta` from the point (world) counts, 0..1: 1 within 0.75 `radius`,
// fading to 0 at `radius` (so that the search's end draws no line), the distance measured with
// the part along v (toward the eye) that exceeds `thickness` stretched by `thin`: an occluder far
// in front of the point in view depth is taken as a thin object with empty space behind it (a
// sphere in front of another across a gap), not as the top of a solid height field that claims
// every direction below it (XeGTAO's "thin occluder compensation" of Jimenez et al. 2016's
// falloff, applied only in front, where the height field's assumption reaches; app/core/gtao.py
// falloff_weight).
float gtao_falloff_weight(vec3 delta, vec3 v, float radius, float thickness, float thin) {
    float along = dot(delta, v);
    float across = length(delta - along * v);
    along += thin * max(along - thickness, 0.0);
    return clamp((radius - length(vec2(across, along))) / (0.25 * radius), 0.0, 1.0);
}
