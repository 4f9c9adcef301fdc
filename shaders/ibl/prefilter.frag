#version 450 core
// The prefilter as a fragment shader, for benchmarks/bench_compute_vs_fragment.py: the six faces
// of one step stacked in a (size x 6 size) 2D target, face f in rows [f size, (f+1) size).
#include "common/brdf.glsl"
#include "common/cubemap.glsl"
#include "common/prefilter.glsl"

uniform int u_size;
layout(location = 0) out vec4 out_radiance;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec3 texel = ivec3(p.x, p.y % u_size, p.y / u_size);
    out_radiance = vec4(prefilter_radiance(cube_texel_direction(texel, u_size)), 1.0);
}
