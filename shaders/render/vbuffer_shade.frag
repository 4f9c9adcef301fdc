#version 450 core
// A part shaded from the visibility buffer (app/render/vbuffer.py), one full-screen pass per
// part, added into a single-sample target that render/resolve.frag reads with SCENE_SAMPLES 1.
// Each pixel shades each distinct triangle of this part among its 4 samples once (the same
// material and light functions as render/pbr.frag), weighted by the samples it covers: a pixel
// inside a triangle once, an edge pixel once per triangle. Each is shaded where the forward pass
// shades it under MSAA, at the pixel centre (extrapolated where the centre lies off the
// triangle), with the normal read at the covered samples' centroid where the centre's faces
// away (common/mesh_material.glsl geometric_normal). The triangle's vertices are fetched from the
// part's own buffers, and its attributes interpolated with the barycentrics where the view ray
// meets its plane, so they are perspective-correct (Burns and Hunt 2013, "The Visibility
// Buffer"; Schied and Dachsbacher 2015).
//
// Quad-coherent: the 2x2 block of pixels the implicit derivatives are taken over (texture()'s
// mip level) shades one triangle at a time, all four pixels evaluating that same triangle's
// plane, extended past its edges, at their own centres, as the rasteriser's block does for the
// forward pass. So the maps' derivatives are the forward pass's, with no textureGrad. The block
// agrees on its triangle by exchanging ids through dFdxFine / dFdyFine (quad_min), and loops
// until none of its pixels has a triangle left; a pixel shades the others' triangles only for
// their derivatives. app/render/vbuffer.py draws this pass with an even scissor on an even
// viewport, so the blocks are the forward pass's.
#include "common/shading.glsl"
#include "common/mesh_material.glsl"
#include "common/debug_views.glsl"
#include "common/output_encoding.glsl"

// GpuPart's buffers as 32-bit words: its vertex layout (packed or not) comes as defines from
// app/render/vbuffer.py's vertex_layout (VERTEX_WORDS, NORMAL_AT, UV_AT, UV1_AT, COLOR_AT,
// NORMAL_SNORM16, UV_HALF, TANGENT_SNORM16), the tangents from their own buffer.
layout(std430, binding = 0) readonly buffer Vertices { uint vertex_words[]; };   // GpuPart.vbo
layout(std430, binding = 1) readonly buffer Indices { uint index_data[]; };       // GpuPart.ibo
#ifdef READS_TANGENT
layout(std430, binding = 2) readonly buffer Tangents { uint tangent_words[]; };  // GpuPart.tangent_buffer
#endif
#ifdef HAS_VISIBILITY
// The visibility bake's per-vertex values (alight.render.visibility_parts: GpuPart.extra_buffers),
// 8 floats a vertex each: (in_visibility, in_bounce) and (in_sun_bounce, in_sun_bounce2).
layout(std430, binding = 3) readonly buffer Visibility { vec4 visibility_data[]; };
layout(std430, binding = 4) readonly buffer SunBounce { vec4 sun_bounce_data[]; };
// (in_hit_albedo, in_hit_emission): alight.core.visibility.bake_occluder_materials
layout(std430, binding = 6) readonly buffer HitMaterial { vec4 hit_material_data[]; };
#ifdef HAS_SKY_WEIGHT
layout(std430, binding = 5) readonly buffer SkyWeight { vec4 sky_weight_data[]; };
#endif
#endif

uniform usampler2DMS u_visibility;        // render/vbuffer.frag's (triangle + 1, part + 1)
uniform uint u_part;                      // this part's index + 1
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_inverse_view_projection;   // this pass's (a tile's off-centre projection included)
uniform vec2 u_viewport_size;             // pixels

layout(location = 0) out vec4 out_radiance;

// OpenGL's standard 4x positions (the D3D pattern) from the pixel centre, as the impostor's
// (common/mesh_material.glsl sphere_coverage).
const vec2 SAMPLE_OFFSETS[4] = vec2[4](vec2(-0.125, -0.375), vec2(0.375, -0.125), vec2(-0.375, 0.125), vec2(0.125, 0.375));

float word_float(uint v, int at) {
    return uintBitsToFloat(vertex_words[v * uint(VERTEX_WORDS) + uint(at)]);
}

vec3 fetch3(uint v, int at) {
    return vec3(word_float(v, at), word_float(v, at + 1), word_float(v, at + 2));
}

vec4 fetch4(uint v, int at) {
    return vec4(word_float(v, at), word_float(v, at + 1), word_float(v, at + 2), word_float(v, at + 3));
}

vec2 fetch2(uint v, int at) {
    return vec2(word_float(v, at), word_float(v, at + 1));
}

// Four int16 in two words (little-endian, as numpy writes them), decoded as GL 4.2's snorm.
vec4 snorm16x4(uint low, uint high) {
    ivec4 c = ivec4(bitfieldExtract(int(low), 0, 16), bitfieldExtract(int(low), 16, 16),
                    bitfieldExtract(int(high), 0, 16), bitfieldExtract(int(high), 16, 16));
    return max(vec4(c) * (1.0 / 32767.0), vec4(-1.0));
}

vec3 fetch_normal(uint v) {
#ifdef NORMAL_SNORM16
    uint i = v * uint(VERTEX_WORDS) + uint(NORMAL_AT);
    return snorm16x4(vertex_words[i], vertex_words[i + 1u]).xyz;
#else
    return fetch3(v, NORMAL_AT);
#endif
}

vec2 fetch_uv(uint v) {
#ifdef UV_HALF
    return unpackHalf2x16(vertex_words[v * uint(VERTEX_WORDS) + uint(UV_AT)]);
#else
    return fetch2(v, UV_AT);
#endif
}

#ifdef READS_TANGENT
vec4 fetch_tangent(uint v) {
#ifdef TANGENT_SNORM16
    return snorm16x4(tangent_words[2u * v], tangent_words[2u * v + 1u]);
#else
    uint i = 4u * v;
    return uintBitsToFloat(uvec4(tangent_words[i], tangent_words[i + 1u], tangent_words[i + 2u], tangent_words[i + 3u]));
#endif
}
#endif

// The world-space ray through window position xy (pixels): origin, direction.
void view_ray(vec2 xy, out vec3 origin, out vec3 direction) {
    vec2 ndc = xy / u_viewport_size * 2.0 - 1.0;
    vec4 near = u_inverse_view_projection * vec4(ndc, -1.0, 1.0);
    vec4 far = u_inverse_view_projection * vec4(ndc, 1.0, 1.0);
    origin = near.xyz / near.w;
    direction = far.xyz / far.w - origin;
}

// Barycentrics (of p1, p2; p0's is 1 - both) where the ray meets the triangle's plane
// (Moller and Trumbore 1997), valid outside the triangle too (the block's other pixels).
vec2 barycentrics(vec2 xy, vec3 p0, vec3 e1, vec3 e2) {
    vec3 origin, direction;
    view_ray(xy, origin, direction);
    vec3 pv = cross(direction, e2);
    float inv = 1.0 / dot(e1, pv);
    vec3 tv = origin - p0;
    vec3 qv = cross(tv, e1);
    return vec2(dot(tv, pv), dot(direction, qv)) * inv;
}

// Fills common/mesh_material.glsl's globals for triangle `triangle` at window position xy, and
// vb_centroid_normal at xy + at_centroid (its covered samples' mean offset).
void interpolate(uint triangle, vec2 xy, vec2 at_centroid) {
    uint i0 = index_data[3u * triangle], i1 = index_data[3u * triangle + 1u], i2 = index_data[3u * triangle + 2u];
    vec3 p0 = (u_model * vec4(fetch3(i0, 0), 1.0)).xyz;
    vec3 p1 = (u_model * vec4(fetch3(i1, 0), 1.0)).xyz;
    vec3 p2 = (u_model * vec4(fetch3(i2, 0), 1.0)).xyz;
    vec3 e1 = p1 - p0, e2 = p2 - p0;
    vec2 b = barycentrics(xy, p0, e1, e2);
    vec3 w = vec3(1.0 - b.x - b.y, b);
    v_position = p0 + b.x * e1 + b.y * e2;
    vec3 n0 = fetch_normal(i0), n1 = fetch_normal(i1), n2 = fetch_normal(i2);
    v_normal = u_normal_matrix * (w.x * n0 + w.y * n1 + w.z * n2);
    vec2 bc = barycentrics(xy + at_centroid, p0, e1, e2);
    vb_centroid_normal = u_normal_matrix * ((1.0 - bc.x - bc.y) * n0 + bc.x * n1 + bc.y * n2);
    vec2 t0 = fetch_uv(i0), t1 = fetch_uv(i1), t2 = fetch_uv(i2);
    v_uv = w.x * t0 + w.y * t1 + w.z * t2;
#ifdef READS_TANGENT
    vec4 tangent = w.x * fetch_tangent(i0) + w.y * fetch_tangent(i1) + w.z * fetch_tangent(i2);
    v_tangent = vec4(mat3(u_model) * tangent.xyz, tangent.w);
#else
    v_tangent = vec4(0.0);   // (read by nothing in this variant: common/mesh_material.glsl READS_TANGENT)
#endif
#ifdef HAS_VISIBILITY
    // As render/pbr.vert passes them on.
    v_visibility = w.x * visibility_data[2u * i0] + w.y * visibility_data[2u * i1] + w.z * visibility_data[2u * i2];
    v_visibility.xyz = u_normal_matrix * v_visibility.xyz;
    v_bounce = w.x * visibility_data[2u * i0 + 1u] + w.y * visibility_data[2u * i1 + 1u] + w.z * visibility_data[2u * i2 + 1u];
    vec3 bounce = u_normal_matrix * v_bounce.xyz;   // its length kept (pbr.vert)
    v_bounce.xyz = bounce * (length(v_bounce.xyz) / max(length(bounce), 1e-12));
    v_sun_bounce = w.x * sun_bounce_data[2u * i0] + w.y * sun_bounce_data[2u * i1] + w.z * sun_bounce_data[2u * i2];
    v_sun_bounce2 = w.x * sun_bounce_data[2u * i0 + 1u] + w.y * sun_bounce_data[2u * i1 + 1u]
                    + w.z * sun_bounce_data[2u * i2 + 1u];
    v_hit_albedo = w.x * hit_material_data[2u * i0] + w.y * hit_material_data[2u * i1] + w.z * hit_material_data[2u * i2];
    v_hit_emission = w.x * hit_material_data[2u * i0 + 1u] + w.y * hit_material_data[2u * i1 + 1u]
                     + w.z * hit_material_data[2u * i2 + 1u];
    v_baked_normal = v_normal;
#ifdef HAS_SKY_WEIGHT
    v_sky_weight = w.x * sky_weight_data[i0] + w.y * sky_weight_data[i1] + w.z * sky_weight_data[i2];
#endif
#endif
#if defined(HAS_UV1) && defined(UV1_AT)
    vec2 s0 = fetch2(i0, UV1_AT), s1 = fetch2(i1, UV1_AT), s2 = fetch2(i2, UV1_AT);
    v_uv1 = w.x * s0 + w.y * s1 + w.z * s2;
#elif defined(HAS_UV1)
    // A part without TEXCOORD_1 in a mesh whose maps read it (HAS_UV1 is the mesh's,
    // app/render/variants.py): its own maps read TEXCOORD_0 (u_map_uv1 is 0).
    v_uv1 = vec2(0.0);
#endif
#ifdef HAS_VERTEX_COLOR
    v_color = w.x * fetch4(i0, COLOR_AT) + w.y * fetch4(i1, COLOR_AT) + w.z * fetch4(i2, COLOR_AT);
#endif
    // Counter-clockwise on screen is front (the forward pass's front_face "ccw"): the winding's
    // normal faces the eye.
    vec3 face = normalize(cross(e1, e2));
    vb_front_facing = dot(face, u_camera_position - p0) > 0.0;
    vb_face_normal = vb_front_facing ? face : -face;
}

vec3 shade_here() {
#ifdef UNLIT
    return material_base_color().rgb;
#else
    vec3 n = shading_normal();
    vec3 v = normalize(u_camera_position - surface_position());
#ifdef HAS_SHADOWS
    set_shadow_receiver(surface_position(), geometric_normal());
#endif
#ifdef DEBUG_VIEW
    return debug_view(material_surface(n), n, v, surface_position());
#else
    return shade(material_surface(n), n, v, surface_position());
#endif
#endif
}

// Triangle ids travel between the block's pixels as floats: exact below 2^24
// (app/render/vbuffer.py MAX_TRIANGLES keeps larger parts on the forward pass).
const float NO_TRIANGLE = 16777215.0;

// The least of v over this pixel's 2x2 block: the neighbour across is v plus or minus the fine
// derivative (the right or upper pixel's value minus the left or lower's), exact for integers
// below 2^24. Every pixel of the block gets the same value.
float quad_min(float v) {
    float across = v + ((int(gl_FragCoord.x) & 1) == 0 ? dFdxFine(v) : -dFdxFine(v));
    float row = min(v, across);
    float other_row = row + ((int(gl_FragCoord.y) & 1) == 0 ? dFdyFine(row) : -dFdyFine(row));
    return min(row, other_row);
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    uvec2 ids[4];
    for (int i = 0; i < 4; ++i) ids[i] = texelFetch(u_visibility, p, i).xy;
    // This part's distinct triangles in the pixel, their sample counts and the centroids of
    // their samples; the pixel centre where one triangle holds all four.
    uint triangles[4];
    float weights[4];
    vec2 offsets[4];
    int count = 0;
    for (int i = 0; i < 4; ++i) {
        bool first = ids[i].y == u_part;
        for (int j = 0; j < i; ++j) first = first && ids[j] != ids[i];
        if (first) {
            float n = 0.0;
            vec2 sum = vec2(0.0);
            for (int j = i; j < 4; ++j) {
                bool same = ids[j] == ids[i];
                n += same ? 1.0 : 0.0;
                sum += same ? SAMPLE_OFFSETS[j] : vec2(0.0);
            }
            triangles[count] = ids[i].x - 1u;
            weights[count] = n;
            offsets[count] = sum / n;   // (0 where all four: the centre)
            ++count;
        }
    }
    // No discard before the loop: a pixel without this part still evaluates its block's
    // triangles, for the others' derivatives. A loop, not branches: llvmpipe runs both sides of
    // a branch, but ends a loop once no block of its vector needs another round (most: one).
    uint pending = (1u << uint(count)) - 1u;
    vec4 sum = vec4(0.0);
    // At most 16 rounds (4 pixels of 4 triangles): each round the pixel whose triangle it is
    // shades it, so one round fewer is left. (The bound only keeps a driver whose fine
    // derivatives are not, which the tests would show as wrong pictures, from looping forever.)
    for (int round = 0; round < 16; ++round) {
        // The block's least pending triangle; the same in all four pixels, so the loop's exit
        // and the derivatives inside it are uniform over the block.
        float mine = pending != 0u ? float(triangles[findLSB(pending)]) : NO_TRIANGLE;
        float shared_id = quad_min(mine);
        if (shared_id == NO_TRIANGLE) break;
        uint triangle = uint(shared_id);
        int k = -1;
        for (int i = 0; i < count; ++i) {
            if (((pending >> uint(i)) & 1u) != 0u && triangles[i] == triangle) k = i;
        }
        interpolate(triangle, gl_FragCoord.xy, k >= 0 ? offsets[k] : vec2(0.0));
        vec3 shaded = encode_output(shade_here(), 1.0).rgb;
        if (k >= 0) {
            sum += vec4(shaded, 1.0) * weights[k];
            pending &= ~(1u << uint(k));
        }
    }
    if (count == 0) discard;
    // The mean over the pixel's 4 samples (this part's share: the others add theirs), as the
    // MSAA resolve would take it; premultiplied by coverage in alpha.
    out_radiance = sum / 4.0;
}
