#version 450 core
// The editor's reduced-resolution view (while the camera moves) stretched over the window,
// bilinear. Its input is already tone mapped and sRGB encoded: no colour maths here.
in vec2 v_ndc;

uniform sampler2D u_image;

layout(location = 0) out vec4 out_color;

void main() {
    out_color = vec4(texture(u_image, v_ndc * 0.5 + 0.5).rgb, 1.0);
}
