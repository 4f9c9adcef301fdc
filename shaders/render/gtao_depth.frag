#version 450 core
// GTAO's prepass: the world position in 32-bit floats (w = 1: covered). A 24-bit depth buffer,
// unprojected, put a flat floor's far pixels a little above their neighbours' plane (V down to
// 0.8 on an open floor).
in vec3 v_world;

layout(location = 0) out vec4 out_position;

void main() {
    out_position = vec4(v_world, 1.0);
}
