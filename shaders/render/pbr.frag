#version 450 core
// Forward PBR pass: a mesh with the metal-roughness material (factors times glTF textures).
#include "common/shading.glsl"
#include "common/mesh_material.glsl"
#include "common/debug_views.glsl"
#include "common/output_encoding.glsl"

layout(location = 0) out vec4 out_radiance;

void main() {
    vec3 n = shading_normal();
    vec3 v = normalize(u_camera_position - v_position);
#ifdef DEBUG_VIEW
    out_radiance = encode_output(debug_view(material_surface(n), n, v, v_position), 1.0);
#else
    out_radiance = encode_output(shade(material_surface(n), n, v, v_position), 1.0);
#endif
}
