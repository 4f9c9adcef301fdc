#version 450 core
// render/vbuffer_shade.frag's one triangle, drawn with a viewport twice the image's width and
// height (app/render/vbuffer.py): its corners (-1, -1), (1, -1), (-1, 1) lie on the clip volume's
// edges, so nothing clips it, and it covers the image (the lower-left quarter of the viewport)
// whole. With render/fullscreen.vert's triangle, which reaches past the clip volume, the 2x2
// blocks along the image's diagonal came out wrong on llvmpipe (it is clipped into two there, and
// each half ran the blocks with their other pixels masked), which the shading pass's exchanges
// between a block's pixels cannot have.
void main() {
    gl_Position = vec4(float((gl_VertexID & 1) << 1) - 1.0, float(gl_VertexID & 2) - 1.0, 1.0, 1.0);
}
