#version 450 core
// GTAO's prepass: the world position in 32-bit floats (w = 1: covered). A 24-bit depth buffer,
// unprojected, put a flat floor's far pixels a little above their neighbours' plane (V down to
// 0.8 on an open floor). And the face's normal, facing the eye (the cross of the screen axes'
// derivatives, whatever the winding), which lights the occluders (render/gtao.frag,
// common/occlusion.glsl), and in w the part's size: how thick an occluder it drawn here may be.
in vec3 v_world;
uniform float u_part_size;   // the part's bounding-box diagonal (world): its occluders' thickness (render/gtao.frag)

layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;

void main() {
    out_position = vec4(v_world, 1.0);
    vec3 n = cross(dFdx(v_world), dFdy(v_world));
    out_normal = vec4(dot(n, n) > 0.0 ? normalize(n) : vec3(0.0), u_part_size);
}
