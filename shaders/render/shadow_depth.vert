#version 450 core
// A shadow map's depth pass (app/render/shadows.py): positions only, seen from the light.
layout(location = 0) in vec3 in_position;

uniform mat4 u_view_projection;   // the shadow view's world -> clip (app/core/shadow_fit.py)

void main() {
    gl_Position = u_view_projection * vec4(in_position, 1.0);
}
