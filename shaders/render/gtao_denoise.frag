#version 450 core
// GTAO's spatial denoise (app/render/screen_ao.py): the mean over the 4x4 block that holds each
// of render/gtao.frag's 16 rotations once, of the pixels on the same surface (distance to the eye
// within 5% of this one's), so edges stay sharp (the paper's 4x4 bilateral filter); then the
// running mean with the earlier passes of the same view (u_history, weight n / (n + 1) after n),
// the paper's temporal accumulation for a view that does not move.
uniform sampler2D u_raw;         // gtao.frag's visibility
uniform sampler2D u_raw_occluders;       // ... and its occluders' normals (out_occluders)
uniform sampler2D u_history;     // the mean of the earlier passes (any texture when the weight is 0)
uniform sampler2D u_history_occluders;
uniform float u_history_weight;
uniform sampler2D u_positions;   // the prepass's world positions (w = 1 where a surface is)
uniform vec3 u_camera_position;

layout(location = 0) out vec4 out_visibility;   // as gtao.frag's
layout(location = 1) out vec4 out_occluders;    // as gtao.frag's, through the same weights

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 last = textureSize(u_raw, 0) - 1;
    if (texelFetch(u_positions, p, 0).w < 0.5) {
        out_visibility = vec4(0.0, 0.0, 0.0, 1.0);
        out_occluders = vec4(0.0);
        return;
    }
    float here = distance(texelFetch(u_positions, p, 0).xyz, u_camera_position);
    vec4 sum = vec4(0.0);
    vec4 sum_occluders = vec4(0.0);
    float weight = 0.0;
    for (int y = -1; y <= 2; ++y) {
        for (int x = -1; x <= 2; ++x) {
            ivec2 q = clamp(p + ivec2(x, y), ivec2(0), last);
            vec4 at = texelFetch(u_positions, q, 0);
            if (at.w < 0.5) continue;
            float w = abs(distance(at.xyz, u_camera_position) - here) < 0.05 * here ? 1.0 : 0.0;
            sum += w * texelFetch(u_raw, q, 0);
            sum_occluders += w * texelFetch(u_raw_occluders, q, 0);
            weight += w;
        }
    }
    out_visibility = weight > 0.0 ? sum / weight : texelFetch(u_raw, p, 0);
    out_visibility.w = clamp(out_visibility.w, 0.0, 1.0);
    out_occluders = weight > 0.0 ? sum_occluders / weight : texelFetch(u_raw_occluders, p, 0);
    if (u_history_weight > 0.0) {
        out_visibility = mix(out_visibility, texelFetch(u_history, p, 0), u_history_weight);
        out_occluders = mix(out_occluders, texelFetch(u_history_occluders, p, 0), u_history_weight);
    }
}
