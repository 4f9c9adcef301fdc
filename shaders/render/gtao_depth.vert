#version 450 core
// GTAO's prepass (app/render/screen_ao.py): the opaque parts' world positions per pixel.
layout(location = 0) in vec3 in_position;

uniform mat4 u_view_projection;   // world -> clip (a tile's: the whole image's, off centre)

out vec3 v_world;

void main() {
    v_world = in_position;
    gl_Position = u_view_projection * vec4(in_position, 1.0);
}
