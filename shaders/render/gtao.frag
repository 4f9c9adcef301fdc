#version 450 core
// Screen-space ground-truth ambient occlusion (app/render/screen_ao.py): per pixel the
// cosine-weighted visibility from the opaque parts' depth (GTAO_SLICES slice directions, GTAO_STEPS
// depth samples a side, horizons within u_radius world units) and the occluded directions' sum, rotated by a 4x4 pattern that
// render/gtao_denoise.frag averages out. Jimenez et al. 2016, Algorithm 1, in world space.
#include "common/gtao.glsl"

uniform sampler2D u_depth;       // the depth prepass (window depth, 1 where no surface)
uniform mat4 u_inverse_vp;       // NDC -> world (a tile's: the whole image's, off centre)
uniform vec3 u_camera_position;
uniform mat4 u_view_projection;
uniform float u_radius;          // world units
uniform float u_pixel_scale;     // pixels per world unit at clip w = 1 (half the image's height times P[1][1])
uniform float u_max_radius_px;

layout(location = 0) out vec4 out_visibility;   // the occluded directions' cosine-weighted sum (world), V

vec3 world_at(vec2 pixel, float depth) {
    vec2 size = vec2(textureSize(u_depth, 0));
    vec4 ndc = vec4(pixel / size * 2.0 - 1.0, depth * 2.0 - 1.0, 1.0);
    vec4 w = u_inverse_vp * ndc;
    return w.xyz / w.w;
}

// The surface's position at a pixel centre; `depth` 1 is no surface.
vec3 position_at(ivec2 p, out float depth) {
    depth = texelFetch(u_depth, p, 0).r;
    return world_at(vec2(p) + 0.5, depth);
}

// The geometric normal from the depth buffer: of the two neighbours on each axis the one nearer
// in depth (across an edge the other belongs to another surface), facing the eye.
vec3 depth_normal(ivec2 p, vec3 centre, float depth, vec3 v) {
    ivec2 last = textureSize(u_depth, 0) - 1;
    float d;
    vec3 right = position_at(min(p + ivec2(1, 0), last), d);
    float dr = abs(d - depth);
    vec3 left = position_at(max(p - ivec2(1, 0), ivec2(0)), d);
    vec3 dx = abs(d - depth) < dr ? centre - left : right - centre;
    vec3 up = position_at(min(p + ivec2(0, 1), last), d);
    float du = abs(d - depth);
    vec3 down = position_at(max(p - ivec2(0, 1), ivec2(0)), d);
    vec3 dy = abs(d - depth) < du ? centre - down : up - centre;
    vec3 n = cross(dx, dy);
    n = dot(n, n) > 0.0 ? normalize(n) : v;
    return dot(n, v) < 0.0 ? -n : n;
}

// The 4x4 pattern's rotation (0..15)/16 and step offset, so that 16 neighbours hold 16 rotations.
vec2 pattern_noise(ivec2 p) {
    const float BAYER[16] = float[](0.0, 8.0, 2.0, 10.0, 12.0, 4.0, 14.0, 6.0,
                                    3.0, 11.0, 1.0, 9.0, 15.0, 7.0, 13.0, 5.0);
    int i = (p.x & 3) + 4 * (p.y & 3);
    return vec2(BAYER[i] / 16.0, fract(float(i) * 0.618034));
}

// The largest horizon cosine to v along one side of the slice; occluders fade out between 0.75
// and 1 times the radius, so that the search's end does not draw a line.
float horizon_cos(vec2 origin, vec2 step_px, vec3 centre, vec3 v, float jitter) {
    float best = -1.0;
    vec2 size = vec2(textureSize(u_depth, 0));
    for (int j = 0; j < GTAO_STEPS; ++j) {
        vec2 q = origin + step_px * (float(j) + jitter + 1.0);
        if (any(lessThan(q, vec2(0.0))) || any(greaterThanEqual(q, size))) break;
        float d;
        vec3 s = position_at(ivec2(q), d);
        if (d >= 1.0) continue;
        vec3 delta = s - centre;
        float dist = length(delta);
        if (dist < 1e-6) continue;
        float weight = clamp((u_radius - dist) / (0.25 * u_radius), 0.0, 1.0);
        best = max(best, mix(-1.0, dot(delta, v) / dist, weight));
    }
    return best;
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float depth;
    vec3 centre = position_at(p, depth);
    if (depth >= 1.0) {
        out_visibility = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec3 v = normalize(u_camera_position - centre);
    vec3 n = depth_normal(p, centre, depth, v);
    vec4 clip = u_view_projection * vec4(centre, 1.0);
    float radius_px = min(u_radius * u_pixel_scale / max(clip.w, 1e-6), u_max_radius_px);
    vec2 noise = pattern_noise(p);
    vec2 origin = vec2(p) + 0.5;
    float visibility = 0.0;
    vec3 occluded = vec3(0.0);
    for (int i = 0; i < GTAO_SLICES; ++i) {
        float phi = (float(i) + noise.x) * 3.14159265 / float(GTAO_SLICES);
        vec2 omega = vec2(cos(phi), sin(phi));
        // The slice's direction in the world: one pixel along omega at this depth, off v.
        vec3 direction = world_at(origin + omega, depth) - centre;
        direction -= dot(direction, v) * v;
        direction = normalize(direction);
        vec3 axis = normalize(cross(direction, v));
        vec3 projected = n - axis * dot(n, axis);
        float length_n = length(projected);
        float cos_n = clamp(dot(projected, v) / max(length_n, 1e-6), -1.0, 1.0);
        float gamma = sign(dot(projected, direction)) * acos(cos_n);
        vec2 step_px = omega * max(radius_px / float(GTAO_STEPS), 1.0);
        float c2 = horizon_cos(origin, step_px, centre, v, noise.y);
        float c1 = horizon_cos(origin, -step_px, centre, v, noise.y);
        visibility += gtao_slice_visibility(c1, c2, gamma, length_n);
        vec2 o = gtao_slice_occluded_direction(c1, c2, gamma, length_n);
        occluded += direction * o.x + v * o.y;
    }
    out_visibility = vec4(occluded / float(GTAO_SLICES), clamp(visibility / float(GTAO_SLICES), 0.0, 1.0));
}
