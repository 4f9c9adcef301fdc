// Shadow maps for the punctual lights and the compact sources taken out of the environment
// (app/render/shadows.py draws them into one depth atlas; app/core/shadow_fit.py places them).
// Compiled in only with HAS_SHADOWS: a scene that cannot shadow itself pays nothing.
//
// Filtering: percentage-closer filtering (Reeves et al. 1987) with the hardware's bilinear
// comparison per tap over a few taps of Vogel's spiral disk; where the source has a size (a sun's angular
// radius), percentage-closer soft shadows (Fernando 2005): a blocker search gives the mean
// occluder depth, and the penumbra's width follows from similar triangles.
// Bias: the receiver is moved along its geometric normal by a texel's size (normal offset,
// Holbert 2011), and each tap compares against the receiver's plane at that tap, from the same
// normal (receiver plane depth bias, Isidoro 2006, without screen derivatives), so tilted flat
// faces show no acne and contacts no gap.
#ifdef HAS_SHADOWS

const int MAX_SHADOW_VIEWS = 16;     // app/render/shadows.py MAX_SHADOW_VIEWS
const int SHADOW_MAX_LIGHTS = 16;    // punctual.glsl's MAX_LIGHTS
const int SHADOW_MAX_SUNS = 4;       // suns.glsl's MAX_SUNS
const float SHADOW_MAX_SLOPE = 8.0;  // the receiver plane's depth slope is clamped (grazing faces)
const float SHADOW_MAX_RADIUS = 24.0;   // texels: the widest kernel 16 taps still cover

uniform sampler2DShadow u_shadow_atlas;  // depth with comparison (ref <= stored: lit)
uniform sampler2D u_shadow_depth;        // the same depth, read as values (the blocker search)
uniform vec2 u_shadow_atlas_size;        // texels
uniform mat4 u_shadow_matrix[MAX_SHADOW_VIEWS];   // world -> the view's clip space (shadow_fit.py)
uniform vec4 u_shadow_rect[MAX_SHADOW_VIEWS];     // the view's tile in atlas uv: min xy, max xy
// kind (0 orthographic, 1 perspective), texel (world size; at unit distance for perspective),
// source (tan of the angular radius; radius in world units for perspective), unused
uniform vec4 u_shadow_params[MAX_SHADOW_VIEWS];
uniform vec2 u_shadow_range[MAX_SHADOW_VIEWS];    // near, far (world units along the view)
uniform int u_light_shadow[SHADOW_MAX_LIGHTS];    // each light's first view; -1: not shadowed
uniform int u_sun_shadow[SHADOW_MAX_SUNS];        // each compact source's view; -1: not shadowed

// The shaded point and its geometric normal (pbr.frag sets them before shading).
vec3 shadow_receiver_position;
vec3 shadow_receiver_normal;

void set_shadow_receiver(vec3 position, vec3 geometric_normal) {
    shadow_receiver_position = position;
    shadow_receiver_normal = geometric_normal;
}

// Taps on the unit disk: Vogel's spiral (golden-angle steps, radius sqrt((k + 0.5) / n)), even at
// any n (app/core/shadow_fit.py vogel_disk prints them; tests/test_shadows.py checks both forms).
const vec2 SHADOW_TAPS_4[4] = vec2[](
    vec2(0.353553, 0.000000), vec2(-0.451544, 0.413652), vec2(0.069116, -0.787542),
    vec2(0.569142, 0.742346));
// The soft shadows' 8 and 12 taps are walked, not read from tables: a constant array indexed by
// a loop's counter cost llvmpipe about as much as the loops' taps, at every pixel, even where the
// loop ran no iteration (benchmarks/results/sun_shadow_cost.md). Each step turns the direction
// by the golden angle; tap k of n lies at radius sqrt((k + 0.5) / n), as in the tables.
const vec2 SHADOW_GOLDEN_TURN = vec2(-0.737369, 0.675490);   // cos, sin of 2.39996323

vec2 shadow_turn(vec2 d) {
    return vec2(d.x * SHADOW_GOLDEN_TURN.x - d.y * SHADOW_GOLDEN_TURN.y,
                d.x * SHADOW_GOLDEN_TURN.y + d.y * SHADOW_GOLDEN_TURN.x);
}

// World distance along the view from a depth in [0, 1], and back.
float shadow_linear_depth(int view, float z) {
    vec2 r = u_shadow_range[view];
    if (u_shadow_params[view].x < 0.5) return r.x + z * (r.y - r.x);
    float ndc = z * 2.0 - 1.0;
    return 2.0 * r.x * r.y / (r.y + r.x - ndc * (r.y - r.x));
}

float shadow_depth01(int view, float linear) {
    vec2 r = u_shadow_range[view];
    if (u_shadow_params[view].x < 0.5) return (linear - r.x) / (r.y - r.x);
    float ndc = (r.y + r.x - 2.0 * r.x * r.y / max(linear, 1e-6)) / (r.y - r.x);
    return ndc * 0.5 + 0.5;
}

// Where a receiver meets a view's map: its atlas uv, its depth along the view (world units),
// the receiver plane's depth change per texel (x, y), the bias, the tile's clamp and a texel's size.
struct ShadowLookup {
    bool inside;
    vec2 uv;
    float receiver;
    vec2 slope;
    float bias;
    vec2 lo, hi;
    float texel;
};

ShadowLookup shadow_lookup(int view, vec3 l) {
    ShadowLookup look;
    vec3 n = shadow_receiver_normal;
    if (dot(n, l) < 0.0) n = -n;        // a two-sided face lit from behind
    float n_dot_l = max(dot(n, l), 1e-3);
    mat4 m = u_shadow_matrix[view];
    vec4 clip = m * vec4(shadow_receiver_position, 1.0);
    // clip.w: 1 (orthographic) or the distance along the view (perspective)
    look.texel = u_shadow_params[view].y * max(clip.w, 0.0);
    float sin_l = sqrt(max(1.0 - n_dot_l * n_dot_l, 0.0));
    vec3 p = shadow_receiver_position + n * look.texel * (0.5 + 1.5 * sin_l);
    clip = m * vec4(p, 1.0);
    vec3 ndc = clip.xyz / max(clip.w, 1e-12);
    // Outside the map (or behind a perspective view's eye) nothing casts.
    look.inside = clip.w > 0.0 && all(lessThanEqual(abs(ndc), vec3(1.0)));
    vec4 rect = u_shadow_rect[view];
    look.uv = mix(rect.xy, rect.zw, ndc.xy * 0.5 + 0.5);
    look.receiver = shadow_linear_depth(view, ndc.z * 0.5 + 0.5);
    // The receiver's plane in the view's texel axes: depth change per texel along x and y.
    vec3 axis_x = normalize(vec3(m[0][0], m[1][0], m[2][0]));
    vec3 axis_y = normalize(vec3(m[0][1], m[1][1], m[2][1]));
    vec2 slope = clamp(vec2(dot(n, axis_x), dot(n, axis_y)) / n_dot_l, -SHADOW_MAX_SLOPE, SHADOW_MAX_SLOPE);
    look.slope = slope * look.texel;
    look.bias = look.texel * (0.5 + min(length(slope), SHADOW_MAX_SLOPE));
    vec2 texel_uv = 1.0 / u_shadow_atlas_size;
    look.lo = rect.xy + texel_uv;
    look.hi = rect.zw - texel_uv;
    return look;
}

// The comparison at offset o (texels) from the receiver against its plane there, bilinear.
float shadow_tap_lit(int view, ShadowLookup look, vec2 o) {
    vec2 uv = clamp(look.uv + o / u_shadow_atlas_size, look.lo, look.hi);
    return texture(u_shadow_atlas, vec3(uv, shadow_depth01(view, look.receiver + dot(look.slope, o) - look.bias)));
}

// A delta light (no size): 4 bilinear taps within a texel, an edge 2-3 texels wide.
float shadow_hard(int view, vec3 l) {
    ShadowLookup look = shadow_lookup(view, l);
    if (!look.inside) return 1.0;
    float lit = 0.0;
    for (int k = 0; k < 4; ++k) lit += shadow_tap_lit(view, look, SHADOW_TAPS_4[k]);
    return lit * 0.25;
}

// A source of angular (orthographic) or world (perspective) radius u_shadow_params[view].z: PCSS.
// ``wanted`` false: the caller multiplies the result by 0, so no tap is taken (it returns 1).
float shadow_soft(int view, vec3 l, bool wanted) {
    ShadowLookup look = shadow_lookup(view, l);
    // Loops with counts that a block of pixels may share as 0 (outside the map, no blocker,
    // not wanted): llvmpipe runs both sides of a branch, but leaves a loop once no pixel of a
    // block is in it.
    int searches = look.inside && wanted ? 8 : 0;
    vec4 params = u_shadow_params[view];
    float near = u_shadow_range[view].x;
    bool ortho = params.x < 0.5;
    // Blocker search over the region that could hide part of the source.
    float reach = ortho ? (look.receiver - near) * params.z : params.z * (look.receiver - near) / look.receiver;
    float search = clamp(reach / look.texel, 1.0, SHADOW_MAX_RADIUS);
    float blockers = 0.0, count = 0.0;
    vec2 dir = vec2(1.0, 0.0);
    for (int k = 0; k < searches; ++k) {
        vec2 o = dir * (sqrt((float(k) + 0.5) / 8.0) * search);
        dir = shadow_turn(dir);
        vec2 uv = clamp(look.uv + o / u_shadow_atlas_size, look.lo, look.hi);
        float stored = shadow_linear_depth(view, textureLod(u_shadow_depth, uv, 0.0).r);
        bool blocks = stored < look.receiver + dot(look.slope, o) - look.bias;
        blockers += blocks ? stored : 0.0;
        count += blocks ? 1.0 : 0.0;
    }
    float blocker = blockers / max(count, 1.0);
    float penumbra = ortho ? (look.receiver - blocker) * params.z
                           : params.z * (look.receiver - blocker) / max(blocker, 1e-6);
    float radius = clamp(penumbra / look.texel, 1.0, SHADOW_MAX_RADIUS);
    int taps = count > 0.0 ? 12 : 0;
    float lit = 0.0;
    dir = vec2(1.0, 0.0);
    for (int k = 0; k < taps; ++k) {
        lit += shadow_tap_lit(view, look, dir * (sqrt((float(k) + 0.5) / 12.0) * radius));
        dir = shadow_turn(dir);
    }
    return count > 0.0 ? lit / 12.0 : 1.0;
}

// Light i of punctual.glsl's block: its view (a point light's by the cube face the receiver
// lies on, app/core/shadow_fit.py CUBE_FACES), or 1 where it has none.
float light_shadow(int i, int kind, vec3 l, vec3 light_position) {
    int first = u_light_shadow[i];
    if (first < 0) return 1.0;
    if (kind == 0) {
        vec3 v = shadow_receiver_position - light_position;
        vec3 a = abs(v);
        int axis = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
        first += 2 * axis + (v[axis] >= 0.0 ? 0 : 1);
    }
    return shadow_hard(first, l);      // punctual lights have no size
}

// ``wanted``: whether the caller reads the result (false: 1, no tap taken; shadow_soft).
float sun_shadow_where(int i, vec3 l, bool wanted) {
    int view = u_sun_shadow[i];
    return view < 0 ? 1.0 : shadow_soft(view, l, wanted);
}

float sun_shadow(int i, vec3 l) {
    return sun_shadow_where(i, l, true);
}

#endif
