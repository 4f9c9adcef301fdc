#version 450 core
// Forward PBR pass: world-space position, normal and tangent for the fragment shader; the
// second uv set (HAS_UV1), vertex colours (HAS_VERTEX_COLOR) and baked visibility (HAS_VISIBILITY)
// only for parts that have them.

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_tangent;
#ifdef HAS_UV1
layout(location = 4) in vec2 in_uv1;
out vec2 v_uv1;
#endif
#ifdef HAS_VERTEX_COLOR
layout(location = 5) in vec4 in_color;
out vec4 v_color;
#endif

#ifdef HAS_VISIBILITY
// The visibility bake's per-vertex values (app/core/visibility.py), for common/occlusion.glsl.
layout(location = 6) in vec4 in_visibility;
layout(location = 7) in vec4 in_bounce;
layout(location = 8) in vec4 in_sun_bounce;    // per sun: its E/pi on the occluders over its power
layout(location = 9) in vec4 in_sun_bounce2;   // ... and what their sunlit occluders pass them
layout(location = 11) in vec4 in_hit_albedo;    // what the bounce rays hit: its albedo, and 1 where one hit
layout(location = 12) in vec4 in_hit_emission;  // ... and its emission (bake_occluder_materials)
out vec4 v_hit_albedo;
out vec4 v_hit_emission;
#ifdef HAS_SKY_WEIGHT
layout(location = 10) in vec4 in_sky_weight;    // the visible sky weight W (rgb), its rays' V (app/core/sky_weight.py)
out vec4 v_sky_weight;
#endif
out vec4 v_visibility;
out vec4 v_bounce;
out vec4 v_sun_bounce;
out vec4 v_sun_bounce2;
out vec3 v_baked_normal;
#endif

#ifdef PACKED_VERTICES
// Normals and tangents arrive as int16 (alight.render.gpu_mesh.pack_snorm16): the snorm decode
// of GL 4.2, max(c / 32767, -1), which moderngl's vertex formats cannot ask GL for.
#define SNORM16(v) max((v) * (1.0 / 32767.0), -1.0)
#else
#define SNORM16(v) (v)
#endif

uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_view_projection;

out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_tangent;

void main() {
    vec4 world = u_model * vec4(in_position, 1.0);
    v_position = world.xyz;
    v_normal = u_normal_matrix * SNORM16(in_normal);
    vec4 tangent = SNORM16(in_tangent);
    v_tangent = vec4(mat3(u_model) * tangent.xyz, tangent.w);
    v_uv = in_uv;
#ifdef HAS_UV1
    v_uv1 = in_uv1;
#endif
#ifdef HAS_VERTEX_COLOR
    v_color = in_color;
#endif
#ifdef HAS_VISIBILITY
    v_visibility = vec4(u_normal_matrix * in_visibility.xyz, in_visibility.w);
    // the mean bent normal's length (bounce_irradiance) kept through a scaling normal matrix
    vec3 bounce = u_normal_matrix * in_bounce.xyz;
    v_bounce = vec4(bounce * (length(in_bounce.xyz) / max(length(bounce), 1e-12)), in_bounce.w);
    v_sun_bounce = in_sun_bounce;
    v_sun_bounce2 = in_sun_bounce2;
    v_hit_albedo = in_hit_albedo;
    v_hit_emission = in_hit_emission;
#ifdef HAS_SKY_WEIGHT
    v_sky_weight = in_sky_weight;
#endif
    v_baked_normal = v_normal;
#endif
    gl_Position = u_view_projection * world;
}
