#version 450 core
// alight reference (app/accuracy/reference.py): docs/conventions.md's ground truth at every G-buffer pixel.
// One dispatch sums the environment rows [u_row_begin, u_row_end) into the accumulator; the
// first one (u_first) starts it from emission plus the punctual lights (punctual.glsl's
// punctual_light, k = (r+1)^2/8, no occlusion). Pixels the G-buffer marks empty stay 0.
layout(local_size_x = 8, local_size_y = 8) in;
// Every light kind alight has: the reference is measured, not raced.
#define PUNCTUAL_SPOT
#define PUNCTUAL_RANGE
#include "accuracy/ground_truth.glsl"
#include "common/material_layers.glsl"

uniform sampler2D u_g_position;     // xyz world position, w coverage (0 or 1)
uniform sampler2D u_g_normal;       // xyz n, w roughness
uniform sampler2D u_g_view;         // xyz v, w metallic
uniform sampler2D u_g_base_color;
uniform sampler2D u_g_specular_f0;
uniform sampler2D u_g_emissive;
uniform sampler2D u_g_tangent;      // xyz the tangent t of the layers' frame (b = cross(n, t) * w)
uniform sampler2D u_env;            // the (possibly downsampled) equirect, level 0
layout(rgba32f, binding = 0) uniform image2D u_accum;

uniform ivec2 u_size;
uniform bool u_first;
uniform bool u_env_enabled;
uniform int u_row_begin;
uniform int u_row_end;
// u_env_rotation ((cos(-deg), sin(-deg)): world -> map) and u_env_intensity: common/ibl.glsl's.

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= u_size.x || p.y >= u_size.y) return;
    vec4 position = texelFetch(u_g_position, p, 0);
    if (position.w < 0.5) {
        if (u_first) imageStore(u_accum, p, vec4(0.0));
        return;
    }
    vec4 nr = texelFetch(u_g_normal, p, 0);
    vec4 vm = texelFetch(u_g_view, p, 0);
    Surface s = surface_base(texelFetch(u_g_base_color, p, 0).rgb, vm.w, nr.w,
                             texelFetch(u_g_specular_f0, p, 0).rgb, texelFetch(u_g_emissive, p, 0).rgb, 1.0);
    s.specular_f90 = texelFetch(u_g_specular_f0, p, 0).a;   // 1 unless KHR_materials_specular
    vec3 n = normalize(nr.xyz);
    vec3 v = normalize(vm.xyz);
    vec3 n_map = rotate_world_to_map(n, u_env_rotation);
    vec3 v_map = rotate_world_to_map(v, u_env_rotation);
    // The environment is summed in the map's frame: a copy of the surface with its layers'
    // directions (coat normal, tangent frame) in that frame too.
    Surface s_map = s;
#if defined(HAS_CLEARCOAT) || defined(HAS_SHEEN) || defined(HAS_ANISOTROPY) || defined(HAS_TRANSMISSION) || defined(HAS_VOLUME) || defined(HAS_DIFFUSE_TRANSMISSION)
    // The layers' factors are the scene material's (app/accuracy/reference.py), about the
    // G-buffer's frame.
    vec4 tw = texelFetch(u_g_tangent, p, 0);
    vec3 t = tw.xyz - n * dot(n, tw.xyz);
    t = dot(t, t) > 1e-12 ? normalize(t) : normalize(cross(abs(n.y) < 0.999 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0), n));
    vec3 b = cross(n, t) * (tw.w < 0.0 ? -1.0 : 1.0);
    apply_material_layers(s, n, t, b);
    apply_material_layers(s_map, n_map, rotate_world_to_map(t, u_env_rotation), rotate_world_to_map(b, u_env_rotation));
#endif
#ifdef HAS_ANISOTROPY
    // The G-buffer's tangent length: the anisotropy map's factor on the strength, 0 where the
    // part has no anisotropy (render/gbuffer.frag); 1 in the probe's G-buffer.
    s.anisotropy_strength *= min(length(tw.xyz), 1.0);
    s_map.anisotropy_strength = s.anisotropy_strength;
#endif
#ifdef HAS_IRIDESCENCE
    apply_material_iridescence(s);
    iridescence_at_view(s, n, v);
    apply_material_iridescence(s_map);
    iridescence_at_view(s_map, n_map, v_map);
#endif
    vec3 sum = u_first ? layered_emission(s, v) + punctual_lights(s, n, v, position.xyz) : imageLoad(u_accum, p).rgb;
    if (u_env_enabled && u_row_end > u_row_begin) {
        sum += u_env_intensity * ground_truth_rows(u_env, 0, u_row_begin, u_row_end, s_map, n_map, v_map);
    }
    imageStore(u_accum, p, vec4(sum, 1.0));
}
