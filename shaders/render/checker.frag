#version 450 core
// The editor's view over a checkerboard where its background is transparent, as image editors
// show alpha; stretched over the window as render/upscale.frag does (bilinear). The view is
// already tone mapped and sRGB encoded, with straight alpha: mixed as encoded values, as a
// viewer composites a PNG. The PNG written keeps the real alpha (only the window shows this).
in vec2 v_ndc;

uniform sampler2D u_image;
uniform float u_square;         // the checker's square, window pixels
uniform vec2 u_origin;          // the view's corner in window pixels: the squares start there

layout(location = 0) out vec4 out_color;

// Two light greys, as GIMP and Photoshop draw transparency (sRGB-encoded values).
#define CHECKER_LIGHT 0.80
#define CHECKER_DARK 0.60

vec3 checker(vec2 pixel) {
    ivec2 cell = ivec2(floor((pixel - u_origin) / u_square));
    return vec3(((cell.x + cell.y) & 1) == 0 ? CHECKER_LIGHT : CHECKER_DARK);
}

void main() {
    vec4 view = texture(u_image, v_ndc * 0.5 + 0.5);
    out_color = vec4(mix(checker(gl_FragCoord.xy), view.rgb, view.a), 1.0);
}
