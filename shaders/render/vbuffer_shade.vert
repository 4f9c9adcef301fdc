#version 450 core
// render/vbuffer_shade.frag's one triangle, drawn with a viewport twice the image's width and
// height (app/render/vbuffer.py): its corners (-1, -1), (1, -1), (-1, 1) lie on the clip volume's
// edges, so nothing clips it, and it covers the image (the lower-left quarter of the viewport)
// whole. A triangle reaching past the clip volume, as render/fullscreen.vert's, is cut at the
// viewport by llvmpipe into two, and the 2x2 blocks along their shared diagonal run once per
// half with their other pixels masked, which the shading pass's exchanges between a block's
// pixels cannot have.
void main() {
    gl_Position = vec4(float((gl_VertexID & 1) << 1) - 1.0, float(gl_VertexID & 2) - 1.0, 1.0, 1.0);
}
