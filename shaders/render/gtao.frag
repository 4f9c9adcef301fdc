#version 450 core
// Screen-space ground-truth ambient occlusion (app/render/screen_ao.py): per pixel the
// cosine-weighted visibility and the occluded directions' sum from the opaque parts' positions
// (GTAO_SLICES slice directions, GTAO_STEPS samples a side, horizons within u_radius world
// units), the slices turned by a 4x4 pattern that render/gtao_denoise.frag averages out, and
// the whole pattern by u_rotation_offset from pass to pass (alight.core.gtao.rotation_offset).
// Jimenez et al. 2016, Algorithm 1, in world space.
#include "common/gtao.glsl"

uniform sampler2D u_positions;   // the prepass's world positions (w = 1 where a surface is)
uniform sampler2D u_normals;     // the prepass's face normals (either side); w: their part's size
uniform sampler2D u_history;     // the earlier passes' mean (render/gtao_denoise.frag): V at the occluders
uniform bool u_has_history;      // false in a view's first pass
uniform mat4 u_inverse_vp;       // NDC -> world (a tile's: the whole image's, off centre)
uniform vec3 u_camera_position;
uniform mat4 u_view_projection;
uniform float u_radius;          // world units
uniform float u_pixel_scale;     // pixels per world unit at clip w = 1 (half the image's height times P[1][1])
uniform float u_max_radius_px;
uniform vec2 u_rotation_offset;  // this pass's turn of the pattern: slice angle (x pi / GTAO_SLICES), step jitter

layout(location = 0) out vec4 out_visibility;   // the occluded directions' cosine-weighted sum (world), V
layout(location = 1) out vec4 out_occluders;    // the facing occluders' V times normal (world), their share: horizon_cos

vec3 world_at(vec2 pixel, float ndc_depth) {
    vec2 size = vec2(textureSize(u_positions, 0));
    vec4 w = u_inverse_vp * vec4(pixel / size * 2.0 - 1.0, ndc_depth, 1.0);
    return w.xyz / w.w;
}

// The surface's position at a pixel; `covered` false where there is none.
vec3 position_at(ivec2 p, out bool covered) {
    vec4 x = texelFetch(u_positions, p, 0);
    covered = x.w > 0.5;
    return x.xyz;
}

// The geometric normal from the positions: of the two neighbours on each axis the one nearer to
// this pixel (across an edge the other belongs to another surface), facing the eye.
vec3 screen_normal(ivec2 p, vec3 centre, vec3 v) {
    ivec2 last = textureSize(u_positions, 0) - 1;
    bool c1, c2;
    vec3 right = position_at(min(p + ivec2(1, 0), last), c1);
    vec3 left = position_at(max(p - ivec2(1, 0), ivec2(0)), c2);
    // (at the image's border the clamped neighbour is this pixel: not a neighbour)
    float dr = c1 && p.x < last.x ? distance(right, centre) : 1e30;
    float dl = c2 && p.x > 0 ? distance(left, centre) : 1e30;
    vec3 dx = dl < dr ? centre - left : right - centre;
    vec3 up = position_at(min(p + ivec2(0, 1), last), c1);
    vec3 down = position_at(max(p - ivec2(0, 1), ivec2(0)), c2);
    float du = c1 && p.y < last.y ? distance(up, centre) : 1e30;
    float dd = c2 && p.y > 0 ? distance(down, centre) : 1e30;
    vec3 dy = dd < du ? centre - down : up - centre;
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

// The offset in pixels of sample j (of GTAO_STEPS, jittered) along a slice: quadratic in j, so
// that the samples crowd near the pixel, where a groove's or a contact's occluder is, and still
// reach the far ones (XeGTAO's sample distribution, power 2, of Jimenez et al. 2016's method).
float sample_offset_px(int j, float jitter, float radius_px) {
    float s = (float(j) + jitter + 1.0) / float(GTAO_STEPS);
    return max(radius_px * s * s, 1.0);
}

// The occluder at pixel p (position s) as the point at `centre` sees it: its V times its normal
// (V and bent normal, app/core/gtao.py bent_normal, from the view's earlier passes: the bake
// lights its hits by their bent normals), or 0 where its face is turned away (the point then
// sees a face behind it that the screen does not hold: a bowl's near wall seen from its floor
// over the rim; common/occlusion.glsl lights that share as before). In a view's first pass V is
// 1 and the normal the face's: main then takes this point's V for it, the paper's assumption
// that the occluders see as the point does.
vec3 facing_occluder(ivec2 p, vec3 s, vec3 centre) {
    vec3 n = texelFetch(u_normals, p, 0).xyz;
    if (dot(n, centre - s) <= 0.0) return vec3(0.0);
    if (!u_has_history) return n;
    vec4 earlier = texelFetch(u_history, p, 0);
    vec3 b = (2.0 / 3.0) * n - earlier.xyz;
    return max(earlier.w, 1e-3) * (dot(b, n) > 1e-6 ? normalize(b) : n);   // (0 would read as turned away)
}

// The largest horizon cosine to v along one side of the slice (screen direction omega, side +1
// or -1 for gtao_band_weight); the occluders fade out between 0.75 and 1 times `radius` (world
// units), so that the search's end does not draw a line, and those more than GTAO_THICKNESS times
// their part's size in front of the point sooner (common/gtao.glsl gtao_falloff_weight: a sphere of
// a grid in front of another across a gap is thin, not a height field's top; one mesh's walls,
// with no part of their own, still are). Each sample that raises the horizon and
// faces the point adds (its V times its normal, 1) to `occluders`, weighted by the band of
// directions it raised the horizon over (those that, on a height field, see it): the near
// occluders count as much as the point sees of them, not only the farthest that sets the horizon.
float horizon_cos(vec2 origin, vec2 omega, float radius_px, vec3 centre, vec3 v, float jitter, float radius,
                  float gamma, float side, float projected_length, inout vec4 occluders) {
    float best = -1.0;
    vec2 size = vec2(textureSize(u_positions, 0));
    for (int j = 0; j < GTAO_STEPS; ++j) {
        vec2 q = origin + omega * sample_offset_px(j, jitter, radius_px);
        if (any(lessThan(q, vec2(0.0))) || any(greaterThanEqual(q, size))) break;
        // Bilinear between the 4 texels about q: on a plane the point at q itself, so it lies in
        // the slice (the nearest texel's centre, up to half a pixel off it, rose above an open
        // floor's tangent in some slices: V 0.9 there). Where a texel is uncovered, the nearest.
        vec4 at = textureLod(u_positions, q / size, 0.0);
        if (at.w < 0.999) at = texelFetch(u_positions, ivec2(q), 0);
        if (at.w < 0.5) continue;
        vec3 s = at.xyz;
        vec3 delta = s - centre;
        float dist = length(delta);
        if (dist < 1e-6) continue;
        float thickness = GTAO_THICKNESS * texelFetch(u_normals, ivec2(q), 0).w;   // (its part's size)
        float weight = gtao_falloff_weight(delta, v, radius, thickness, GTAO_THIN_OCCLUDER);
        float c = mix(-1.0, dot(delta, v) / dist, weight);
        if (c > best) {
            // The facing occluder's own light reaches only the band from its front down to
            // GTAO_FACING_THICKNESS of its part's size behind it (along the view ray): below that
            // the screen does not say what the point sees (the corner's wall above the box sees
            // the box's dim back face and the gap's floor, not its sunlit top), lit as the point.
            vec3 back = s + normalize(s - u_camera_position) * (GTAO_FACING_THICKNESS / GTAO_THICKNESS) * thickness;
            vec3 to_back = back - centre;
            float c_back = mix(-1.0, dot(to_back, v) / max(length(to_back), 1e-6), weight);
            float w = gtao_band_weight(max(best, min(c_back, c)), c, gamma, side, projected_length);
            if (w > 0.0) {
                ivec2 p = ivec2(q);
                vec3 facing = facing_occluder(p, s, centre);
                if (dot(facing, facing) > 0.0) occluders += w * vec4(facing, 1.0);
            }
            best = c;
        }
    }
    return best;
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    bool covered;
    vec3 centre = position_at(p, covered);
    if (!covered) {
        out_visibility = vec4(0.0, 0.0, 0.0, 1.0);
        out_occluders = vec4(0.0);
        return;
    }
    vec3 v = normalize(u_camera_position - centre);
    vec3 n = screen_normal(p, centre, v);
    vec4 clip = u_view_projection * vec4(centre, 1.0);
    float ndc_depth = clip.z / clip.w;
    float radius_px = min(u_radius * u_pixel_scale / max(clip.w, 1e-6), u_max_radius_px);
    // The world radius the pixels reach: the fade-out follows it, so that where the pixel cap
    // cuts the search short the occluders fade rather than stop (a hard vertical band on the
    // corner's back wall in the editor at 1280x720).
    float radius = radius_px * max(clip.w, 1e-6) / u_pixel_scale;
    vec2 noise = pattern_noise(p);
    noise = vec2(noise.x + u_rotation_offset.x, fract(noise.y + u_rotation_offset.y));
    vec2 origin = vec2(p) + 0.5;
    float visibility = 0.0;
    vec3 occluded = vec3(0.0);
    vec4 occluders = vec4(0.0);    // (horizon_cos)
    for (int i = 0; i < GTAO_SLICES; ++i) {
        float phi = (float(i) + noise.x) * 3.14159265 / float(GTAO_SLICES);
        vec2 omega = vec2(cos(phi), sin(phi));
        // The slice's direction in the world: one pixel along omega at this depth, off v.
        vec3 direction = world_at(origin + omega, ndc_depth) - centre;
        direction -= dot(direction, v) * v;
        direction = normalize(direction);
        vec3 axis = normalize(cross(direction, v));
        vec3 projected = n - axis * dot(n, axis);
        float length_n = length(projected);
        float cos_n = clamp(dot(projected, v) / max(length_n, 1e-6), -1.0, 1.0);
        float gamma = sign(dot(projected, direction)) * acos(cos_n);
        float c2 = horizon_cos(origin, omega, radius_px, centre, v, noise.y, radius, gamma, 1.0, length_n, occluders);
        float c1 = horizon_cos(origin, -omega, radius_px, centre, v, noise.y, radius, gamma, -1.0, length_n, occluders);
        visibility += gtao_slice_visibility(c1, c2, gamma, length_n);
        vec2 o = gtao_slice_occluded_direction(c1, c2, gamma, length_n);
        occluded += direction * o.x + v * o.y;
    }
    // (a view's first pass: the occluders see as this point does, the paper's assumption)
    if (!u_has_history) occluders.xyz *= visibility / float(GTAO_SLICES);
    // Not clamped here: the mean of 2 slices is 1 over an open pixel only on average (1.07 for
    // a normal 69 degrees from v), and render/gtao_denoise.frag's mean over 16 rotations is the
    // estimate (clamped per pixel first, an open floor seen at a slant came out 0.96).
    out_visibility = vec4(occluded, visibility) / float(GTAO_SLICES);
    out_occluders = occluders / float(GTAO_SLICES);
}
