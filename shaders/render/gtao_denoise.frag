#version 450 core
// GTAO's spatial denoise (app/render/screen_ao.py): the mean over the 4x4 block that holds each
// of render/gtao.frag's 16 rotations once, of the pixels on the same surface (depth within a few
// per cent of this one's distance), so edges stay sharp (the paper's 4x4 bilateral filter).
uniform sampler2D u_raw;         // gtao.frag's visibility
uniform sampler2D u_depth;       // the depth prepass
uniform mat4 u_inverse_vp;

layout(location = 0) out vec4 out_visibility;   // as gtao.frag's

float eye_distance(ivec2 p) {
    vec2 size = vec2(textureSize(u_depth, 0));
    float depth = texelFetch(u_depth, p, 0).r;
    vec4 w = u_inverse_vp * vec4((vec2(p) + 0.5) / size * 2.0 - 1.0, depth * 2.0 - 1.0, 1.0);
    return w.w == 0.0 ? 0.0 : 1.0 / abs(w.w);   // clip w, the view depth (1 for orthographic views)
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 last = textureSize(u_raw, 0) - 1;
    if (texelFetch(u_depth, p, 0).r >= 1.0) {
        out_visibility = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    float here = eye_distance(p);
    vec4 sum = vec4(0.0);
    float weight = 0.0;
    for (int y = -1; y <= 2; ++y) {
        for (int x = -1; x <= 2; ++x) {
            ivec2 q = clamp(p + ivec2(x, y), ivec2(0), last);
            if (texelFetch(u_depth, q, 0).r >= 1.0) continue;
            float w = abs(eye_distance(q) - here) < 0.05 * here ? 1.0 : 0.0;
            sum += w * texelFetch(u_raw, q, 0);
            weight += w;
        }
    }
    out_visibility = weight > 0.0 ? sum / weight : texelFetch(u_raw, p, 0);
}
