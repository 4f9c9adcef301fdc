#version 450 core
// One direction of the per-vertex occlusion bake (app/render/occlusion.py): each vertex is tested
// against the orthographic depth map seen from u_toward, and its cosine weight added to
// (weight, visible weight). The numpy twin is app/core/occlusion_bake.py's visible_from and
// accumulate (tests/test_occlusion_bake.py compares them).
layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Positions { float positions[]; };   // xyz per vertex
layout(std430, binding = 1) readonly buffer Normals { float normals[]; };       // xyz per vertex
layout(std430, binding = 2) buffer Sums { vec2 sums[]; };

uniform sampler2D u_depth;     // window depth in [0, 1], no comparison
uniform mat4 u_matrix;         // the view's world -> clip (app/core/shadow_fit.py)
uniform vec3 u_toward;         // unit, from the mesh toward the viewer of the map
uniform float u_texel;         // world size of a texel
uniform float u_depth_range;   // far - near
uniform int u_count;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_count) return;
    vec3 p = vec3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
    vec3 n = vec3(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
    float n_dot_d = dot(n, u_toward);
    vec3 q = p + n * (1.5 * u_texel) * sign(n_dot_d);
    vec4 clip = u_matrix * vec4(q, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    int res = textureSize(u_depth, 0).x;
    ivec2 ij = clamp(ivec2((ndc.xy * 0.5 + 0.5) * float(res)), ivec2(0), ivec2(res - 1));
    float stored = texelFetch(u_depth, ij, 0).r;
    float c = clamp(abs(n_dot_d), 1e-3, 1.0);
    float tan_theta = min(sqrt(1.0 - c * c) / c, 8.0);
    float bias = u_texel * (1.0 + 2.0 * tan_theta) / u_depth_range;
    bool visible = ndc.z * 0.5 + 0.5 <= stored + bias;
    float w = max(n_dot_d, 0.0);
    sums[i] += vec2(w, visible ? w : 0.0);
}
