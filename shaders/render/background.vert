#version 450 core
// render/fullscreen.vert's triangle (on the far plane: depth 1, so with depth test '<=' the
// background fills only pixels no surface covered), plus the world-space view ray. The far
// plane maps affinely to NDC, so the ray interpolates exactly; the fragment only normalises it.
// BACKGROUND_RING: instead, triangles in NDC (in_ndc) that cover the viewport but a hole the
// sphere's impostor then fills (app/core/sphere_lod.py impostor_background_ring), so neither
// pass needs a depth buffer.
uniform mat4 u_inverse_view_projection;

#ifdef BACKGROUND_RING
in vec2 in_ndc;
#endif

out vec3 v_ray;

void main() {
#ifdef BACKGROUND_RING
    vec2 p = in_ndc;
#else
    vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
#endif
    vec4 near = u_inverse_view_projection * vec4(p, -1.0, 1.0);
    vec4 far = u_inverse_view_projection * vec4(p, 1.0, 1.0);
    v_ray = far.xyz / far.w - near.xyz / near.w;
    gl_Position = vec4(p, 1.0, 1.0);
}
