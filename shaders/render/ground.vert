#version 450 core
// The ground under the model (app/render/ground.py): a square on y = u_ground.y, drawn as a
// shadow catcher over what is behind it.
layout(location = 0) in vec2 in_corner;     // (-1..1, -1..1)

uniform vec4 u_ground;                      // centre x, y (the plane's height), centre z, half size
uniform mat4 u_view_projection;

out vec3 v_position;

void main() {
    v_position = vec3(u_ground.x + in_corner.x * u_ground.w, u_ground.y, u_ground.z + in_corner.y * u_ground.w);
    gl_Position = u_view_projection * vec4(v_position, 1.0);
}
