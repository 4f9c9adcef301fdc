#version 450 core
// The reference's G-buffer (app/accuracy/reference.py): what the texel sum needs at each pixel, from the
// same material inputs as the forward pass (common/mesh_material.glsl), unshaded. Alpha of
// target 0 is 1 where the mesh covers the pixel (cleared to 0 elsewhere).
#include "common/mesh_material.glsl"

layout(location = 0) out vec4 out_position;     // world position, 1
layout(location = 1) out vec4 out_normal;       // shading normal n, roughness
layout(location = 2) out vec4 out_view;         // v (surface -> eye), metallic
layout(location = 3) out vec4 out_base_color;   // base colour, 1
layout(location = 4) out vec4 out_specular_f0;  // specular F0 of the dielectric part, its F90
layout(location = 5) out vec4 out_emissive;     // emissive, 1
layout(location = 6) out vec4 out_tangent;      // the tangent frame's t, its handedness (the layers')

void main() {
    vec3 n = shading_normal();
    Surface s = material_surface(n);
    out_position = vec4(surface_position(), 1.0);
    out_normal = vec4(n, s.roughness);
    out_view = vec4(normalize(u_camera_position - surface_position()), s.metallic);
    out_base_color = vec4(s.base_color, 1.0);
    out_specular_f0 = vec4(s.specular_f0, s.specular_f90);
    out_emissive = vec4(s.emissive, 1.0);
    out_tangent = vec4(tangent_frame(n)[0], v_tangent.w < 0.0 ? -1.0 : 1.0);
#ifdef HAS_ANISOTROPY
    // KHR_materials_anisotropy: the direction before the material's rotation (the reference
    // rotates it), its length the factor on the strength: the map's B, 0 on a part without the
    // layer (accuracy/reference.comp).
    float factor = s.anisotropy_strength > 0.0 ? 1.0 : 0.0;
    if (has_map(MAP_ANISOTROPY, u_has_anisotropy_map)) {
        vec3 texel = sample_map(u_anisotropy_map, MAP_ANISOTROPY, 12).rgb;
        mat3 frame = tangent_frame(n);
        vec3 direction = frame * vec3(texel.rg * 2.0 - 1.0, 0.0);
        if (dot(direction, direction) > 1e-12) out_tangent.xyz = normalize(direction);
        factor *= texel.b;
    }
    out_tangent.xyz *= factor;
#else
    // A part drawn without the layer: length 0, so the reference (which applies a scene's one set
    // of layer factors at every pixel) leaves it isotropic; no other layer reads the tangent.
    out_tangent.xyz = vec3(0.0);
#endif
}
