// Occlusion of the environment light and one diffuse bounce, from the per-vertex visibility bake
// (app/core/visibility.py; its numpy twins there: cone_aperture_cos, spherical_caps_intersection,
// specular_occlusion, combined_visibility, occluded_environment, visible_sky_radiance,
// visible_lobe_radiance; sky_visibility's in app/core/sky_weight.py). Compiled only with HAS_VISIBILITY, which app/render/visibility_parts.py
// sets for a mesh that was baked: every other mesh reads the glTF occlusion texture alone,
// exactly as before. HAS_SKY_WEIGHT (with it): the visible sky weight of the environment drawn
// (app/core/sky_weight.py) is in the vertices too.

// cos of the visibility cone's half-angle: a cone of half-angle a holds cosine-weighted
// visibility sin^2 a (Jimenez et al. 2016, "Practical Real-Time Strategies for Accurate Indirect
// Occlusion"), so cos a = sqrt(1 - V).
float cone_aperture_cos(float visibility) {
    return sqrt(clamp(1.0 - visibility, 0.0, 1.0));
}

// Solid angle / (2 pi) two caps share (Oat and Sander 2007), with the smoothstep of Jimenez et
// al. 2016 (as Filament's ambient_occlusion.fs sphericalCapsIntersection).
float spherical_caps_intersection(float cos_cap1, float cos_cap2, float cos_distance) {
    float r1 = acos(clamp(cos_cap1, -1.0, 1.0));
    float r2 = acos(clamp(cos_cap2, -1.0, 1.0));
    float d = acos(clamp(cos_distance, -1.0, 1.0));
    float small = 1.0 - max(cos_cap1, cos_cap2);
    if (min(r1, r2) <= max(r1, r2) - d) return small;
    if (r1 + r2 <= d) return 0.0;
    float delta = abs(r1 - r2);
    float x = 1.0 - clamp((d - delta) / max(r1 + r2 - delta, 1e-4), 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x) * small;
}

// The share of the specular lobe around direction r inside the visibility cone (Jimenez et al.
// 2016, cone-cone specular occlusion): the lobe's cone has cos(aperture) = 0.1^(alpha^2), the
// visibility cone's axis is the bent normal. Relative to what the open hemisphere of n passes
// (the cone of V = 1 around n), whose horizon the split sum already holds, so an unoccluded point
// keeps exactly its reflection; faded in over alpha 0.01..0.09 as Filament does, so a near-mirror
// is not switched off by a coarse cone. Arguments: bent.r, n.r, V, perceptual roughness.
float specular_occlusion(float bent_dot_r, float n_dot_r, float visibility, float roughness) {
    float alpha = roughness * roughness;
    float cos_as = exp2(-3.321928 * alpha * alpha);
    float inside = spherical_caps_intersection(cone_aperture_cos(visibility), cos_as, bent_dot_r);
    float open = spherical_caps_intersection(0.0, cos_as, n_dot_r);
    float so = clamp(inside / max(open, 1e-6), 0.0, 1.0);
    return mix(1.0, so, smoothstep(0.01, 0.09, alpha));
}
// The bent normal for a normal-mapped shading normal n. The bake knows the vertex normal only
// (its bent normal leans from it toward the open sky); taking the bent normal as it is would
// replace the normal map in the diffuse lookup (the relief of NormalTangentMirrorTest's tiles
// went flat, a bright ring on one). So its lean is added to n: an open point (bent = vertex
// normal) keeps n exactly, an occluded one leans from n as its vertex normal does. Arguments:
// unit n, bent normal and vertex normal, on one side.
vec3 mapped_bent_normal(vec3 n, vec3 bent, vec3 vertex_normal) {
    vec3 leaned = n + bent - vertex_normal;
    return dot(leaned, leaned) > 1e-8 ? normalize(leaned) : n;
}

// The mean visibility of what the occluded rays hit, w / (1 - V): at most 1. w (64 bounce rays)
// and V (192 rays) are counted by different rays, so where the bake saw almost nothing (V near
// 1) their noise made the ratio large, and with the occlusion texture darker there (min below)
// the occluders' radiance lit a bright ring (NormalTangentMirrorTest's top right tile).
float occluder_visibility(float bounce_weight, float baked_visibility) {
    return min(bounce_weight / max(1.0 - baked_visibility, 1e-3), 1.0);
}

// What the occluders reflect of E/pi: one bounce is albedo a times their visibility V_hit; the
// light they receive from their own occluders (further bounces) is summed as a geometric series,
// assuming those see as this point's occluders do (the assumption of Jimenez et al. 2016's
// multi-bounce fit): a V_hit / (1 - a (1 - V_hit)). The path tracer's walls of albedo 0.7 were
// ~8% brighter than one bounce.
vec3 occluders_reflectance(vec3 hit_albedo, float hit_visibility) {
    return hit_albedo * hit_visibility / max(1.0 - hit_albedo * (1.0 - hit_visibility), vec3(1e-3));
}

// The occluders' visible irradiance / pi (per unit V_hit), from the bake's mean of the hits' bent
// normals (visibility.py bake_visibility: each leaned by cone_lean, so mean_length is at most 1.5:
// near 1.5 where every hit sees a narrow patch of sky the same way, toward 0 where the hits'
// directions cancel, as on two facing partitions) and E/pi along the mean's direction (along)
// and against it (against). Under radiance linear in the direction, E's even part (along +
// against)/2 plus mean_length times its odd part (along - against)/2 is the mean over the hits
// exactly. E along the unit direction alone counted the hits on both sides of a bay as all
// facing its brighter side (EmissiveStrengthTest's lit patches beside each partition).
vec3 bounce_irradiance(float mean_length, vec3 along, vec3 against) {
    float k = clamp(mean_length, 0.0, 1.5);
    return max(0.5 * (1.0 + k) * along + 0.5 * (1.0 - k) * against, vec3(0.0));
}

// What the occluders shine of the suns' light (first: sum_k P_k B1_k, the suns' E/pi on them;
// second: sum_k P_k B2_k, what their own sunlit occluders pass them, over albedo; from the bake's
// bake_sun_bounce): a B1 + a^2 B2, the further bounces as the tail of the series above.
vec3 suns_on_occluders(vec3 hit_albedo, float hit_visibility, vec3 first, vec3 second) {
    return hit_albedo * first
           + hit_albedo * hit_albedo * second / max(1.0 - hit_albedo * (1.0 - hit_visibility), vec3(1e-3));
}

// The roughness whose prefiltered lobe is as wide as the visibility cone: the inverse of
// specular_occlusion's lobe aperture cos a = 0.1^(alpha^2), alpha = roughness^2, at the cone's
// cos a = sqrt(1 - V); at most 1.
float cone_roughness(float visibility) {
    float alpha2 = log(max(cone_aperture_cos(visibility), 1e-4)) / log(0.1);
    return min(sqrt(sqrt(alpha2)), 1.0);
}

// How much of the visible cone's mean radiance is taken as E(bent)/pi: 0 for a narrow cone (the
// prefiltered lobe), 1 for an open point (the hemisphere's cosine mean, exact there).
float cone_blend(float visibility) {
    return smoothstep(0.6, 0.95, visibility);
}

// The cosine-weighted mean radiance over the visibility cone (V of it is what reaches the
// point): E(bent)/pi means the whole hemisphere around the bent normal, which under a sky
// brighter at the horizon than overhead lit a bowl's floor, seeing only the sky overhead, 26-37%
// too bright (newport_loft, quarry_01, against the path tracer's direct light); the prefiltered
// radiance at cone_roughness is the mean over a lobe as wide as the cone.
vec3 visible_cone_radiance(vec3 bent, float visibility) {
    vec3 cone = prefiltered_radiance_at(bent, cone_roughness(visibility), false);
    return mix(cone, irradiance_at(bent, false), cone_blend(visibility));
}

// The combined visibility V made a per-channel share of the environment's light: the visible sky
// weight W (per channel: the share of the light the vertex's rays see) over those rays' V, times
// V, at most 1 (app/core/sky_weight.py). Under a uniform environment W = V_rays: V as before;
// under newport_loft a bowl's floor sees the dim ceiling, not the bright windows. V where the
// rays' V is 0.
vec3 sky_visibility(float visibility, vec3 sky, float ray_visibility) {
    vec3 ratio = ray_visibility > 1e-4 ? max(sky, vec3(0.0)) / ray_visibility : vec3(1.0);
    return min(visibility * ratio, vec3(1.0));
}

// The mean radiance of the sky the vertex's rays see, per channel: (W / V_rays) E(n)/pi (the
// visible sky weight's rays' sum of free L over their sum of free, times the hemisphere's cosine
// mean E(n)/pi); E(n)/pi where the rays' V is 0. Under a uniform environment it is E/pi.
vec3 visible_sky_radiance(vec3 sky, float ray_visibility, vec3 irradiance) {
    vec3 ratio = ray_visibility > 1e-4 ? max(sky, vec3(0.0)) / ray_visibility : vec3(1.0);
    return ratio * irradiance;
}

// The radiance the visible part of the specular lobe brings (HAS_SKY_WEIGHT): the share so of the
// lobe is visible (specular_occlusion), and its radiance is the prefiltered radiance at the
// lobe's middle only where the whole lobe is (so = 1); as less of it is, it moves toward the mean
// radiance of the sky the point sees (visible_sky_radiance), by so^2. The prefiltered fetch holds
// the blocked part's light too: inside the bowl under newport_loft the windows near the horizon
// the walls hide (the gold bowl r 0.6 35.0% -> 21.7% against the path tracer); under
// royal_esplanade a rough metal's floor sees the bright sky overhead, brighter than its lobe's
// middle (gold r 0.9 34.5% -> 15.9%; benchmarks/results/occlusion-metals.md). Under a uniform
// environment: so times it, as before.
vec3 visible_lobe_radiance(vec3 prefiltered, vec3 visible_sky, float so) {
    return so * mix(visible_sky, prefiltered, so * so);
}

#ifdef HAS_VISIBILITY
#ifdef VBUFFER_SHADING
// Shaded from the visibility buffer: globals render/vbuffer_shade.frag fills from the bake's
// per-vertex buffers (the other varyings: common/mesh_material.glsl).
#define VISIBILITY_IN
#else
#define VISIBILITY_IN in
#endif
VISIBILITY_IN vec4 v_visibility;   // bent normal (xyz, interpolated: normalise), cosine-weighted visibility V
VISIBILITY_IN vec4 v_bounce;       // the hits' mean bent normal (xyz, length <= 1.5: bounce_irradiance), weight w
VISIBILITY_IN vec3 v_baked_normal; // the vertex normal the bake cast about (v_normal, under its own name)
VISIBILITY_IN vec4 v_sun_bounce;   // per sun k: B1_k, the occluders' shadowed max(n.l_k, 0)/pi (bake_sun_bounce)
VISIBILITY_IN vec4 v_sun_bounce2;  // per sun k: B2_k, what their sunlit occluders pass them
VISIBILITY_IN vec4 v_hit_albedo;   // what the bounce rays hit: its recorded albedo (rgb, times w), 1 where a ray hit (w)
VISIBILITY_IN vec4 v_hit_emission; // ... and the radiance it emits (rgb): bake_occluder_materials
#ifdef HAS_SKY_WEIGHT
VISIBILITY_IN vec4 v_sky_weight;   // the visible sky weight W (rgb) and its rays' V (w): app/core/sky_weight.py
#endif

// sum_k P_k B_k over the suns, for B = v_sun_bounce (second: v_sun_bounce2). Clamped at 0: a
// multisampled pixel's centre may lie outside its triangle, where the interpolation runs on
// past a vertex (a steep B beside a shadow's edge went negative: black specks on the helmet).
vec3 suns_weighted(vec4 per_sun) {
    vec3 e = vec3(0.0);
    for (int i = 0; i < u_sun_count; ++i) e += u_sun_power[i] * max(per_sun[i], 0.0);
    return e;
}

// The baked values at this fragment, or none (V = 1) where the shading normal n faces away from
// the side that was baked (an open mesh seen from behind: its bent normal lies in the front
// hemisphere).
bool baked_side(vec3 n) {
    return dot(n, v_visibility.xyz) > 0.0;
}

vec3 bent_normal(vec3 n) {
    if (!baked_side(n)) return n;
    vec3 bent = normalize(v_visibility.xyz);
    vec3 vertex_normal = normalize(v_baked_normal);
    return mapped_bent_normal(n, bent, dot(vertex_normal, bent) < 0.0 ? -vertex_normal : vertex_normal);
}

// The diffuse visibility with the glTF occlusion texture (s.occlusion): the smaller of the two,
// not the product. The texture is this mesh's own baked AO, so the same crease would otherwise
// be darkened twice; the minimum keeps the texture's finer detail where it is darker. Clamped to
// [0, 1]: the texture's strength (1 + strength (texel - 1)) takes it below 0 past strength 1.
float combined_visibility(Surface s, vec3 n) {
    return clamp(min(baked_side(n) ? v_visibility.w : 1.0, s.occlusion), 0.0, 1.0);
}

#endif

// The environment's light as the mesh lets it through (HAS_VISIBILITY; else unchanged), given
// the split sum's E/pi at n (irradiance) and its prefiltered radiance around r, and the
// surface's specular albedo (the split sum's weight on the prefiltered radiance).
// What the occluded directions see instead of the sky is the mesh: its radiance, one bounce, is
// hit albedo * (w / (1 - V)) * the hits' E/pi (bounce_irradiance), the hit's albedo as the bake
// recorded it (recorded_occluder_albedo; this surface's where it has none: diffuse plus specular, a rough
// metal's walls light each other too), plus the radiance the hits emit.
// Plus the suns' light on the occluders (in their own shadows, baked: suns_on_occluders).
// Diffuse: V times the visible cone's radiance (visible_cone_radiance) + (1 - V) times that; specular: the prefiltered radiance for the share of
// the lobe inside the visibility cone (specular_occlusion), the mesh's radiance for the rest.
// The compact sources' direct light (with_suns) stays unoccluded here (shadows are theirs).
#ifdef HAS_SCREEN_AO
#include "common/gtao.glsl"
// Screen-space GTAO (app/render/screen_ao.py): the cosine-weighted visibility at this pixel, from
// the depth of the opaque parts drawn this frame.
uniform sampler2D u_screen_ao;
// The occluders' face normals, each turned toward this pixel and weighted by the share of it
// that it hides (xyz), and the weights' sum (w): render/gtao.frag.
uniform sampler2D u_screen_ao_occluders;

// As combined_visibility: the smaller of GTAO's and the glTF occlusion texture's (the texture is
// the mesh's own baked AO: a product would darken the same crease twice), clamped to [0, 1].
float screen_visibility(Surface s) {
    return clamp(min(texelFetch(u_screen_ao, ivec2(gl_FragCoord.xy), 0).a, s.occlusion), 0.0, 1.0);
}

// The mean occluded direction (GTAO's sum of them, normalised); -n where nothing is occluded.
vec3 screen_occluded_direction(vec3 n) {
    vec3 o = texelFetch(u_screen_ao, ivec2(gl_FragCoord.xy), 0).xyz;
    return dot(o, o) > 1e-12 ? normalize(o) : -n;
}

// The sky's light the pixel sees (E/pi, without the suns), as what the occluders around it
// receive per unit V (occlude_environment): E(n)/pi less the hidden part's, taken as the radiance
// of a cone of cosine-weighted share 1 - V about the mean occluded direction
// (visible_cone_radiance; Jimenez et al. 2016's cone model of the occluded solid angle).
vec3 screen_visible_irradiance(vec3 n, float visibility) {
    vec3 hidden = visible_cone_radiance(screen_occluded_direction(n), 1.0 - visibility);
    return max(irradiance_at(n, false) - (1.0 - visibility) * hidden, vec3(0.0));
}

#ifdef GTAO_OCCLUDERS
// The occluders' light / pi (the sky's and the suns', per unit V) as this point's own: the sky
// it sees per unit V (screen_visible_irradiance: Jimenez et al. 2016's multi-bounce assumption,
// that the occluders see as the point does) and the suns on surfaces facing back along d
// (unshadowed: the occluders' own shadows are not known here).
vec3 screen_light_as_point(vec3 n, float visibility) {
    return screen_visible_irradiance(n, visibility) / max(visibility, 1e-3)
           + suns_irradiance_over_pi(-screen_occluded_direction(n));
}

// The occluders that face the point on screen (render/gtao.frag horizon_cos): their share of the
// occluded directions (x, 0..1) and their own mean V (y); the direction of their mean normal in
// `along` (their bent normals where the pass had earlier passes of the view), n where none.
vec2 screen_facing_occluders(vec3 n, float visibility, out vec3 along) {
    vec4 o = texelFetch(u_screen_ao_occluders, ivec2(gl_FragCoord.xy), 0);
    vec3 mean = o.w > 1e-4 ? o.xyz / o.w : vec3(0.0);
    float length_mean = length(mean);
    along = length_mean > 1e-4 ? mean / length_mean : n;
    return vec2(clamp(o.w / max(1.0 - visibility, 1e-3), 0.0, 1.0), min(length_mean, 1.0));
}

// The facing occluders' light / pi per unit V: the sky they see by their own normals (the
// visible cone's radiance about their mean, of their V: a corner's floor sees the sky overhead,
// the shader ball's bowl underside the dark ground) and the suns on them (unshadowed).
vec3 screen_light_by_occluders(vec3 along, float occluder_visibility) {
    return visible_cone_radiance(along, occluder_visibility) + suns_irradiance_over_pi(along);
}

// Where the facing occluders see no more of the sky than the point (their V below its V, ramped
// in over GTAO_FACING_RAMP_LOW..HIGH: app/core/gtao.py FACING_RAMP; the numpy twin facing_light),
// no more light than the point's own (as_point): they stand in the same
// enclosure, so their normals' open hemisphere overstates what reaches them (the shader ball's
// base under the bowl, facing up at its neck: 1.5x the path tracer's light on the neck, brighter
// than --occlusion off). Where they see more (a corner's floor beside its wall) their own light.
vec3 screen_facing_light(vec3 by_occluders, vec3 as_point, float occluder_visibility, float visibility) {
    return gtao_facing_light(by_occluders, as_point, occluder_visibility, visibility,
                             vec2(GTAO_FACING_RAMP_LOW, GTAO_FACING_RAMP_HIGH));
}

// What the occluded share sees / pi (occlude_environment's GTAO_OCCLUDERS; numpy twin
// app/core/gtao.py occluder_radiance): the occluders'
// radiance, this surface's albedo through the bake's series (occluders_reflectance) over the
// light on them; the share that faces the point on screen lit by the occluders' own normals and
// V (screen_facing_light), the rest (faces the screen does not hold) as the point is.
vec3 screen_occluder_radiance(vec3 albedo, vec3 n, float visibility) {
    vec3 along;
    vec2 facing = screen_facing_occluders(n, visibility, along);
    vec3 as_point = screen_light_as_point(n, visibility);
    vec3 lit = screen_facing_light(screen_light_by_occluders(along, facing.y), as_point, facing.y, visibility);
    return mix(occluders_reflectance(albedo, visibility) * as_point, occluders_reflectance(albedo, facing.y) * lit,
               facing.x);
}
#endif

// The bent normal (the mean unoccluded direction): the whole hemisphere's cosine-weighted sum
// of directions is 2/3 n in GTAO's measure, so the visible ones sum to 2/3 n minus the occluded
// sum (app/core/gtao.py bent_normal). n where open or where the sum leaves n's hemisphere.
vec3 screen_bent_normal(vec3 n) {
    vec3 b = (2.0 / 3.0) * n - texelFetch(u_screen_ao, ivec2(gl_FragCoord.xy), 0).xyz;
    return dot(b, n) > 1e-6 ? normalize(b) : n;
}
#endif

// The occluders' albedo as the bake takes it: this surface's (one material per scene), the
// diffuse lobe weighted by 1 - F (docs/conventions.md) plus the specular albedo.
vec3 occluder_albedo(Surface s, vec3 specular_albedo) {
    return min(s.base_color * (1.0 - s.metallic) * (1.0 - specular_albedo) + specular_albedo, vec3(1.0));
}

// The albedo an occluder's material is recorded with in the bake (app/core/visibility.py
// bake_occluder_materials, which calls this function's numpy twin): the diffuse lobe weighted by
// 1 - F0 plus F0, F0 = mix(specular_f0, base, metallic): the split sum's specular albedo at normal
// incidence with A + B = 1, one rule with no view for every hit.
vec3 occluder_base_albedo(vec3 base_color, float metallic, vec3 specular_f0) {
    vec3 f0 = mix(specular_f0, base_color, metallic);
    return min(base_color * (1.0 - metallic) * (1.0 - f0) + f0, vec3(1.0));
}

// The occluders' albedo from what the bake recorded of the surfaces its bounce rays hit (hit, by
// occluder_base_albedo), times how this surface's own albedo (own: occluder_albedo's, with the
// view's Fresnel) departs from that rule at this surface (own_recorded), one ratio of the
// channels' sums (a per-channel one would tint the hit with this surface's colour). Where the
// hits are this surface's material it is its own albedo as before (exactly for a grey one);
// beside a red part, red: the grey box no longer lends its albedo to the red arrows on it.
vec3 recorded_occluder_albedo(vec3 own, vec3 own_recorded, vec3 hit) {
    float ratio = (own.r + own.g + own.b) / max(own_recorded.r + own_recorded.g + own_recorded.b, 1e-4);
    return min(hit * ratio, vec3(1.0));
}

#if defined(HAS_VISIBILITY) || defined(HAS_SCREEN_AO)
// What the occluded directions send this point (the occluders' bounce and the suns on them),
// which occlude_environment works out for the base; the layers' lobes above it (clearcoat_ibl,
// sheen_ibl) see the same surroundings, and the base's IBL always runs before layered_ibl, so
// they read it here instead of fetching the bounce's irradiance again.
vec3 g_occluder_radiance = vec3(0.0);
#endif

void occlude_environment(Surface s, vec3 n, vec3 r, vec3 specular_albedo, bool with_suns,
                         inout vec3 irradiance, inout vec3 prefiltered) {
#ifdef HAS_VISIBILITY
    bool baked = baked_side(n);
    float visibility = combined_visibility(s, n);
    float baked_visibility = baked ? v_visibility.w : 1.0;
    vec3 bent = bent_normal(n);
    vec3 occluder = vec3(0.0);
    if (baked) {
        vec3 hit_albedo = occluder_albedo(s, specular_albedo);
        // What the bounce rays hit, by its material (bake_occluder_materials; w 0 where no ray hit
        // or the pass has not run: this surface's own albedo then). rgb is 0 at such a vertex, so
        // rgb / w is the mean over the triangle's vertices that have it.
        if (v_hit_albedo.w > 1e-3) {
            hit_albedo = recorded_occluder_albedo(hit_albedo, occluder_base_albedo(s.base_color, s.metallic, s.specular_f0),
                                                  v_hit_albedo.rgb / v_hit_albedo.w);
        }
        float hit_visibility = occluder_visibility(v_bounce.w, baked_visibility);
        if (v_bounce.w > 0.0) {
            float mean_length = length(v_bounce.xyz);
            vec3 along = mean_length > 1e-6 ? v_bounce.xyz / mean_length : n;
            occluder = occluders_reflectance(hit_albedo, hit_visibility)
                       * bounce_irradiance(mean_length, irradiance_at(along, false), irradiance_at(-along, false));
        }
        // The compact sources on the occluders, which E above (the map without them) leaves out.
        occluder += suns_on_occluders(hit_albedo, hit_visibility, suns_weighted(v_sun_bounce),
                                      suns_weighted(v_sun_bounce2));
        // What the occluders emit (the mean over the rays that hit; the occluded share 1 - V
        // multiplies it below, as the bounce): an emissive part lights its neighbours.
        occluder += max(v_hit_emission.rgb, vec3(0.0));
    }
#ifdef HAS_SKY_WEIGHT
    // The visible sky's light: the share W / V_rays of the irradiance at n (the map without its
    // suns) that the vertex's rays see, per channel (sky_visibility). The occluded share of the
    // directions, 1 - V, still sees the occluders.
    vec3 sky = baked ? sky_visibility(visibility, v_sky_weight.rgb, v_sky_weight.w) : vec3(visibility);
    vec3 irradiance_n = irradiance_at(n, false);
    irradiance = sky * irradiance_n + (1.0 - visibility) * occluder;
#else
    irradiance = visibility * visible_cone_radiance(bent, visibility) + (1.0 - visibility) * occluder;
#endif
    if (with_suns) irradiance += suns_irradiance_over_pi(n);
    float so = specular_occlusion(dot(bent, r), dot(n, r), visibility, s.roughness);
#ifdef HAS_SKY_WEIGHT
    // The visible part of the lobe as the sky the point sees (visible_lobe_radiance); the blocked
    // part, 1 - so, sees the occluders as before.
    vec3 visible_sky = baked ? visible_sky_radiance(v_sky_weight.rgb, v_sky_weight.w, irradiance_n) : prefiltered;
    prefiltered = visible_lobe_radiance(prefiltered, visible_sky, so) + (1.0 - so) * occluder;
#else
    prefiltered = so * prefiltered + (1.0 - so) * occluder;
#endif
    g_occluder_radiance = occluder;
#elif defined(HAS_SCREEN_AO)
    // GTAO's V and mean occluded direction d. GTAO_OCCLUDERS, the bake's terms: the visible share
    // sees the visible cone's radiance about the bent normal (visible_cone_radiance: a bowl's floor
    // sees the bright sky overhead, not the map's dark ground), the occluded share the occluders'
    // radiance as the bake's bounce does (screen_occluder_radiance): the occluders the screen
    // shows facing the point lit by the sky their own normals see (a corner's floor, under the
    // sky, lights its walls), held to the point's own light where they see no more sky than it
    // does; the rest lit as the point is (Jimenez et al. 2016's multi-bounce assumption). Lit by
    // E(-d)/pi for all (surfaces facing back along d, open to the sky), the occluders under the
    // shader ball's bowl and in its groove, which see little of it, shone: rings brighter than
    // --occlusion off on the neck (up to 1.56x at 384 px under royal_esplanade); lit as the point
    // for all, the corner's walls missed the floor's light (benchmarks/results/gtao.md).
    // Else V scales E(n)/pi, with the paper's multi-bounce fit where GTAO_MULTI_BOUNCE.
    // The specular lobe keeps its share inside the visibility cone about the bent normal (n
    // without GTAO_OCCLUDERS; specular_occlusion, the bake's cone-cone term), the rest sees the
    // occluders (black without GTAO_OCCLUDERS).
    float visibility = screen_visibility(s);
    vec3 occluder = vec3(0.0);
    vec3 bent = n;
#if defined(GTAO_OCCLUDERS)
    occluder = screen_occluder_radiance(occluder_albedo(s, specular_albedo), n, visibility);
    bent = screen_bent_normal(n);
    irradiance = visibility * visible_cone_radiance(bent, visibility) + (1.0 - visibility) * occluder;
#elif defined(GTAO_MULTI_BOUNCE)
    irradiance = gtao_multi_bounce(visibility, s.base_color * (1.0 - s.metallic)) * irradiance_at(n, false);
#else
    irradiance = visibility * irradiance_at(n, false);
#endif
    if (with_suns) irradiance += suns_irradiance_over_pi(n);
    float so = specular_occlusion(dot(bent, r), dot(n, r), visibility, s.roughness);
    prefiltered = so * prefiltered + (1.0 - so) * occluder;
    g_occluder_radiance = occluder;
#endif
}

// A layer's lobe over the base (the clearcoat's about its normal n, the sheen's) under the same
// occlusion as the base's specular: the share so of the lobe of roughness `roughness` around d
// that falls inside the visibility cone sees the prefiltered radiance, the rest the occluders
// (Jimenez et al. 2016's cone-cone specular occlusion, as occlude_environment). Without it a
// coat inside a crevice reflected the whole sky (ibl_outer_occlusion is 1 under a bake).
vec3 occluded_layer_radiance(Surface s, vec3 n, vec3 d, float roughness, vec3 prefiltered) {
#ifdef HAS_VISIBILITY
    float so = specular_occlusion(dot(bent_normal(n), d), dot(n, d), combined_visibility(s, n), roughness);
    return so * prefiltered + (1.0 - so) * g_occluder_radiance;
#elif defined(HAS_SCREEN_AO)
#ifdef GTAO_OCCLUDERS
    vec3 bent = screen_bent_normal(n);
#else
    vec3 bent = n;
#endif
    float so = specular_occlusion(dot(bent, d), dot(n, d), screen_visibility(s), roughness);
    return so * prefiltered + (1.0 - so) * g_occluder_radiance;
#else
    return prefiltered;
#endif
}

// What multiplies the whole IBL result (layers too): the occlusion texture alone without a bake;
// with one it is already in the base's terms above.
float ibl_outer_occlusion(Surface s) {
#if defined(HAS_VISIBILITY) || defined(HAS_SCREEN_AO)
    return 1.0;
#else
    return s.occlusion;
#endif
}
