// Shadow maps for the punctual lights and the compact sources taken out of the environment
// (app/render/shadows.py draws them into one depth atlas; app/core/shadow_fit.py places them).
// Compiled in only with HAS_SHADOWS: a scene that cannot shadow itself pays nothing.
//
// Filtering: percentage-closer filtering (Reeves et al. 1987) with the hardware's bilinear
// comparison per tap over a 16-tap Poisson disk; where the source has a size (a sun's angular
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

const vec2 SHADOW_POISSON[16] = vec2[](
    vec2(-0.94201624, -0.39906216), vec2(0.94558609, -0.76890725), vec2(-0.09418410, -0.92938870),
    vec2(0.34495938, 0.29387760), vec2(-0.91588581, 0.45771432), vec2(-0.81544232, -0.87912464),
    vec2(-0.38277543, 0.27676845), vec2(0.97484398, 0.75648379), vec2(0.44323325, -0.97511554),
    vec2(0.53742981, -0.47373420), vec2(-0.26496911, -0.41893023), vec2(0.79197514, 0.19090188),
    vec2(-0.24188840, 0.99706507), vec2(-0.81409955, 0.91437590), vec2(0.19984126, 0.78641367),
    vec2(0.14383161, -0.14100790));

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

// The fraction of light ``l`` (unit, toward the light) that reaches the receiver through
// ``view``'s map: 1 lit, 0 in shadow.
float shadow_visibility(int view, vec3 l) {
    vec3 n = shadow_receiver_normal;
    if (dot(n, l) < 0.0) n = -n;        // a two-sided face lit from behind
    float n_dot_l = max(dot(n, l), 1e-3);
    mat4 m = u_shadow_matrix[view];
    vec4 params = u_shadow_params[view];
    vec4 clip = m * vec4(shadow_receiver_position, 1.0);
    // clip.w: 1 (orthographic) or the distance along the view (perspective)
    float texel = params.y * max(clip.w, 0.0);
    float sin_l = sqrt(max(1.0 - n_dot_l * n_dot_l, 0.0));
    vec3 p = shadow_receiver_position + n * texel * (0.5 + 1.5 * sin_l);
    clip = m * vec4(p, 1.0);
    if (clip.w <= 0.0) return 1.0;
    vec3 ndc = clip.xyz / clip.w;
    if (any(greaterThan(abs(ndc), vec3(1.0)))) return 1.0;    // outside the map: nothing casts there
    vec4 rect = u_shadow_rect[view];
    vec3 c = vec3(mix(rect.xy, rect.zw, ndc.xy * 0.5 + 0.5), ndc.z * 0.5 + 0.5);
    float receiver = shadow_linear_depth(view, c.z);
    // The receiver's plane in the view's texel axes: depth change per texel along x and y.
    vec3 axis_x = normalize(vec3(m[0][0], m[1][0], m[2][0]));
    vec3 axis_y = normalize(vec3(m[0][1], m[1][1], m[2][1]));
    vec2 slope = clamp(vec2(dot(n, axis_x), dot(n, axis_y)) / n_dot_l, -SHADOW_MAX_SLOPE, SHADOW_MAX_SLOPE) * texel;
    float bias = texel * (0.5 + min(length(slope) / max(texel, 1e-12), SHADOW_MAX_SLOPE));
    vec2 texel_uv = 1.0 / u_shadow_atlas_size;
    vec2 lo = rect.xy + texel_uv, hi = rect.zw - texel_uv;

    float radius = 1.0;      // texels: the delta light's edge, anti-aliased
    if (params.z > 0.0) {
        // Blocker search over the region that could hide part of the source.
        float reach = params.x < 0.5 ? (receiver - u_shadow_range[view].x) * params.z
                                     : params.z * (receiver - u_shadow_range[view].x) / receiver;
        float search = clamp(reach / texel, 1.0, SHADOW_MAX_RADIUS);
        float blockers = 0.0, count = 0.0;
        for (int k = 0; k < 16; ++k) {
            vec2 o = SHADOW_POISSON[k] * search;
            vec2 uv = clamp(c.xy + o * texel_uv, lo, hi);
            float stored = shadow_linear_depth(view, textureLod(u_shadow_depth, uv, 0.0).r);
            if (stored < receiver + dot(slope, o) - bias) {
                blockers += stored;
                count += 1.0;
            }
        }
        if (count == 0.0) return 1.0;
        float blocker = blockers / count;
        float penumbra = params.x < 0.5 ? (receiver - blocker) * params.z
                                        : params.z * (receiver - blocker) / max(blocker, 1e-6);
        radius = clamp(penumbra / texel, 1.0, SHADOW_MAX_RADIUS);
    }
    float lit = 0.0;
    for (int k = 0; k < 16; ++k) {
        vec2 o = SHADOW_POISSON[k] * radius;
        vec2 uv = clamp(c.xy + o * texel_uv, lo, hi);
        float ref = shadow_depth01(view, receiver + dot(slope, o) - bias);
        lit += texture(u_shadow_atlas, vec3(uv, ref));
    }
    return lit / 16.0;
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
    return shadow_visibility(first, l);
}

float sun_shadow(int i, vec3 l) {
    int view = u_sun_shadow[i];
    return view < 0 ? 1.0 : shadow_visibility(view, l);
}

#endif
