// The mesh pass's material inputs: varyings from render/pbr.vert, the material uniforms and
// texture maps, the shading normal and the Surface at a fragment. Shared by render/pbr.frag
// (forward shading) and render/gbuffer.frag (the reference's G-buffer).
#include "common/surface.glsl"
#include "common/material_layers.glsl"

in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_tangent;

uniform vec3 u_camera_position;
uniform vec3 u_base_color;
uniform float u_metallic;
uniform float u_roughness;
uniform vec3 u_specular_f0;
uniform vec3 u_emissive;
uniform float u_normal_scale;
uniform float u_occlusion_strength;
// The maps' coordinates: uv * u_uv_scale + u_uv_offset (the editor's tiling; identity for files).
uniform vec2 u_uv_scale;
uniform vec2 u_uv_offset;

// Texture maps; sRGB ones are uploaded with sRGB formats so sampling returns linear values.
uniform bool u_has_base_color_map;
uniform bool u_has_metallic_roughness_map;
uniform bool u_has_normal_map;
uniform bool u_has_emissive_map;
uniform bool u_has_occlusion_map;
// Separate greyscale maps (R), as many texture sets ship: over a metallic-roughness map they
// replace its B (metallic) or G (roughness) channel.
uniform bool u_has_metallic_map;
uniform bool u_has_roughness_map;
uniform sampler2D u_base_color_map;
uniform sampler2D u_metallic_roughness_map;
uniform sampler2D u_normal_map;
uniform sampler2D u_emissive_map;
uniform sampler2D u_occlusion_map;
uniform sampler2D u_metallic_map;
uniform sampler2D u_roughness_map;

// The layers' maps (glTF: KHR_materials_clearcoat, KHR_materials_sheen), declared with their layer.
#ifdef HAS_CLEARCOAT
uniform bool u_has_clearcoat_map;             // R multiplies clearcoat
uniform bool u_has_clearcoat_roughness_map;   // G multiplies clearcoat_roughness
uniform bool u_has_clearcoat_normal_map;      // the coat's own tangent-space normal map
uniform float u_clearcoat_normal_scale;
uniform sampler2D u_clearcoat_map;
uniform sampler2D u_clearcoat_roughness_map;
uniform sampler2D u_clearcoat_normal_map;
#endif
#ifdef HAS_SHEEN
uniform bool u_has_sheen_color_map;           // RGB (sRGB) multiplies sheen_color
uniform bool u_has_sheen_roughness_map;       // A multiplies sheen_roughness
uniform sampler2D u_sheen_color_map;
uniform sampler2D u_sheen_roughness_map;
#endif

// The maps compiled in, a bit each (app/render/renderer.py MATERIAL_MAPS order). llvmpipe runs both
// sides of a branch, so a map's fetch costs even where u_has_*_map is false; the forward pass
// passes only the bits of maps present, and has_map() folds to false for the rest. Unset: all.
#ifndef MATERIAL_MAPS_MASK
#define MATERIAL_MAPS_MASK 4095
#endif
const int MAP_BASE_COLOR = 1;
const int MAP_METALLIC_ROUGHNESS = 2;
const int MAP_NORMAL = 4;
const int MAP_EMISSIVE = 8;
const int MAP_OCCLUSION = 16;
const int MAP_METALLIC = 32;
const int MAP_ROUGHNESS = 64;
const int MAP_CLEARCOAT = 128;
const int MAP_CLEARCOAT_ROUGHNESS = 256;
const int MAP_CLEARCOAT_NORMAL = 512;
const int MAP_SHEEN_COLOR = 1024;
const int MAP_SHEEN_ROUGHNESS = 2048;

bool has_map(int bit, bool present) {
    return (MATERIAL_MAPS_MASK & bit) != 0 && present;
}

vec2 material_uv() {
    return v_uv * u_uv_scale + u_uv_offset;
}

// The interpolated normal, or the face normal from screen derivatives where it is zero (bad
// meshes), facing the viewer's side.
vec3 geometric_normal() {
    vec3 n = v_normal;
    vec3 face = normalize(cross(dFdx(v_position), dFdy(v_position)));
    n = dot(n, n) > 1e-12 ? normalize(n) : face;
    return gl_FrontFacing ? n : -n;
}

// An orthonormal tangent frame about n from the mesh's tangent (Gram-Schmidt); a tangent
// parallel to n (a broken file) gets any perpendicular instead. b carries the mesh's handedness.
mat3 tangent_frame(vec3 n) {
    vec3 t = v_tangent.xyz - n * dot(n, v_tangent.xyz);
    if (dot(t, t) < 1e-12) t = cross(abs(n.y) < 0.999 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0), n);
    t = normalize(t);
    vec3 b = cross(n, t) * (v_tangent.w < 0.0 ? -1.0 : 1.0);
    return mat3(t, b, n);
}

// A tangent-space normal map's value in world space about n (glTF: xy scaled by scale).
vec3 normal_from_map(sampler2D map, float scale, vec3 n) {
    vec3 m = texture(map, material_uv()).xyz * 2.0 - 1.0;
    m.xy *= scale;
    vec3 mapped = tangent_frame(n) * m;
    return dot(mapped, mapped) > 1e-12 ? normalize(mapped) : n;
}

vec3 shading_normal() {
    vec3 n = geometric_normal();
    if (has_map(MAP_NORMAL, u_has_normal_map)) {
        n = normal_from_map(u_normal_map, u_normal_scale, n);
    }
    return n;
}

// The material at this fragment; n is shading_normal() (the layers' directions are built about it).
Surface material_surface(vec3 n) {
    vec2 uv = material_uv();
    Surface s = surface_base(u_base_color, u_metallic, u_roughness, u_specular_f0, u_emissive, 1.0);
    if (has_map(MAP_BASE_COLOR, u_has_base_color_map)) s.base_color *= texture(u_base_color_map, uv).rgb;
    // glTF's packing: G = roughness, B = metallic; a separate greyscale map takes precedence.
    vec2 metal_rough = vec2(1.0);
    if (has_map(MAP_METALLIC_ROUGHNESS, u_has_metallic_roughness_map)) metal_rough = texture(u_metallic_roughness_map, uv).bg;
    if (has_map(MAP_METALLIC, u_has_metallic_map)) metal_rough.x = texture(u_metallic_map, uv).r;
    if (has_map(MAP_ROUGHNESS, u_has_roughness_map)) metal_rough.y = texture(u_roughness_map, uv).r;
    s.metallic *= metal_rough.x;
    s.roughness *= metal_rough.y;
    if (has_map(MAP_EMISSIVE, u_has_emissive_map)) s.emissive *= texture(u_emissive_map, uv).rgb;
    if (has_map(MAP_OCCLUSION, u_has_occlusion_map)) s.occlusion = 1.0 + u_occlusion_strength * (texture(u_occlusion_map, uv).r - 1.0);
    s.roughness = clamp(s.roughness, 0.0, 1.0);
    s.metallic = clamp(s.metallic, 0.0, 1.0);
#if defined(HAS_CLEARCOAT) || defined(HAS_SHEEN) || defined(HAS_ANISOTROPY) || defined(HAS_TRANSMISSION) || defined(HAS_VOLUME)
    mat3 frame = tangent_frame(n);
    apply_material_layers(s, n, frame[0], frame[1]);
#endif
#ifdef HAS_CLEARCOAT
    // KHR_materials_clearcoat: without a clearcoat normal map the coat is not normal-mapped,
    // even where the base is.
    s.clearcoat_normal = geometric_normal();
    if (has_map(MAP_CLEARCOAT, u_has_clearcoat_map)) s.clearcoat *= texture(u_clearcoat_map, uv).r;
    if (has_map(MAP_CLEARCOAT_ROUGHNESS, u_has_clearcoat_roughness_map)) {
        s.clearcoat_roughness *= texture(u_clearcoat_roughness_map, uv).g;
    }
    if (has_map(MAP_CLEARCOAT_NORMAL, u_has_clearcoat_normal_map)) {
        s.clearcoat_normal = normal_from_map(u_clearcoat_normal_map, u_clearcoat_normal_scale, s.clearcoat_normal);
    }
#endif
#ifdef HAS_SHEEN
    if (has_map(MAP_SHEEN_COLOR, u_has_sheen_color_map)) s.sheen_color *= texture(u_sheen_color_map, uv).rgb;
    if (has_map(MAP_SHEEN_ROUGHNESS, u_has_sheen_roughness_map)) s.sheen_roughness *= texture(u_sheen_roughness_map, uv).a;
#endif
    return s;
}
