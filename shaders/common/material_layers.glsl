// The layers' material inputs (docs/layers.md): the factors as uniforms
// (app/render/bindings.py: set_material), each under its layer's HAS_* define, and
// apply_material_layers, which writes them into a Surface. Shared by the forward pass
// (common/mesh_material.glsl, render/probe.frag) and the reference (accuracy/reference.comp).

#ifdef HAS_CLEARCOAT
uniform float u_clearcoat;
uniform float u_clearcoat_roughness;
#endif
#ifdef HAS_SHEEN
uniform vec3 u_sheen_color;
uniform float u_sheen_roughness;
#endif
#ifdef HAS_ANISOTROPY
uniform float u_anisotropy_strength;
uniform float u_anisotropy_rotation;   // radians, counter-clockwise from the tangent
#endif
#ifdef HAS_TRANSMISSION
uniform float u_transmission;
uniform float u_ior;
#endif
#ifdef HAS_VOLUME
uniform float u_thickness;
uniform vec3 u_attenuation_color;
uniform float u_attenuation_distance;  // 3e38 stands for glTF's +inf (no attenuation)
#endif
#ifdef HAS_DISPERSION
uniform float u_dispersion;
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
uniform float u_diffuse_transmission;
uniform vec3 u_diffuse_transmission_color;
#endif

#include "common/material_iridescence.glsl"

// The layer factors at a point with shading normal n and tangent frame (t, b) (orthonormal,
// b = cross(n, t) up to the mesh's handedness). Maps, where a layer has them, multiply these
// factors afterwards (common/mesh_material.glsl).
void apply_material_layers(inout Surface s, vec3 n, vec3 t, vec3 b) {
#ifdef HAS_CLEARCOAT
    s.clearcoat = u_clearcoat;
    s.clearcoat_roughness = u_clearcoat_roughness;
    s.clearcoat_normal = n;
#endif
#ifdef HAS_SHEEN
    s.sheen_color = u_sheen_color;
    s.sheen_roughness = u_sheen_roughness;
#endif
#ifdef HAS_ANISOTROPY
    s.anisotropy_strength = u_anisotropy_strength;
    vec3 direction = t * cos(u_anisotropy_rotation) + b * sin(u_anisotropy_rotation);
    s.anisotropy_direction = direction;
    s.anisotropy_bitangent = cross(n, direction);
#endif
#ifdef HAS_TRANSMISSION
    s.transmission = u_transmission;
    s.ior = u_ior;
#endif
#ifdef HAS_VOLUME
    s.thickness = u_thickness;
    s.attenuation_color = u_attenuation_color;
    s.attenuation_distance = u_attenuation_distance;
#endif
#ifdef HAS_DISPERSION
    s.dispersion = u_dispersion;
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
    s.diffuse_transmission = u_diffuse_transmission;
    s.diffuse_transmission_color = u_diffuse_transmission_color;
#endif
}

// The probe view's tangent frame (docs/conventions.md's probe has no mesh): the direction of
// increasing longitude about +Y, as the built-in sphere's u (app/core/mesh.py: sphere), so the
// probe and the sphere agree; at the poles, where longitude has no direction, +X.
void probe_tangent_frame(vec3 n, out vec3 t, out vec3 b) {
    vec3 along = vec3(n.z, 0.0, -n.x);
    t = dot(along, along) > 1e-12 ? normalize(along) : vec3(1.0, 0.0, 0.0);
    b = cross(n, t);
}
