// The mesh pass's material inputs: varyings from render/pbr.vert, the material uniforms and
// texture maps, the shading normal and the Surface at a fragment. Shared by render/pbr.frag
// (forward shading) and render/gbuffer.frag (the reference's G-buffer).
//
// The per-texture features of glTF that cost a fetch or more are compile-time choices, a bit per
// map in a mask, so a part pays only for what its maps use (llvmpipe runs both sides of a branch):
//   MATERIAL_MAPS_MASK   the maps present;
//   MAP_MIRROR_S_MASK,   maps whose sampler wraps by MIRRORED_REPEAT in s or t (REPEAT and
//   MAP_MIRROR_T_MASK    CLAMP_TO_EDGE are the texture's own wrap state).
// Which uv set a map reads (u_map_uv1, with HAS_UV1) and its KHR_texture_transform
// (u_map_transform, with HAS_TEXTURE_TRANSFORM) are uniforms: a select and a mat3 multiply a map
// cost less than a variant of their own, compiled by LLVM at its first draw (app/render/variants.py).
// HAS_VERTEX_COLOR: COLOR_0 multiplies the base colour and alpha (glTF 2.0 section 3.9.2).
// SPHERE_SURFACE: the part is the built-in sphere drawn at a coarser level (alight.core.sphere_lod):
// the surface point is where the view ray meets the true sphere, and the normal is the sphere's.
#include "common/surface.glsl"
#include "common/material_layers.glsl"

#ifdef VBUFFER_SHADING
// Shaded from the visibility buffer (render/vbuffer_shade.frag): no rasteriser behind this pass,
// so the "varyings" are globals its main() fills from the triangle's vertices at the shaded
// point (each 2x2 block evaluating one triangle, so the implicit derivatives are the forward
// pass's), with the facing it finds.
vec3 v_position;
vec3 v_normal;
vec2 v_uv;
vec4 v_tangent;
#ifdef HAS_UV1
vec2 v_uv1;
#endif
#ifdef HAS_VERTEX_COLOR
vec4 v_color;
#endif
vec3 vb_centroid_normal;   // the normal at the triangle's covered samples' centroid
vec3 vb_face_normal;   // the triangle's unit normal toward the eye (as cross(dFdx, dFdy) of the position)
bool vb_front_facing;
#define FRONT_FACING vb_front_facing
#else
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_tangent;
#ifdef HAS_UV1
in vec2 v_uv1;
#endif
#ifdef HAS_VERTEX_COLOR
in vec4 v_color;
#endif
#define FRONT_FACING gl_FrontFacing
#endif

uniform vec3 u_camera_position;
uniform vec3 u_base_color;
uniform float u_metallic;
uniform float u_roughness;
uniform vec3 u_specular_f0;
uniform vec3 u_emissive;
uniform float u_normal_scale;
uniform float u_occlusion_strength;
uniform float u_alpha;          // baseColorFactor's alpha
uniform float u_alpha_cutoff;   // MASK
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
#ifdef HAS_ANISOTROPY
uniform bool u_has_anisotropy_map;            // KHR_materials_anisotropy: RG a direction (2x - 1), B x strength
uniform sampler2D u_anisotropy_map;
#endif
#ifdef HAS_TRANSMISSION
uniform bool u_has_transmission_map;          // R multiplies transmission
uniform sampler2D u_transmission_map;
#endif
#ifdef HAS_VOLUME
uniform bool u_has_thickness_map;             // G multiplies thickness
uniform sampler2D u_thickness_map;
#endif
#ifdef HAS_IRIDESCENCE
uniform bool u_has_iridescence_map;           // KHR_materials_iridescence: R multiplies iridescence
uniform bool u_has_iridescence_thickness_map; // G mixes the film's thickness from the minimum to the maximum
uniform sampler2D u_iridescence_map;
uniform sampler2D u_iridescence_thickness_map;
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
// KHR_materials_diffuse_transmission's two textures in one (alight.exchange.packed_textures):
// A multiplies diffuse_transmission, RGB (sRGB) multiplies diffuse_transmission_color.
uniform bool u_has_diffuse_transmission_map;
uniform sampler2D u_diffuse_transmission_map;
#endif

// The maps compiled in, a bit each (app/core/shader_names.py MATERIAL_MAPS order). llvmpipe runs both
// sides of a branch, so a map's fetch costs even where u_has_*_map is false; the forward pass
// passes only the bits of maps present, and has_map() folds to false for the rest. Unset: all.
#ifndef MATERIAL_MAPS_MASK
#define MATERIAL_MAPS_MASK MAP_ALL
#endif
#ifndef MAP_MIRROR_S_MASK
#define MAP_MIRROR_S_MASK 0
#endif
#ifndef MAP_MIRROR_T_MASK
#define MAP_MIRROR_T_MASK 0
#endif
// MAP_BASE_COLOR ... MAP_SPECULAR_COLOR (a bit each), MAP_SLOTS and MAP_ALL: app/core/shader_names.py
// MATERIAL_MAPS (generated).
// READS_TANGENT: the material reads the mesh's tangent frame (a normal map, the coat's normal
// map, anisotropy); elsewhere the frame tangent_frame() builds for the layers goes unused.
// render/vbuffer_shade.frag fetches and interpolates tangents only where it is defined (the
// forward pass's in_tangent is inactive, and unbound, in the same variants).
#if (MATERIAL_MAPS_MASK & (MAP_NORMAL | MAP_CLEARCOAT_NORMAL)) != 0 || defined(HAS_ANISOTROPY)
#define READS_TANGENT
#endif
// KHR_materials_specular's textures, compiled in only where a part has one 
#if (MATERIAL_MAPS_MASK & (MAP_SPECULAR | MAP_SPECULAR_COLOR)) != 0
#define HAS_SPECULAR_MAPS
uniform bool u_has_specular_map;              // A multiplies specularFactor
uniform bool u_has_specular_color_map;        // RGB (sRGB) multiplies specularColorFactor
uniform sampler2D u_specular_map;
uniform sampler2D u_specular_color_map;
uniform float u_specular_factor;
uniform vec3 u_specular_color_f0;             // F0(ior) * specularColorFactor, before the min(., 1)
#endif
uniform float u_specular_f90 = 1.0;           // KHR_materials_specular's specularFactor (1 without it)
// KHR_texture_transform's matrix per map (slot = log2 of its bit), on alight's OpenGL uvs;
// identity for a map without one (exact: 1 * u + 0 * v + 0).
uniform mat3 u_map_transform[MAP_SLOTS];
#ifdef HAS_UV1
uniform int u_map_uv1;   // the maps read with TEXCOORD_1 (MATERIAL_MAPS bits); the rest TEXCOORD_0
#endif

#ifdef SPHERE_SURFACE
#include "common/sphere_surface.glsl"
uniform float u_sphere_radius;   // centred at the origin; the camera is outside it (perspective)

#ifdef SPHERE_IMPOSTOR
// The built-in sphere drawn as an impostor (app/render/renderer.py _sphere_impostor): a coarse
// proxy around the sphere is rasterised, and each pixel's coverage is the fraction of its
// SPHERE_IMPOSTOR sample rays (1: the pixel centre; 4: the standard 4x MSAA pattern) that meet the
// true sphere. llvmpipe shades a pixel once per triangle that covers any of its samples, so the
// MSAA ball's small facets shaded most edge pixels twice; the proxy's few large triangles do not,
// and the 4x frame needs no multisampled target at all.
uniform mat4 u_inverse_view_projection;   // this pass's (a tile's off-centre projection included)
uniform vec2 u_viewport_size;             // pixels

float sphere_coverage() {
#if SPHERE_IMPOSTOR == 1
    // The pixel centre's ray passes through the proxy's point here.
    return ray_meets_sphere(u_camera_position, v_position - u_camera_position, u_sphere_radius) ? 1.0 : 0.0;
#else
    // OpenGL's standard 4x positions (the D3D pattern), from the pixel centre.
    const vec2 offsets[4] = vec2[4](vec2(-0.125, -0.375), vec2(0.375, -0.125), vec2(-0.375, 0.125), vec2(0.125, 0.375));
    float covered = 0.0;
    for (int i = 0; i < 4; ++i) {
        vec2 ndc = (gl_FragCoord.xy + offsets[i]) / u_viewport_size * 2.0 - 1.0;
        vec4 far = u_inverse_view_projection * vec4(ndc, 1.0, 1.0);
        covered += ray_meets_sphere(u_camera_position, far.xyz / far.w - u_camera_position, u_sphere_radius) ? 1.0 : 0.0;
    }
    return covered / 4.0;
#endif
}
#endif
#endif

// The shaded point: the interpolated position, or on the built-in sphere the true surface's.
vec3 surface_position() {
#ifdef SPHERE_SURFACE
    return sphere_surface_point(u_camera_position, v_position, u_sphere_radius);
#else
    return v_position;
#endif
}

bool has_map(int bit, bool present) {
    return (MATERIAL_MAPS_MASK & bit) != 0 && present;
}

// The mesh's uv (TEXCOORD_0), or on the impostor the built-in sphere's at the shaded point: the
// proxy has none, and the tessellated ball's interpolated ones differ from it only by its facets.
vec2 surface_uv() {
#ifdef SPHERE_IMPOSTOR
    // Across the seam the analytic u jumps from 1 to 0, and a 2x2 block straddling it would take
    // a whole texture's width as its derivative (the smallest mip: a visible line). There u is
    // read in (-0.5, 0.5] instead, equal under the maps' repeat wrap (Tarini 2012, "Cylindrical and
    // toroidal parameterizations without vertex seams"); the block chooses as one.
    vec2 uv = sphere_uv(surface_position());
    return fwidth(uv.x) > 0.5 ? vec2(uv.x > 0.5 ? uv.x - 1.0 : uv.x, uv.y) : uv;
#else
    return v_uv;
#endif
}

// The mesh's tangent and handedness, or on the impostor the built-in sphere's.
vec4 surface_tangent() {
#ifdef SPHERE_IMPOSTOR
    return sphere_tangent(surface_position());
#else
    return v_tangent;
#endif
}

vec2 material_uv() {
    return surface_uv() * u_uv_scale + u_uv_offset;
}

// The coordinates a map reads: its uv set, then its texture transform (glTF 2.0 textureInfo
// texCoord; KHR_texture_transform).
vec2 map_uv(int bit, int slot) {
    vec2 uv = material_uv();
#ifdef HAS_UV1
    if ((u_map_uv1 & bit) != 0) uv = v_uv1;
#endif
#ifdef HAS_TEXTURE_TRANSFORM
    uv = (u_map_transform[slot] * vec3(uv, 1.0)).xy;
#endif
    return uv;
}

// MIRRORED_REPEAT (OpenGL 4.5 section 8.14.2): the triangle wave of period 2.
float mirrored_repeat(float x) {
    return 1.0 - abs(mod(x, 2.0) - 1.0);
}

// A map's texel at its coordinates, its level of detail moved by lod_bias (log2; negative:
// finer). Mirrored axes are folded here and sampled with the unfolded derivatives (scaled to
// match the bias), so the mip level does not jump at the folds.
vec4 sample_map_biased(sampler2D map, int bit, int slot, float lod_bias) {
    vec2 uv = map_uv(bit, slot);
    if (((MAP_MIRROR_S_MASK | MAP_MIRROR_T_MASK) & bit) != 0) {
        vec2 folded = uv;
        if ((MAP_MIRROR_S_MASK & bit) != 0) folded.x = mirrored_repeat(uv.x);
        if ((MAP_MIRROR_T_MASK & bit) != 0) folded.y = mirrored_repeat(uv.y);
        float scale = exp2(lod_bias);
        return textureGrad(map, folded, dFdx(uv) * scale, dFdy(uv) * scale);
    }
    return texture(map, uv, lod_bias);
}

vec4 sample_map(sampler2D map, int bit, int slot) {
    return sample_map_biased(map, bit, slot, 0.0);
}

// The interpolated normal, or the face normal from screen derivatives where it is zero (bad
// meshes), facing the viewer's side.
vec3 geometric_normal() {
#ifdef SPHERE_SURFACE
    vec3 n = surface_position();
#elif defined(VBUFFER_SHADING)
    // As below, with the centroid's normal found by render/vbuffer_shade.frag.
    vec3 n = v_normal;
    if (dot(n, u_camera_position - v_position) * (vb_front_facing ? 1.0 : -1.0) < 0.0) n = vb_centroid_normal;
    vec3 face = vb_face_normal;
#else
    vec3 n = v_normal;
    // With MSAA the pixel centre of an edge pixel may lie off the triangle, where the
    // interpolated normal is extrapolated past the silhouette and faces away from the eye (a
    // mirror-like ball then sparkles along its rim): there, read it at the covered samples'
    // centroid instead. Covered centres are left as they are (GLSL 4.50 section 8.13.2).
    vec3 eye = u_camera_position - v_position;
    if (dot(n, eye) * (gl_FrontFacing ? 1.0 : -1.0) < 0.0) n = interpolateAtCentroid(v_normal);
#endif
#ifndef VBUFFER_SHADING
    vec3 face = normalize(cross(dFdx(v_position), dFdy(v_position)));
#endif
    n = dot(n, n) > 1e-12 ? normalize(n) : face;
    return FRONT_FACING ? n : -n;
}

// An orthonormal tangent frame about n from the mesh's tangent (Gram-Schmidt); a tangent
// parallel to n (a broken file) gets any perpendicular instead. b carries the mesh's handedness.
mat3 tangent_frame(vec3 n) {
    vec4 tangent = surface_tangent();
    vec3 t = tangent.xyz - n * dot(n, tangent.xyz);
    if (dot(t, t) < 1e-12) t = cross(abs(n.y) < 0.999 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0), n);
    t = normalize(t);
    vec3 b = cross(n, t) * (tangent.w < 0.0 ? -1.0 : 1.0);
    return mat3(t, b, n);
}

// NORMAL_MAP_TOKSVIG (compiled in where a part has a normal map, alight.render.variants): the
// normal map's texels carry in A the spread of the level-0 normals under them (Toksvig 2005;
// alight.render.normal_spread: 0 on level 0, so an 8-bit map never widens a mirror), added to
// the roughness of the layers shaded about that normal (brdf.glsl normal_map_roughness).
#ifdef NORMAL_MAP_TOKSVIG
float normal_map_widening = 0.0;   // the base normal map's A, set by shading_normal()
#endif

// A tangent-space normal map's value in world space about n (glTF: xy scaled by scale), and
// the texel's A (the spread, under NORMAL_MAP_TOKSVIG).
vec3 normal_from_map(sampler2D map, int bit, int slot, float scale, vec3 n, out float widening) {
#ifdef NORMAL_MAP_LOD_BIAS
    // One level finer: trilinear filtering's kernel (a bilinear tent at the level whose texel
    // spans the pixel, blended with the next coarser) is about twice the pixel's box across, and
    // the shading is not linear in the normal, so a near-mirror's relief under the pixel was
    // averaged away (results/helmet_split.md).
    vec4 texel = sample_map_biased(map, bit, slot, NORMAL_MAP_LOD_BIAS);
#else
    vec4 texel = sample_map(map, bit, slot);
#endif
    widening = texel.a;
    vec3 m = texel.xyz * 2.0 - 1.0;
    m.xy *= scale;
    vec3 mapped = tangent_frame(n) * m;
    return dot(mapped, mapped) > 1e-12 ? normalize(mapped) : n;
}

// The shading normal. Every caller runs it before material_surface() (which reads the spread).
vec3 shading_normal() {
    vec3 n = geometric_normal();
    if (has_map(MAP_NORMAL, u_has_normal_map)) {
        float widening;
        n = normal_from_map(u_normal_map, MAP_NORMAL, 2, u_normal_scale, n, widening);
#ifdef NORMAL_MAP_TOKSVIG
        normal_map_widening = widening;
#endif
    }
    return n;
}

// Base colour and alpha: factor x map x COLOR_0 (glTF 2.0 section 3.9.2).
vec4 material_base_color() {
    vec4 c = vec4(u_base_color, u_alpha);
    if (has_map(MAP_BASE_COLOR, u_has_base_color_map)) c *= sample_map(u_base_color_map, MAP_BASE_COLOR, 0);
#ifdef HAS_VERTEX_COLOR
    c *= v_color;
#endif
    return c;
}

float material_alpha() {
    return material_base_color().a;
}

#ifdef ALPHA_TO_COVERAGE
// alphaMode MASK under MSAA: the samples the alpha test keeps, as a gl_SampleMask word. Sharpened
// alpha to coverage (Golus, "Anti-aliased Alpha Test: The Esoteric Alpha To Coverage", 2017): the
// distance past the cutoff in units of alpha's change over one pixel (fwidth) picks how many of
// the ALPHA_TO_COVERAGE samples are covered, so the cutoff's edge is resolved to one pixel
// across as a triangle's edge is, and a pixel wholly past it keeps every sample (the plain test).
// In the shader, not GL's SAMPLE_ALPHA_TO_COVERAGE: the visibility buffer's integer target skips
// that (GL 4.5 section 17.3.3), and both passes must keep the same samples.
int alpha_coverage_mask(float alpha) {
    float past = clamp((alpha - u_alpha_cutoff) / max(fwidth(alpha), 1e-4) + 0.5, 0.0, 1.0);
    int kept = int(past * float(ALPHA_TO_COVERAGE) + 0.5);
    return (1 << kept) - 1;
}
#endif

// The material at this fragment; n is shading_normal() (the layers' directions are built about it).
Surface material_surface(vec3 n) {
    Surface s = surface_base(material_base_color().rgb, u_metallic, u_roughness, u_specular_f0, u_emissive, 1.0);
    s.specular_f90 = u_specular_f90;
    // glTF's packing: G = roughness, B = metallic; a separate greyscale map takes precedence.
    vec2 metal_rough = vec2(1.0);
    if (has_map(MAP_METALLIC_ROUGHNESS, u_has_metallic_roughness_map)) metal_rough = sample_map(u_metallic_roughness_map, MAP_METALLIC_ROUGHNESS, 1).bg;
    if (has_map(MAP_METALLIC, u_has_metallic_map)) metal_rough.x = sample_map(u_metallic_map, MAP_METALLIC, 5).r;
    if (has_map(MAP_ROUGHNESS, u_has_roughness_map)) metal_rough.y = sample_map(u_roughness_map, MAP_ROUGHNESS, 6).r;
    s.metallic *= metal_rough.x;
    s.roughness *= metal_rough.y;
    if (has_map(MAP_EMISSIVE, u_has_emissive_map)) s.emissive *= sample_map(u_emissive_map, MAP_EMISSIVE, 3).rgb;
#ifdef HAS_SPECULAR_MAPS
    if (has_map(MAP_SPECULAR, u_has_specular_map) || has_map(MAP_SPECULAR_COLOR, u_has_specular_color_map)) {
        // KHR_materials_specular: dielectric F0 = min(F0(ior) * specularColor, 1) * specular.
        vec3 color = u_specular_color_f0;
        float factor = u_specular_factor;
        if (has_map(MAP_SPECULAR_COLOR, u_has_specular_color_map)) {
            color *= sample_map(u_specular_color_map, MAP_SPECULAR_COLOR, 16).rgb;
        }
        if (has_map(MAP_SPECULAR, u_has_specular_map)) factor *= sample_map(u_specular_map, MAP_SPECULAR, 15).a;
        s.specular_f0 = min(color, vec3(1.0)) * factor;
        s.specular_f90 = factor;   // the extension's F90 = specular (factor times texture A)
    }
#endif
    if (has_map(MAP_OCCLUSION, u_has_occlusion_map)) s.occlusion = 1.0 + u_occlusion_strength * (sample_map(u_occlusion_map, MAP_OCCLUSION, 4).r - 1.0);
    s.roughness = clamp(s.roughness, 0.0, 1.0);
#ifdef NORMAL_MAP_TOKSVIG
    // before the layers: anisotropy and transmission shade at this roughness about n too
    s.roughness = normal_map_roughness(s.roughness, normal_map_widening);
#endif
    s.metallic = clamp(s.metallic, 0.0, 1.0);
#if defined(HAS_CLEARCOAT) || defined(HAS_SHEEN) || defined(HAS_ANISOTROPY) || defined(HAS_TRANSMISSION) || defined(HAS_VOLUME) || defined(HAS_DIFFUSE_TRANSMISSION)
    mat3 frame = tangent_frame(n);
    apply_material_layers(s, n, frame[0], frame[1]);
#endif
#ifdef HAS_IRIDESCENCE
    apply_material_iridescence(s);
    if (has_map(MAP_IRIDESCENCE, u_has_iridescence_map)) s.iridescence *= sample_map(u_iridescence_map, MAP_IRIDESCENCE, 17).r;
    if (has_map(MAP_IRIDESCENCE_THICKNESS, u_has_iridescence_thickness_map)) {
        s.iridescence_thickness = mix(u_iridescence_thickness_minimum, u_iridescence_thickness_maximum,
                                      sample_map(u_iridescence_thickness_map, MAP_IRIDESCENCE_THICKNESS, 18).g);
    }
#endif
#ifdef HAS_ANISOTROPY
    if (has_map(MAP_ANISOTROPY, u_has_anisotropy_map)) {
        // KHR_materials_anisotropy: the map's direction, turned by anisotropyRotation, in the
        // tangent frame; its B scales the strength.
        vec3 texel = sample_map(u_anisotropy_map, MAP_ANISOTROPY, 12).rgb;
        vec2 d = texel.rg * 2.0 - 1.0;
        float c = cos(u_anisotropy_rotation);
        float sn = sin(u_anisotropy_rotation);
        vec3 direction = frame[0] * (c * d.x - sn * d.y) + frame[1] * (sn * d.x + c * d.y);
        s.anisotropy_direction = dot(direction, direction) > 1e-12 ? normalize(direction) : frame[0];
        s.anisotropy_bitangent = cross(n, s.anisotropy_direction);
        s.anisotropy_strength *= texel.b;
    }
#endif
#ifdef HAS_CLEARCOAT
    // KHR_materials_clearcoat: without a clearcoat normal map the coat is not normal-mapped,
    // even where the base is.
    s.clearcoat_normal = geometric_normal();
    if (has_map(MAP_CLEARCOAT, u_has_clearcoat_map)) s.clearcoat *= sample_map(u_clearcoat_map, MAP_CLEARCOAT, 7).r;
    if (has_map(MAP_CLEARCOAT_ROUGHNESS, u_has_clearcoat_roughness_map)) {
        s.clearcoat_roughness *= sample_map(u_clearcoat_roughness_map, MAP_CLEARCOAT_ROUGHNESS, 8).g;
    }
    if (has_map(MAP_CLEARCOAT_NORMAL, u_has_clearcoat_normal_map)) {
        float widening;
        s.clearcoat_normal = normal_from_map(u_clearcoat_normal_map, MAP_CLEARCOAT_NORMAL, 9, u_clearcoat_normal_scale,
                                             s.clearcoat_normal, widening);
#ifdef NORMAL_MAP_TOKSVIG
        // the coat's own map's spread (the coat never takes the base normal map's)
        s.clearcoat_roughness = normal_map_roughness(clamp(s.clearcoat_roughness, 0.0, 1.0), widening);
#endif
    }
#endif
#ifdef HAS_SHEEN
    if (has_map(MAP_SHEEN_COLOR, u_has_sheen_color_map)) s.sheen_color *= sample_map(u_sheen_color_map, MAP_SHEEN_COLOR, 10).rgb;
    if (has_map(MAP_SHEEN_ROUGHNESS, u_has_sheen_roughness_map)) {
        s.sheen_roughness *= sample_map(u_sheen_roughness_map, MAP_SHEEN_ROUGHNESS, 11).a;
    }
#endif
#ifdef HAS_TRANSMISSION
    if (has_map(MAP_TRANSMISSION, u_has_transmission_map)) s.transmission *= sample_map(u_transmission_map, MAP_TRANSMISSION, 13).r;
#endif
#ifdef HAS_VOLUME
    if (has_map(MAP_THICKNESS, u_has_thickness_map)) s.thickness *= sample_map(u_thickness_map, MAP_THICKNESS, 14).g;
#endif
#ifdef HAS_DIFFUSE_TRANSMISSION
    if (has_map(MAP_DIFFUSE_TRANSMISSION, u_has_diffuse_transmission_map)) {
        vec4 texel = sample_map(u_diffuse_transmission_map, MAP_DIFFUSE_TRANSMISSION, 19);
        s.diffuse_transmission *= texel.a;
        s.diffuse_transmission_color *= texel.rgb;
    }
#endif
    return s;
}
