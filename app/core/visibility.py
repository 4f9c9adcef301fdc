"""Per-vertex visibility for still previews: ambient occlusion, bent normals and one diffuse bounce.

For every vertex of a mesh part, cosine-weighted rays over the hemisphere of its normal are cast
against the whole mesh with Intel Embree (``embreex``; 2-core figures in docs/explanation/occlusion.md). Each
vertex gets
- ``visibility`` V: the cosine-weighted unoccluded fraction, (1/pi) * integral of V(l) (n.l) dl,
  the ambient occlusion of the diffuse term;
- ``bent_normal``: the mean unoccluded direction; with V it is the visibility cone of Jimenez et
  al. 2016 ("Practical Real-Time Strategies for Accurate Indirect Occlusion"): a cone around the
  bent normal holding cosine-weighted visibility V has cos(aperture) = sqrt(1 - V);
- ``bounce``: one diffuse inter-reflection. A ray that hits the mesh sees the hit point's diffuse
  radiance, albedo times the hit's visible irradiance / pi (one bounce). Its mean over all rays
  is stored as (direction, weight): ``bounce_weight`` = mean of V_hit over all rays (0 for the
  unoccluded ones) and ``bounce_direction`` = the V_hit-weighted mean of bent_hit, each leaned by
  ``cone_lean`` (a narrow visibility cone's free directions reach further along its bent normal
  than an open hemisphere's), not normalised: its length says how much the hits agree. The
  occluders' radiance is then hit albedo * w / (1 - V) times ``bounce_irradiance`` of it, E/pi
  along the mean's direction and against it mixed by its length: exact under radiance linear in
  the direction (the hits' V and bent normal standing for their visible sky), and close elsewhere
  since E/pi is smooth (its first two SH bands are linear in the direction). It replaces the sky
  in the occluded directions of both the diffuse and the specular lobe. The hit's albedo and
  emission are recorded by a pass of their own (``bake_occluder_materials``, keyed by the parts'
  materials too); where it recorded none the shading point's albedo stands in, diffuse plus
  specular.
- the suns' bounce (``bake_sun_bounce``, a second pass keyed by the suns' directions too): what
  the occluders receive from each compact source of the environment (app/ibl/sun.py), which the
  bounce above leaves out (E there is the map without its suns). For every bounce ray that hits,
  a shadow ray from the hit point toward sun k gives the hit's own visibility of it; the vertex
  keeps, per sun, that light's mean over its hitting rays (B1) and the same for the light the
  hits get from their own sunlit occluders (B2, from B1 at the hits: no more rays), so the
  occluders' radiance is sum_k P_k (a B1_k + a^2 B2_k + ...) (P_k the sun's power: the shader's
  u_sun_power, so the environment's intensity needs no new pass).

A per-vertex bake needs vertices where the occlusion changes, and no more (llvmpipe pays per
small triangle): the part's edges are split to a coarse size first, then again where V changes
across them (``bake_visibility``), every attribute interpolated linearly, which the rasteriser does
anyway, so the picture without occlusion is unchanged. Baked once per mesh content and settings and cached like the
IBL bake (alight.render.visibility_parts.cached_visibility). Convex meshes cannot occlude themselves (``self_occludes``): they pay nothing.

The visible sky weight (app/core/sky_weight.py) is a pass of its own after the bake, per
environment: the share of the environment's *light* each vertex sees, per channel, which the
shader takes in place of V's share of directions for the diffuse term (HAS_SKY_WEIGHT).

The shader side is shaders/common/occlusion.glsl; its numpy twins are ``cone_aperture_cos``,
``spherical_caps_intersection``, ``specular_occlusion``, ``combined_visibility``, ``cone_roughness``,
``cone_blend``, ``suns_on_occluders``, ``sky_visibility``, ``occluder_base_albedo``,
``recorded_occluder_albedo`` and ``occluded_environment`` here (tests/test_occlusion.py,
test_occlusion_cone.py, test_occlusion_suns.py and test_occlusion_materials.py hold them equal).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import time
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from alight.core.mesh import single_sided
from alight.errors import AlightError

# Bake settings (all in the cache key).
DEFAULT_RAYS = 192            # rays per vertex: V's noise is about sqrt(V(1-V)/N) <= 0.036
DEFAULT_BOUNCE_RAYS = 64      # rays per vertex for the bounce (a smooth mean: fewer suffice)
DEFAULT_COARSE_FRACTION = 1.0 / 12.0  # first, edges split to this times the bounding-box diagonal
DEFAULT_EDGE_FRACTION = 1.0 / 48.0    # then where V changes, down to this
DEFAULT_THRESHOLD = 0.1               # ... by more than this across an edge
DEFAULT_MAX_VERTICES = 400_000        # refinement stops growing a mesh past this
MAX_LEVELS = 3                        # adaptive levels at most (each halves the split edges)
# welded: copies of a vertex further than this from their mean normal stay apart. The copies that
# must share (a file repeating a vertex per face, its normals made per copy) are a degree or two
# apart; an asset's split normals are an authored hard edge (DamagedHelmet's: 20-60 degrees apart),
# and at 30 degrees its copies were merged: V from one side's hemisphere with the sun pass's B1 of
# the other's own hits lit specks (the helmet under spot1Lux 6.2 -> 12.2% against the path tracer).
WELD_CREASE_DEG = 10.0
BAKE_VERSION = 11  # 3: ray origins kept in front of their own faces; 4: splits kept where interpolation misses;
                   # 5: vertices covered by a part take their open neighbours' values;
                   # 6: a vertex's copies share V, the bent normal and the bounce (_copies_averaged);
                   # 7, 8: single-sided parts let light through from their back (_cast's one_way; 8: a
                   # stopped ray reports the first surface it met); 9: WELD_CREASE_DEG 30 -> 10;
                   # 10, 11: bounce_direction the hits' mean bent normal unnormalised, leaned (bounce_irradiance)
# A ray goes on past at most this many single-sided faces met from the front (_cast's one_way).
ONE_WAY_PASSES = 4
# Refinement keeps a split only where the midpoint's value is not the edge's linear interpolation.
INTERPOLATION_TEST = True
# A vertex at least this share of whose rays hit a part from its inside, or hit one closer than
# COVERED_DISTANCE times the finest edge, lies inside or under another part, unseen: it takes its
# open neighbours' values (_fill_covered). Inside a closed part every ray hits its inside.
COVERED_SHARE = 0.9
COVERED_DISTANCE = 0.25
OCCLUSION_MODES = ("auto", "on", "off", "gtao")   # gtao: screen space, no bake (alight.render.screen_ao)
# --occlusion auto: bake where the mesh's mean occlusion (occlusion_statistic) is above this.
AUTO_MIN_OCCLUSION = 0.03
AUTO_SAMPLES = 1024           # surface points of the statistic
AUTO_RAYS = 32                # rays per point
# 'auto' draws a mesh over AUTO_MAX_VERTICES that would need occlusion with screen-space GTAO
# instead of none (benchmarks/results/gtao.md: its cost and error against the path tracer).
AUTO_SCREEN_AO = True
AUTO_MAX_VERTICES = 250_000   # auto bakes no bigger mesh (MetalRoughSpheresNoTextures' 1M triangles: 97 s)
# A bigger mesh's statistic, for its warning only, is taken on a copy merged to a grid of this
# many cells along its longest side (occlusion_estimate).
AUTO_ESTIMATE_CELLS = 64


@dataclass
class PartVisibility:
    """One part's refined geometry (world space, as MeshPart's fields) and its per-vertex
    visibility: ``visibility`` (N,) in [0, 1]; ``bent_normal`` (N, 3) unit; ``bounce_direction``
    (N, 3) the hits' mean bent normal, leaned, of length at most 1.5 (``bounce_irradiance``);
    ``bounce_weight`` (N,) in [0, 1]."""

    positions: np.ndarray
    normals: np.ndarray
    uvs: np.ndarray
    tangents: np.ndarray
    indices: np.ndarray
    uvs1: np.ndarray | None
    colors: np.ndarray | None
    visibility: np.ndarray
    bent_normal: np.ndarray
    bounce_direction: np.ndarray
    bounce_weight: np.ndarray
    one_way: bool = False     # the part is single-sided (alight.core.mesh.single_sided; not cached)

    def vertex_data(self) -> np.ndarray:
        """(N, 8) float32: bent normal and V, bounce direction and weight (pbr.vert's
        in_visibility, in_bounce)."""
        return np.ascontiguousarray(np.column_stack([self.bent_normal, self.visibility,
                                                     self.bounce_direction, self.bounce_weight]), np.float32)


@dataclass
class MeshVisibility:
    parts: list[PartVisibility]
    seconds: float = 0.0          # the bake's wall time (0 when loaded from the cache)
    rays: int = 0
    from_cache: bool = False


# ---- the shader's terms (numpy twins of shaders/common/occlusion.glsl) -------------------------

def cone_aperture_cos(visibility):
    """cos of the visibility cone's half-angle: a cone of half-angle a around the bent normal has
    cosine-weighted visibility sin^2 a (Jimenez et al. 2016, section 5), so cos a = sqrt(1 - V)."""
    return np.sqrt(np.clip(1.0 - np.asarray(visibility, np.float64), 0.0, 1.0))


def spherical_caps_intersection(cos_cap1, cos_cap2, cos_distance):
    """Solid angle / (2 pi) shared by two spherical caps (Oat and Sander 2007, "Ambient Aperture
    Lighting"), with the smoothstep approximation Jimenez et al. 2016 use (as Filament's
    ambient_occlusion.fs)."""
    c1, c2, cd = (np.asarray(x, np.float64) for x in (cos_cap1, cos_cap2, cos_distance))
    r1 = np.arccos(np.clip(c1, -1.0, 1.0))
    r2 = np.arccos(np.clip(c2, -1.0, 1.0))
    d = np.arccos(np.clip(cd, -1.0, 1.0))
    small = 1.0 - np.maximum(c1, c2)
    delta = np.abs(r1 - r2)
    x = 1.0 - np.clip((d - delta) / np.maximum(r1 + r2 - delta, 1e-4), 0.0, 1.0)
    area = x * x * (3.0 - 2.0 * x) * small
    return np.where(np.minimum(r1, r2) <= np.maximum(r1, r2) - d, small, np.where(r1 + r2 <= d, 0.0, area))


def specular_occlusion(bent_dot_r, n_dot_r, visibility, roughness):
    """The share of the specular lobe inside the visibility cone (Jimenez et al. 2016, "specular
    occlusion" by cone-cone intersection): the lobe as a cone around the reflected direction r with
    cos(aperture) = 0.1^(alpha^2) (alpha = roughness^2, their fit to GGX), the visibility cone
    around the bent normal as ``cone_aperture_cos``. Divided by what the open hemisphere of n
    (V = 1) passes, since the split sum already holds the horizon: an unoccluded point keeps its
    whole reflection. Faded in over alpha 0.01..0.09 as Filament does, so a near-mirror is not
    switched off by a coarse cone. Arguments: bent.r, n.r, V, perceptual roughness (broadcast)."""
    alpha = np.asarray(roughness, np.float64) ** 2
    cos_as = np.exp2(-3.321928 * alpha * alpha)
    inside = spherical_caps_intersection(cone_aperture_cos(visibility), cos_as, bent_dot_r)
    open_ = spherical_caps_intersection(0.0, cos_as, n_dot_r)
    so = np.clip(inside / np.maximum(open_, 1e-6), 0.0, 1.0)
    t = np.clip((alpha - 0.01) / 0.08, 0.0, 1.0)
    return 1.0 + (so - 1.0) * t * t * (3.0 - 2.0 * t)


def cone_roughness(visibility):
    """The perceptual roughness whose prefiltered lobe is as wide as the visibility cone: the
    inverse of ``specular_occlusion``'s lobe aperture cos a = 0.1^(alpha^2) (alpha = roughness^2)
    at the cone's cos a = sqrt(1 - V) (``cone_aperture_cos``); at most 1."""
    alpha2 = np.log(np.maximum(cone_aperture_cos(visibility), 1e-4)) / math.log(0.1)
    return np.minimum(np.sqrt(np.sqrt(alpha2)), 1.0)


def cone_blend(visibility):
    """The weight of E(bent)/pi against the prefiltered radiance in the visible cone's mean
    radiance: smoothstep(0.6, 0.95, V): 1 at an open point (exact there), 0 for a narrow cone."""
    t = np.clip((np.asarray(visibility, np.float64) - 0.6) / 0.35, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def mapped_bent_normal(n, bent, vertex_normal):
    """The bent normal for a normal-mapped shading normal ``n`` (all (N, 3) unit, one side): the
    bake's lean of the bent normal from the vertex normal, added to n, so an open point keeps n
    (and the normal map's relief) exactly."""
    leaned = np.asarray(n, np.float64) + np.asarray(bent, np.float64) - np.asarray(vertex_normal, np.float64)
    length = np.linalg.norm(leaned, axis=-1, keepdims=True)
    return np.where(length > 1e-4, leaned / np.maximum(length, 1e-30), n)


def combined_visibility(visibility, occlusion_texture):
    """The diffuse visibility with a glTF occlusion texture: the smaller of the two. Both estimate
    the same quantity for the same geometry (the texture is this mesh's own baked AO), so
    multiplying would darken a crease twice; the minimum keeps the texture's finer detail where it
    is darker and the ray-traced value where the texture misses an occluder (another part).
    Clamped to [0, 1]: the texture's strength, 1 + strength (texel - 1), goes below 0 past 1."""
    return np.clip(np.minimum(np.asarray(visibility, np.float64), np.asarray(occlusion_texture, np.float64)),
                   0.0, 1.0)


def occluder_visibility(bounce_weight, baked_visibility):
    """The mean visibility of what the occluded rays hit, w / (1 - V), at most 1: w and V are
    counted by different rays, whose noise made the ratio large where V is near 1."""
    return np.minimum(np.asarray(bounce_weight, np.float64)
                      / np.maximum(1.0 - np.asarray(baked_visibility, np.float64), 1e-3), 1.0)


def occluders_reflectance(hit_albedo, hit_visibility):
    """What the occluders reflect of E/pi, every bounce: one bounce is a V_hit, the further ones a
    geometric series assuming the occluders' occluders see alike (as Jimenez et al. 2016's
    multi-bounce fit assumes): a V_hit / (1 - a (1 - V_hit)). hit_albedo (3,) or (N, 3),
    hit_visibility (N,); returns (N, 3)."""
    a = np.asarray(hit_albedo, np.float64)
    v = np.asarray(hit_visibility, np.float64)[..., None]
    return a * v / np.maximum(1.0 - a * (1.0 - v), 1e-3)


def bounce_irradiance(mean_length, along, against):
    """The occluders' visible E/pi per unit V_hit (GLSL ``bounce_irradiance``): E's even part
    (along + against)/2 plus the bake's mean bent normal's length (``bounce_direction``'s, the
    hits leaned by ``cone_lean``: at most 1.5) times its odd part (along - against)/2, along and
    against E/pi at the mean's direction and opposite it; at least 0. Exact for the mean of
    E(bent_hit) where E/pi is linear in the direction (its first two SH bands). mean_length (N,),
    along and against (N, 3) or (3,); returns (N, 3)."""
    k = np.clip(np.asarray(mean_length, np.float64), 0.0, 1.5)[..., None]
    along, against = (np.asarray(e, np.float64) for e in (along, against))
    return np.maximum(0.5 * (1.0 + k) * along + 0.5 * (1.0 - k) * against, 0.0)


def cone_lean(visibility):
    """How far the mean free direction of a point with cosine-weighted visibility V reaches along
    its bent normal, over an open point's 2/3: the cosine-weighted mean of cos over a cone of
    cos(aperture) c = sqrt(1 - V) (the visibility cone) is (2/3)(1 + c + c^2)/(1 + c), so this is
    (1 + c + c^2)/(1 + c): 1 open, 3/2 for a narrow cone. A hit's E_vis/pi under radiance linear in
    the direction, L0 + L1.l, is V L0 + L1.(its mean free direction times V); its E(bent)/pi, L0
    + (2/3) L1.bent, took only 2/3 of the odd part for a hit that sees a narrow patch of sky
    (a bowl's wall seeing the bright zenith)."""
    c = np.sqrt(np.clip(1.0 - np.asarray(visibility, np.float64), 0.0, 1.0))
    return (1.0 + c + c * c) / (1.0 + c)


def suns_on_occluders(hit_albedo, hit_visibility, first, second):
    """What the occluders shine of the suns' light, per unit power: a B1 (direct on them) + a^2 B2
    (from their own sunlit occluders), the further bounces as the tail of the same geometric
    series as ``occluders_reflectance``: a B1 + a^2 B2 / (1 - a (1 - V_hit)). hit_albedo (3,) or
    (N, 3), hit_visibility (N,), first and second (N,) or (N, 3) (sum_k P_k B_k); returns (N, 3)."""
    a = np.asarray(hit_albedo, np.float64)
    v = np.asarray(hit_visibility, np.float64)[..., None]
    b1, b2 = (np.asarray(b, np.float64) for b in (first, second))
    b1 = b1[..., None] if b1.ndim == 1 else b1
    b2 = b2[..., None] if b2.ndim == 1 else b2
    return a * b1 + a * a * b2 / np.maximum(1.0 - a * (1.0 - v), 1e-3)


def occluder_base_albedo(base_color, metallic, specular_f0=0.04):
    """The albedo an occluder's material is recorded with (``bake_occluder_materials``): its
    diffuse lobe weighted by 1 - F0 plus F0 (the split sum's specular albedo at normal incidence
    with A + B = 1), F0 = mix(specular_f0, base colour, metallic) (docs/conventions.md). One rule
    for every hit, with no view: the shader's own albedo (``occluder_albedo``) holds the view's
    Fresnel, which ``recorded_occluder_albedo`` carries over. base_color (..., 3), metallic (...),
    specular_f0 scalar or (..., 3); returns (..., 3), at most 1."""
    base = np.asarray(base_color, np.float64)
    m = np.asarray(metallic, np.float64)[..., None]
    f0 = np.asarray(specular_f0, np.float64)
    f0 = f0 + (base - f0) * m
    return np.minimum(base * (1.0 - m) * (1.0 - f0) + f0, 1.0)


def recorded_occluder_albedo(own_albedo, own_recorded, hit_recorded):
    """occlusion.glsl's recorded_occluder_albedo: the occluders' albedo from what the bake recorded
    of the surfaces its bounce rays hit (``hit_recorded``, (N, 3), ``occluder_base_albedo``'s rule),
    times how this surface's own albedo in the shader (``own_albedo``, occluder_albedo's: with the
    view's Fresnel) departs from the same rule at this surface (``own_recorded``), one ratio over
    the channels' sums (grey: a coloured ratio would tint the hit by this surface's colour). So
    where the hits are this surface's material the result is its own albedo as before (exactly for
    a grey one); beside a red part it is red. At most 1."""
    own = np.asarray(own_albedo, np.float64)
    ratio = own.sum(axis=-1) / np.maximum(np.asarray(own_recorded, np.float64).sum(axis=-1), 1e-4)
    return np.minimum(np.asarray(hit_recorded, np.float64) * ratio[..., None], 1.0)

def sky_visibility(visibility, sky, ray_visibility):
    """occlusion.glsl's sky_visibility: the combined V (N,) made a per-channel share of the light,
    min(V W / V_rays, 1) (N, 3), W (N, 3) and V_rays (N,) the visible sky weight's
    (alight.core.sky_weight.sky_weight); V where V_rays is 0 (no ray escaped anywhere near)."""
    v = np.asarray(visibility, np.float64)[..., None]
    rv = np.asarray(ray_visibility, np.float64)[..., None]
    ratio = np.where(rv > 1e-4, np.asarray(sky, np.float64) / np.maximum(rv, 1e-4), 1.0)
    return np.minimum(v * ratio, 1.0)


def visible_sky_radiance(sky, ray_visibility, irradiance):
    """occlusion.glsl's visible_sky_radiance: the mean radiance of the sky the vertex's rays see,
    (W / V_rays) E(n)/pi per channel (N, 3), from the visible sky weight W (N, 3), its rays' V
    (N,) and E/pi at the shading normal (N, 3); E(n)/pi where V_rays is 0."""
    rv = np.asarray(ray_visibility, np.float64)[..., None]
    ratio = np.where(rv > 1e-4, np.maximum(np.asarray(sky, np.float64), 0.0) / np.maximum(rv, 1e-4), 1.0)
    return ratio * np.asarray(irradiance, np.float64)


def visible_lobe_radiance(prefiltered, visible_sky, so):
    """occlusion.glsl's visible_lobe_radiance: the radiance the visible share ``so`` (N,) of the
    specular lobe brings, so (visible_sky + (prefiltered - visible_sky) so^2) (N, 3): the
    prefiltered radiance at the lobe's middle where the whole lobe is visible, the mean radiance
    of the sky the point sees (``visible_sky_radiance``) as less of it is."""
    so = np.asarray(so, np.float64)[..., None]
    sky = np.asarray(visible_sky, np.float64)
    return so * (sky + (np.asarray(prefiltered, np.float64) - sky) * (so * so))


def occluded_environment(visibility, baked_visibility, bounce_weight, irradiance_bent, irradiance_bounce,
                         hit_albedo, so, prefiltered, sun_first=None, sun_second=None, cone_radiance=None,
                         sky=None, hit_emission=None):
    """occlusion.glsl's occlude_environment: (E/pi reaching the diffuse lobe, the prefiltered
    radiance), from the combined V, the baked V, the bounce weight w (N,), E/pi at the bent normal
    and the hits' E/pi (``bounce_irradiance`` of the bounce direction) (N, 3), the hit's albedo
    (3,) or (N, 3), the specular occlusion (N,) and the prefiltered radiance (N, 3). The
    occluders' radiance is hit albedo * min(w / (1 - V_baked), 1) * that, plus, with
    ``sun_first`` and ``sun_second`` (N, 3) (sum_k P_k B1_k and B2_k of bake_sun_bounce),
    ``suns_on_occluders``.
    ``cone_radiance`` (N, 3): the prefiltered radiance at the bent normal and ``cone_roughness``
    (default: irradiance_bent, as a uniform environment has it); what V multiplies is its mix with
    E(bent)/pi by ``cone_blend`` (occlusion.glsl's visible_cone_radiance). ``sky``: (W (N, 3),
    the rays' V (N,), E/pi at the shading normal (N, 3)) of the visible sky weight
    (HAS_SKY_WEIGHT, app/core/sky_weight.py): the visible part is then
    sky_visibility(V, W, V_rays) E(n)/pi instead of V times the cone's radiance, and the visible
    part of the specular lobe visible_lobe_radiance(prefiltered, visible_sky_radiance(W, V_rays,
    E(n)/pi), so) instead of so times the prefiltered radiance. ``hit_emission`` (N, 3): the mean
    radiance the occluders emit (``bake_occluder_materials``), added to their radiance."""
    v = np.asarray(visibility, np.float64)[..., None]
    albedo = np.minimum(hit_albedo, 1.0)
    hit_visibility = occluder_visibility(bounce_weight, baked_visibility)
    occluder = occluders_reflectance(albedo, hit_visibility) * irradiance_bounce
    if sun_first is not None:
        occluder = occluder + suns_on_occluders(albedo, hit_visibility, sun_first, sun_second)
    if hit_emission is not None:
        occluder = occluder + np.asarray(hit_emission, np.float64)
    so = np.asarray(so, np.float64)[..., None]
    bent = np.asarray(irradiance_bent, np.float64)
    cone = bent if cone_radiance is None else np.asarray(cone_radiance, np.float64)
    blend = cone_blend(visibility)[..., None]
    visible = cone + (bent - cone) * blend
    specular = so * prefiltered
    if sky is not None:
        w, ray_visibility, irradiance_n = sky
        diffuse = sky_visibility(visibility, w, ray_visibility) * np.asarray(irradiance_n, np.float64)
        specular = visible_lobe_radiance(prefiltered, visible_sky_radiance(w, ray_visibility, irradiance_n), so[..., 0])
    else:
        diffuse = v * visible
    return diffuse + (1.0 - v) * occluder, specular + (1.0 - so) * occluder


# ---- which meshes need it -----------------------------------------------------------------------

def self_occludes(parts, faces: int = 2000, vertices: int = 20000, tolerance: float = 1e-4) -> bool:
    """Whether a face of the mesh can see another part of it: some vertex lies in front of some
    face's plane (by more than ``tolerance`` times the mesh's size). False for a convex mesh and a
    flat one, whose faces see only the sky. Up to ``faces`` faces against up to ``vertices``
    vertices (seeded samples beyond those counts, for big meshes)."""
    if sum(len(p.positions) for p in parts) < 4:
        return False
    lo = np.min([np.asarray(p.positions).min(axis=0) for p in parts if len(p.positions)], axis=0)
    hi = np.max([np.asarray(p.positions).max(axis=0) for p in parts if len(p.positions)], axis=0)
    size = float(np.linalg.norm(hi.astype(np.float64) - lo)) or 1.0
    rng = np.random.default_rng(0)
    counts = [len(p.indices) for p in parts]
    total = sum(counts)
    # A big mesh's sample is drawn among its faces before any per-face array is made: the
    # (T, 3, 3) corners of a 4M-triangle mesh were 0.8 GiB and seconds of work for 2000 faces.
    # (A degenerate face drawn is dropped, so the sample can come out a little short.)
    pick = np.sort(rng.choice(total, faces, replace=False)) if total > faces else None
    centroids, normals = [], []
    start = 0
    for p, count in zip(parts, counts):
        rows = np.asarray(p.indices).reshape(-1, 3)
        if pick is not None:
            rows = rows[pick[(pick >= start) & (pick < start + count)] - start]
        start += count
        tri = np.asarray(p.positions)[rows.astype(np.int64)].astype(np.float64)
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        length = np.linalg.norm(n, axis=1)
        keep = length > 1e-12 * size * size
        centroids.append(tri[keep].mean(axis=1))
        normals.append(n[keep] / length[keep, None])
    centroids = np.concatenate(centroids)
    normals = np.concatenate(normals)
    # The vertices likewise: only the sample becomes float64.
    sizes = np.cumsum([0] + [len(p.positions) for p in parts])
    chosen = np.sort(rng.choice(sizes[-1], vertices, replace=False)) if sizes[-1] > vertices else np.arange(sizes[-1])
    positions = np.concatenate([np.asarray(p.positions)[chosen[(chosen >= a) & (chosen < b)] - a]
                                for p, a, b in zip(parts, sizes[:-1], sizes[1:])]).astype(np.float64)
    for start in range(0, len(centroids), 64):
        c, n = centroids[start:start + 64], normals[start:start + 64]
        offset = np.einsum("ij,ij->i", c, n)
        ahead = positions @ n.T - offset                  # (V, C): > 0 in front of the face
        if (ahead > tolerance * size).any():
            return True
    return False


def occlusion_statistic(parts, samples: int = AUTO_SAMPLES, rays: int = AUTO_RAYS, seed: int = 0) -> float:
    """The mesh's mean ambient occlusion, 1 - V averaged over its surface by area: ``samples``
    points drawn by area (seeded), ``rays`` cosine-weighted rays each about the face normal, against
    the whole mesh (Embree). 0 for a convex or flat mesh (nothing is cast then: ``self_occludes``);
    about 0.2 for the corner scene. Its error is about sqrt(O(1 - O) / (samples rays)), < 0.003."""
    if not self_occludes(parts):
        return 0.0
    triangles = np.concatenate([np.asarray(p.positions, np.float64)[np.asarray(p.indices, np.int64)]
                                for p in parts])
    cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    if area.sum() <= 0.0:
        return 0.0
    one_way = np.concatenate([np.full(len(np.asarray(p.indices).reshape(-1, 3)), single_sided(p)) for p in parts])
    occluders = _Occluders(triangles, one_way=one_way)
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(triangles), samples, p=area / area.sum())
    a, b = rng.random(samples), rng.random(samples)
    flip = a + b > 1.0
    a, b = np.where(flip, 1.0 - a, a), np.where(flip, 1.0 - b, b)
    t = triangles[pick]
    points = t[:, 0] + a[:, None] * (t[:, 1] - t[:, 0]) + b[:, None] * (t[:, 2] - t[:, 0])
    lo, hi = triangles.reshape(-1, 3).min(axis=0), triangles.reshape(-1, 3).max(axis=0)
    eps = eps_of(float(np.linalg.norm(hi - lo)) or 1.0)
    normals = occluders.normals[pick].astype(np.float64)
    # The side the mesh's normals say is outside (a mirrored node or clockwise winding would
    # otherwise cast into the body), as the bake casts about the vertex normals.
    vertex_normals = np.concatenate([np.asarray(p.normals, np.float64)[np.asarray(p.indices, np.int64)].sum(axis=1)
                                     for p in parts])[pick]
    normals *= np.where(np.einsum("ij,ij->i", normals, vertex_normals) < 0.0, -1.0, 1.0)[:, None]
    hit, _, _ = occluders.hemisphere((points + eps * normals).astype(np.float32), normals.astype(np.float32),
                                     rays, rng, eps)
    return float((hit >= 0).mean())


def wants_occlusion(mesh, mode: str) -> bool:
    """``mode`` 'on': bake unless the mesh is the built-in sphere; 'off': never; 'auto': where
    the mesh occludes enough of its own surface to matter (``occlusion_statistic`` above
    AUTO_MIN_OCCLUSION; convex and flat meshes are decided without a ray)."""
    if mode not in OCCLUSION_MODES:
        raise AlightError(f"--occlusion: '{mode}' is not one of {', '.join(OCCLUSION_MODES)}")
    if mode in ("off", "gtao") or mesh is None or mesh.lod_sphere is not None:
        return False    # (gtao: screen_occlusion)
    if mode == "on":
        return True
    if not embree_available():
        return self_occludes(mesh.parts)    # the caller says it draws without (visibility_parts)
    if auto_too_big(mesh):
        # Not baked either way (the caller says so where it is wanted): the statistic on a coarse
        # copy, so the warning comes only for a mesh that would need it. self_occludes here was
        # true for nearly every big mesh (a scan's noise, a bump of 1e-4 of its size).
        return occlusion_estimate(mesh.parts) > AUTO_MIN_OCCLUSION
    return occlusion_statistic(mesh.parts) > AUTO_MIN_OCCLUSION


def screen_occlusion(mesh, mode: str, baked_wanted: bool = False) -> bool:
    """Whether ``mesh`` is drawn with screen-space GTAO (alight.render.screen_ao): under 'gtao'
    (never the built-in sphere, which is convex), and under 'auto' where the bake is wanted
    (``baked_wanted``: ``wants_occlusion``) but the mesh is too big for auto to bake
    (``auto_too_big``; AUTO_SCREEN_AO, measured in benchmarks/results/gtao.md)."""
    if mesh is None or mesh.lod_sphere is not None:
        return False
    if mode == "gtao":
        return True
    return mode == "auto" and AUTO_SCREEN_AO and baked_wanted and auto_too_big(mesh)


def occlusion_estimate(parts, cells: int = AUTO_ESTIMATE_CELLS) -> float:
    """``occlusion_statistic`` of a big mesh, on a coarse copy of it (``clustered``: its vertices
    merged per cell of a grid of ``cells`` along its bounding box's longest side): what would
    occlude a point by more than a cell's size is kept, bumps and noise smaller than a cell are
    flattened. A hole or gap narrower than a cell closes, so a finely perforated mesh reads as
    more occluded than it is (the estimate errs toward "would need occlusion").

    Measured (2 cores, llvmpipe machine, 1.3M-1.4M triangles): 0.0 on an icosphere and on the
    same sphere with bumps of 0.2% of its radius (occlusion_statistic on the full mesh: 0.0 in
    2.6 s and 13.8 s), 0.81 on an open box with a cube inside (full: 0.82 in 7.0 s), in about
    0.5-0.9 s. Used by ``wants_occlusion`` only for meshes --occlusion auto does not bake."""
    coarse = clustered(parts, cells)
    return occlusion_statistic([coarse]) if len(coarse.indices) else 0.0


def clustered(parts, cells: int = AUTO_ESTIMATE_CELLS) -> SimpleNamespace:
    """The mesh's parts as one coarse part (positions, normals, indices), its vertices merged per
    cell of a grid of ``cells`` along its bounding box's longest side (vertex clustering,
    Rossignac and Borrel 1993), each merged vertex at its cell's mean position, its normal the
    sum of theirs (occlusion_statistic reads only its side). Triangles that collapse (two
    corners in one cell) are dropped, repeated ones kept once; connectivity is kept, so no holes
    open. Vectorised: a 1.3M-triangle mesh in about 0.3 s."""
    positions = [np.asarray(p.positions, np.float64).reshape(-1, 3) for p in parts]
    sizes = np.cumsum([0] + [len(x) for x in positions])
    empty = SimpleNamespace(positions=np.zeros((0, 3)), normals=np.zeros((0, 3)), indices=np.zeros((0, 3), np.int64))
    if sizes[-1] == 0:
        return empty
    points = np.concatenate(positions)
    normals = np.concatenate([np.asarray(p.normals, np.float64).reshape(-1, 3) for p in parts])
    indices = np.concatenate([np.asarray(p.indices, np.int64).reshape(-1, 3) + start
                              for p, start in zip(parts, sizes[:-1])])
    lo, hi = points.min(axis=0), points.max(axis=0)
    step = float((hi - lo).max()) / cells or 1.0
    cell = np.minimum(((points - lo) / step).astype(np.int64), cells)
    key = (cell[:, 0] * (cells + 1) + cell[:, 1]) * (cells + 1) + cell[:, 2]
    _, merged = np.unique(key, return_inverse=True)
    merged = merged.ravel()
    count = int(merged.max()) + 1
    weight = np.bincount(merged, minlength=count).astype(np.float64)
    mean = np.stack([np.bincount(merged, points[:, k], count) for k in range(3)], axis=1) / weight[:, None]
    normal = np.stack([np.bincount(merged, normals[:, k], count) for k in range(3)], axis=1)
    tri = merged[indices]
    tri = tri[(tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])]
    if not len(tri):
        return empty
    _, first = np.unique(np.sort(tri, axis=1), axis=0, return_index=True)
    return SimpleNamespace(positions=mean, normals=normal, indices=tri[np.sort(first)])


def auto_too_big(mesh) -> bool:
    """Whether 'auto' leaves the mesh unbaked for its size (more than AUTO_MAX_VERTICES vertices)."""
    return sum(len(p.positions) for p in mesh.parts) > AUTO_MAX_VERTICES


# ---- refinement ----------------------------------------------------------------------------------

def _attributes(part) -> list[np.ndarray]:
    cols = [part.positions, part.normals, part.uvs, part.tangents]
    if part.uvs1 is not None:
        cols.append(part.uvs1)
    if part.colors is not None:
        cols.append(part.colors)
    return [np.asarray(c, np.float64) for c in cols]


def _split_step(data: np.ndarray, faces: np.ndarray, mark_edges) -> tuple[np.ndarray, np.ndarray, bool]:
    """One step of red-green refinement: the edges ``mark_edges(unique_edges (E, 2)) -> (E,) bool``
    picks are split at their midpoints (one shared vertex per edge, appended after ``data``'s
    rows, every attribute interpolated linearly); a face with 1, 2 or 3 split edges becomes 2, 3
    or 4 faces, so no T-junction remains. Returns (data, faces, whether anything was split)."""
    edges = np.stack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]], axis=1)   # (F, 3, 2)
    keys = np.sort(edges, axis=2).reshape(-1, 2)
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1, 3)
    marked = np.asarray(mark_edges(unique), bool)
    if not marked.any():
        return data, faces, False
    mid_index = np.full(len(unique), -1, np.int64)
    mid_index[marked] = len(data) + np.arange(marked.sum())
    data = np.vstack([data, 0.5 * (data[unique[marked, 0]] + data[unique[marked, 1]])])
    m = mid_index[inverse]                        # (F, 3): midpoint of edge (0-1, 1-2, 2-0) or -1
    a, b, c = faces[:, 0], faces[:, 1], faces[:, 2]
    count = (m >= 0).sum(axis=1)
    full = count == 3
    out = [np.column_stack([a, m[:, 0], m[:, 2]])[full], np.column_stack([m[:, 0], b, m[:, 1]])[full],
           np.column_stack([m[:, 2], m[:, 1], c])[full], np.column_stack([m[:, 0], m[:, 1], m[:, 2]])[full],
           faces[count == 0]]
    for k in range(3):                            # one split edge k: (v_k, v_k+1) halves
        one = (count == 1) & (m[:, k] >= 0)
        v0, v1, v2 = faces[one, k], faces[one, (k + 1) % 3], faces[one, (k + 2) % 3]
        out += [np.column_stack([v0, m[one, k], v2]), np.column_stack([m[one, k], v1, v2])]
    for k in range(3):                            # two split edges: all but edge k
        two = (count == 2) & (m[:, k] < 0)
        v0, v1, v2 = faces[two, k], faces[two, (k + 1) % 3], faces[two, (k + 2) % 3]
        m12, m20 = m[two, (k + 1) % 3], m[two, (k + 2) % 3]
        out += [np.column_stack([m12, v2, m20]), np.column_stack([v0, v1, m12]), np.column_stack([v0, m12, m20])]
    return data, np.vstack([o for o in out if len(o)]), True


def refine_part(part, max_edge: float, max_vertices: int = DEFAULT_MAX_VERTICES):
    """The part's edges longer than ``max_edge`` split at their midpoints until none is
    (``_split_step``), or the part has ``max_vertices``. Every attribute is interpolated
    linearly, as the rasteriser does, so the picture without occlusion is unchanged.
    Returns (data (N, W): the attributes side by side, widths, indices (M, 3))."""
    attrs = _attributes(part)
    data = np.hstack(attrs)
    faces = np.asarray(part.indices, np.int64).reshape(-1, 3)
    while len(data) < max_vertices and len(faces):
        p = data[:, :3]
        data, faces, split = _split_step(
            data, faces, lambda e: np.linalg.norm(p[e[:, 0]] - p[e[:, 1]], axis=1) > max_edge)
        if not split:
            break
    return data, [a.shape[1] for a in attrs], faces


# ---- the bake -------------------------------------------------------------------------------

def embree_available() -> bool:
    """Whether Intel Embree's binding (embreex) imports."""
    try:
        _import_embree()
    except AlightError:
        return False
    return True


def _import_embree():
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
    except ImportError:
        raise AlightError("occlusion: the visibility bake needs Intel Embree's Python binding "
                          "(pip install embreex), or use --occlusion off") from None
    return rtcore_scene, TriangleMesh


def _frame(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents (N, 3) orthogonal to unit normals n (Duff et al. 2017's branchless basis)."""
    sign = np.where(n[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.column_stack([1.0 + sign * n[:, 0] ** 2 * a, sign * b, -sign * n[:, 0]])
    s = np.column_stack([b, sign + n[:, 1] ** 2 * a, -n[:, 1]])
    return t, s


def cosine_directions(count: int) -> np.ndarray:
    """(count, 3) cosine-weighted hemisphere directions about +Z from a Fibonacci lattice
    (low discrepancy; every vertex uses the same set, turned by its own random angle)."""
    i = np.arange(count) + 0.5
    r = np.sqrt(i / count)
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(1.0 - r * r, 0.0))])


def eps_of(size: float) -> float:
    """The rays' offset off the surface, for a mesh of bounding-box diagonal ``size``."""
    return 1e-4 * size


def _cast(scene, origins, dirs, face_normals, eps, retries: int = 2, one_way=None):
    """First hits (triangle index, -1 for none; Embree's barycentric u, v). A ray that starts on
    or just behind a triangle (its own, or a wall its vertex stands against) and leaves through
    it in the direction of its normal hits it at t ~ 0: such hits are skipped by casting again
    from just past them.

    ``one_way`` (T,) bool: the triangles of single-sided parts (alight.core.mesh.single_sided),
    which stop light only where it meets their front, as a shadow map that culls the faces turned
    away from the light draws them: a ray (from the receiver) that meets one's front is not
    stopped by it, the light coming back along the ray meeting its back. Such a ray goes on from
    just past it (up to ONE_WAY_PASSES faces; past that it counts as stopped). A ray that is
    stopped reports its first hit all the same (what the vertex sees there: a closed part's near
    wall, though its far wall is what stops the light), one that is not reports none."""
    prim, tfar, u, v = _first_hits(scene, origins, dirs, face_normals, eps, retries)
    if one_way is None or not one_way.any():
        return prim, u, v
    # Rays on a one-way face met from the front: on past it, to whatever stops the light.
    stop = prim.copy()
    far = tfar.copy()
    for _ in range(ONE_WAY_PASSES):
        hit = np.nonzero(stop >= 0)[0]
        passing = one_way[stop[hit]] & (np.einsum("ij,ij->i", dirs[hit], face_normals[stop[hit]]) < 0.0)
        again = hit[passing]
        if not len(again):
            break
        # From just past the face (a twentieth of eps: a thin part's far side may be closer than eps)
        o2 = np.ascontiguousarray(origins[again] + dirs[again] * (far[again, None] + 0.05 * eps))
        # (no t ~ 0 skip past a face: a back face that close is a thin part's far side, not a
        # wall the origin stands against)
        p2, t2, _, _ = _first_hits(scene, o2, np.ascontiguousarray(dirs[again]), face_normals, eps, 0)
        stop[again] = p2
        far[again] = t2 + far[again] + 0.05 * eps
    free = stop < 0
    prim[free] = -1
    return prim, u, v


def _first_hits(scene, origins, dirs, face_normals, eps, retries: int):
    """``_cast``'s first hits without the one-way faces: (triangle, distance, u, v)."""
    out = scene.run(origins, dirs, output=1)
    prim = np.where(np.asarray(out["geomID"]) < 0, -1, np.asarray(out["primID"])).astype(np.int32)
    tfar = np.asarray(out["tfar"], np.float32).copy()
    u = np.asarray(out["u"], np.float32).copy()
    v = np.asarray(out["v"], np.float32).copy()
    for _ in range(retries):
        hit = prim >= 0
        self_hit = np.zeros(len(prim), bool)
        self_hit[hit] = (tfar[hit] < 4.0 * eps) & (np.einsum("ij,ij->i", dirs[hit], face_normals[prim[hit]]) > 0.0)
        if not self_hit.any():
            break
        again = np.nonzero(self_hit)[0]
        o2 = np.ascontiguousarray(origins[again] + dirs[again] * (tfar[again, None] + eps))
        out = scene.run(o2, np.ascontiguousarray(dirs[again]), output=1)
        prim[again] = np.where(np.asarray(out["geomID"]) < 0, -1, np.asarray(out["primID"]))
        tfar[again] = np.asarray(out["tfar"], np.float32) + tfar[again] + eps
        u[again] = out["u"]
        v[again] = out["v"]
    return prim, tfar, u, v


def _origins(p: np.ndarray, n: np.ndarray, faces: np.ndarray, eps: float) -> np.ndarray:
    """Where a vertex's rays start: eps off the surface along n, and nudged toward the vertex's own
    faces: a vertex on a crease (the floor's corner, where two walls stand) would otherwise start
    in the walls' planes, where a hit at t = 0 is a coin toss."""
    centroid = np.zeros_like(p)
    face_centroid = np.repeat(p[faces].mean(axis=1), 3, axis=0)
    for k in range(3):
        centroid[:, k] = np.bincount(faces.ravel(), face_centroid[:, k], minlength=len(p))
    uses = np.bincount(faces.ravel(), minlength=len(p))[:, None]
    toward = centroid / np.maximum(uses, 1) - p
    reach = np.linalg.norm(toward, axis=1, keepdims=True)
    nudge = toward / np.maximum(reach, 1e-30) * np.minimum(10.0 * eps, 0.5 * reach)
    origin = p + nudge + eps * n
    # The nudge points at the faces' centroid, which lies behind a curved surface's vertex (the
    # chords of a convex patch run inside it): on a coarse mesh (the Duck: 4k triangles over a
    # round body) it took the origin behind the vertex's own faces by more than the t ~ 0 skip
    # covers, and every ray left through its own face as an occluder: V ~ 0 on convex patches,
    # black blotches. So the origin is lifted along n until it is eps in front of every plane
    # of its own faces (a refined face lies in its original triangle's plane).
    face_normal = np.cross(p[faces[:, 1]] - p[faces[:, 0]], p[faces[:, 2]] - p[faces[:, 0]])
    face_normal /= np.maximum(np.linalg.norm(face_normal, axis=1, keepdims=True), 1e-30)
    corner = faces.ravel()
    fn = np.repeat(face_normal, 3, axis=0)
    depth = np.einsum("ij,ij->i", origin[corner] - p[corner], fn)          # height over each own face
    along = np.maximum(np.einsum("ij,ij->i", n[corner], fn), 0.1)         # how fast a lift along n gains
    lift = np.zeros(len(p))
    np.maximum.at(lift, corner, np.maximum(eps - depth, 0.0) / along)
    return (origin + lift[:, None] * n).astype(np.float32)


class _Occluders:
    """Embree's scene of triangles (T, 3, 3) and their unit normals (by winding); ``outside``
    (T,) +1 or -1: the side the mesh's vertex normals call the outside (default: the winding's);
    ``one_way`` (T,) bool: the single-sided triangles (``_cast``)."""

    def __init__(self, triangles: np.ndarray, outside: np.ndarray | None = None, one_way: np.ndarray | None = None):
        rtcore_scene, TriangleMesh = _import_embree()
        # (T,) bool: single-sided triangles (_cast's one_way); None: every one two-sided
        self.one_way = None if one_way is None or not np.any(one_way) else np.asarray(one_way, bool)
        self.triangles = np.ascontiguousarray(triangles, np.float32)
        self.scene = rtcore_scene.EmbreeScene()
        self._mesh = TriangleMesh(scene=self.scene, vertices=self.triangles)
        n = np.cross(self.triangles[:, 1] - self.triangles[:, 0], self.triangles[:, 2] - self.triangles[:, 0])
        self.normals = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
        self.outward = self.normals if outside is None else self.normals * np.asarray(outside, np.float32)[:, None]
        self.near = 0.0          # a hit closer than this is "covered" (hemisphere's covered_share)
        self.covered_share = None  # after hemisphere(): per origin, the share of its rays covered

    def hemisphere(self, origins, normals, rays: int, rng, eps: float):
        """Cast ``rays`` cosine-weighted rays from each origin about its normal: (hit triangle
        (N, R) or -1, Embree's u, v (N, R, 2), the unoccluded directions' sum (N, 3)). Leaves
        ``covered_share`` (N,): the share of the rays that hit a triangle's inside (``outward``)
        or any triangle closer than ``near`` (``_covered``)."""
        count = len(origins)
        hit = np.empty((count, rays), np.int32)
        uv = np.empty((count, rays, 2), np.float32)
        open_sum = np.zeros((count, 3), np.float64)
        covered = np.zeros(count, np.float64)
        for rows, d, o in _ray_chunks(origins, normals, rays, rng):
            prim, u, v = _cast(self.scene, o, d, self.normals, eps, one_way=self.one_way)
            hit[rows] = prim.reshape(-1, rays)
            uv[rows] = np.stack([u, v], axis=-1).reshape(-1, rays, 2)
            open_sum[rows] = (d * (prim < 0)[:, None]).reshape(-1, rays, 3).sum(axis=1)
            covered[rows] = _covered(self, prim, u, v, o, d).reshape(-1, rays).mean(axis=1)
        self.covered_share = covered
        return hit, uv, open_sum


def _covered(occluders, prim, u, v, o, d) -> np.ndarray:
    """Per ray, whether its hit says the origin is covered by a part: it hit a triangle from the
    inside (along the triangle's ``outward`` normal: a ray that starts inside a closed part does
    so in every direction) or hit one closer than ``occluders.near`` (a part lying on the surface
    with a thin gap under it)."""
    out = np.zeros(len(prim), bool)
    hit = np.nonzero(prim >= 0)[0]
    if not len(hit):
        return out
    p = prim[hit]
    out[hit] = np.einsum("ij,ij->i", d[hit], occluders.outward[p]) > 0.0
    if occluders.near > 0.0:
        tri = occluders.triangles[p]
        point = tri[:, 0] + u[hit, None] * (tri[:, 1] - tri[:, 0]) + v[hit, None] * (tri[:, 2] - tri[:, 0])
        out[hit] |= np.linalg.norm(point - o[hit], axis=1) < occluders.near
    return out


def _outside_sign(positions: np.ndarray, normals: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """(T,) +1 where a triangle's winding normal agrees with its vertex normals' sum, else -1 (a
    clockwise or mirrored part: its vertex normals say which side is the outside)."""
    tri = np.asarray(positions, np.float64)[indices]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    vn = np.asarray(normals, np.float64)[indices].sum(axis=1)
    return np.where(np.einsum("ij,ij->i", n, vn) < 0.0, -1.0, 1.0)


def _ray_chunks(origins: np.ndarray, normals: np.ndarray, rays: int, rng):
    """``rays`` cosine-weighted rays about each of the (N, 3) ``normals`` from its origin, a chunk
    of origins at a time (about 262K rays: one Embree call's arrays stay bounded): yields (rows,
    d, o), ``rows`` the chunk's slice of the N, ``d`` and ``o`` its (C * R, 3) float32 directions
    and origins, origin by origin. The directions are cosine_directions(rays) about +Z turned onto
    each normal in a frame spun by a random angle per origin (one ``rng.uniform`` draw of C per
    chunk: the same sequence wherever it is called, so a bake stays reproducible)."""
    local = cosine_directions(rays).astype(np.float32)
    chunk = max(1, 262_144 // rays)
    for s0 in range(0, len(origins), chunk):
        rows = slice(s0, s0 + chunk)
        n = normals[rows]
        t, b = _frame(n)
        angle = rng.uniform(0.0, 2.0 * math.pi, len(n))
        c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
        t, b = c * t + s * b, c * b - s * t
        frame = np.stack([t, b, n], axis=1).astype(np.float32)        # (C, 3, 3): rows t, b, n
        d = np.ascontiguousarray((local @ frame).reshape(-1, 3))
        o = np.ascontiguousarray(np.repeat(origins[rows], rays, axis=0))
        yield rows, d, o


def _free_rays(occluders, see_through, through_of_triangle, origins, normals, rays: int, rng, eps: float):
    """Cosine-weighted rays about each normal, as ``_Occluders.hemisphere``: each ray's free share
    (N, R), 1 where it escapes, 0 where an opaque part (``occluders``, or None) stops it, and the
    light_through (``through_of_triangle``, per triangle of ``see_through``) of the first
    see-through part it meets; and the free directions' weighted sum (N, 3)."""
    if see_through is None:
        hit, _, open_sum = occluders.hemisphere(origins, normals, rays, rng, eps)
        return (hit < 0).astype(np.float64), open_sum, occluders.covered_share
    count = len(origins)
    free = np.empty((count, rays), np.float64)
    open_sum = np.zeros((count, 3), np.float64)
    back = np.zeros(count, np.float64)
    for rows, d, o in _ray_chunks(origins, normals, rays, rng):
        w = np.ones(len(d))
        if occluders is not None:
            prim, u, v = _cast(occluders.scene, o, d, occluders.normals, eps, one_way=occluders.one_way)
            w = (prim < 0).astype(np.float64)
            back[rows] = _covered(occluders, prim, u, v, o, d).reshape(-1, rays).mean(axis=1)
        prim_t, _, _ = _cast(see_through.scene, o, d, see_through.normals, eps, one_way=see_through.one_way)
        w = w * np.where(prim_t < 0, 1.0, through_of_triangle[np.maximum(prim_t, 0)])
        free[rows] = w.reshape(-1, rays)
        open_sum[rows] = (d * w[:, None]).reshape(-1, rays, 3).sum(axis=1)
    return free, open_sum, back


def _values_at(data, faces, first: int, occluders, see_through, through_of_triangle, rays: int, rng, eps: float):
    """(N - first, 5): the bent normal, V and the covered share (``_covered``: the share of the
    rays that say the vertex lies inside or under a part) of the vertices ``data[first:]`` of a
    refined part."""
    p, n = data[:, :3], data[:, 3:6] / np.maximum(np.linalg.norm(data[:, 3:6], axis=1, keepdims=True), 1e-30)
    origins = _origins(p, n, faces, eps)[first:]
    free, open_sum, back = _free_rays(occluders, see_through, through_of_triangle, origins,
                                      n[first:].astype(np.float32), rays, rng, eps)
    length = np.linalg.norm(open_sum, axis=1, keepdims=True)
    bent = np.where(length > 1e-8, open_sum / np.maximum(length, 1e-30), n[first:])
    return np.column_stack([bent, free.mean(axis=1), back])


def _fill_covered(values: np.ndarray, faces: np.ndarray, buried: np.ndarray, unit: bool = True) -> np.ndarray:
    """``values`` (N, 4: a unit direction and a scalar) of a refined part with its buried
    vertices' rows replaced, ring by ring, by the mean of their neighbours' already known rows
    (the direction renormalised). A buried vertex lies inside another part (a floor vertex under
    a box standing on it, an arrow lying in a face): what it sees is that part's inside, V ~ 0
    and the bounce off the part's inner walls, and nothing of it is ever drawn but its share of
    its triangles' interpolation, which then ran a black (or, by the bounce, bright) wedge out to
    the next vertex outside the part. Its open neighbours' values are what the visible rest of
    those triangles sees (lightmap bakers dilate valid texels into those inside geometry alike).
    A buried region with no open neighbour keeps its own values. ``unit`` False: the direction
    is a mean of unit vectors (the bounce's), averaged as it is."""
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    return fill_rings(values, buried, np.concatenate([edges, edges[:, ::-1]]), unit)


def fill_rings(values: np.ndarray, unknown: np.ndarray, edges: np.ndarray, unit: bool = False) -> np.ndarray:
    """``values`` (N, C) as float64 with the ``unknown`` (N,) rows replaced, ring by ring, by the
    mean of their already known neighbours' rows along ``edges`` ((E, 2) (from, to), both ways; an
    edge listed twice weighs twice). ``unit``: columns 0-2 are a direction, renormalised each ring
    (kept as given where the mean vanishes). A region with no known neighbour keeps its own rows."""
    out = np.array(values, np.float64, copy=True)
    unknown = np.asarray(unknown, bool).copy()
    if not unknown.any() or unknown.all():
        return out
    count = len(out)
    while unknown.any():
        e = edges[unknown[edges[:, 1]] & ~unknown[edges[:, 0]]]   # known -> unknown
        if not len(e):
            break
        n = np.bincount(e[:, 1], minlength=count)
        sums = np.column_stack([np.bincount(e[:, 1], out[e[:, 0], k], minlength=count) for k in range(out.shape[1])])
        ring = n > 0
        out[ring] = sums[ring] / n[ring, None]
        if unit:
            length = np.linalg.norm(out[ring, :3], axis=1, keepdims=True)
            out[ring, :3] = np.where(length > 1e-8, out[ring, :3] / np.maximum(length, 1e-30), values[ring, :3])
        unknown &= ~ring
    return out


def welded(positions: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(N,) int64: per vertex, one index shared by the copies of a vertex: vertices at one position
    (to 1e-6 of the mesh's size) whose normals lie within WELD_CREASE_DEG of the copies' mean.
    Files that repeat a vertex per triangle (an OBJ written without shared indices, an exporter's
    per-face split) give each copy rays of its own and, where the normals were made per copy,
    normals a degree or two apart: copies at one point got different values, a smooth bowl's
    inside a speckle of triangles, and the faces alone connect no copy to its neighbours, so
    neighbour averaging stayed inside each triangle. A crease (a cube's edge: copies 45 degrees
    or more from their mean; an asset's split normals, an authored hard edge) keeps one index per
    copy."""
    p = np.asarray(positions, np.float64).reshape(-1, 3)
    if not len(p):
        return np.zeros(0, np.int64)
    n = np.asarray(normals, np.float64).reshape(-1, 3)
    n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    size = max(float(np.ptp(p, axis=0).max()), 1e-30)
    _, at = np.unique(np.round((p - p.min(axis=0)) / size * 1e6), axis=0, return_inverse=True)
    at = np.asarray(at, np.int64).reshape(-1)
    mean = np.zeros((int(at.max()) + 1, 3))
    np.add.at(mean, at, n)
    mean /= np.maximum(np.linalg.norm(mean, axis=1, keepdims=True), 1e-30)
    crease = np.einsum("ij,ij->i", n, mean[at]) < math.cos(math.radians(WELD_CREASE_DEG))
    key = np.where(crease, len(mean) + np.arange(len(p)), at)
    _, ids = np.unique(key, return_inverse=True)
    return np.asarray(ids, np.int64).reshape(-1)


def on_welded(values: np.ndarray, faces: np.ndarray, ids: np.ndarray | None, work):
    """``work(values, faces)`` on the welded mesh (``welded`` ids: each copy's rows averaged,
    the faces renumbered), its result handed back to every copy; ``ids`` None: on the mesh as
    it is."""
    values = np.asarray(values, np.float64)
    if ids is None or not len(values):
        return work(values, faces)
    count = int(ids.max()) + 1
    copies = np.bincount(ids, minlength=count).astype(np.float64)
    merged = np.column_stack([np.bincount(ids, values[:, k], minlength=count) for k in range(values.shape[1])])
    merged /= np.maximum(copies, 1.0)[:, None]
    return work(merged, ids[np.asarray(faces, np.int64).reshape(-1, 3)])[ids]


def _copies_averaged(values: np.ndarray, faces: np.ndarray, data: np.ndarray, unit: bool = True) -> np.ndarray:
    """``values`` (N, 4: a direction and a share) averaged over each vertex's copies
    (``welded`` over ``data``'s positions and normals), the direction renormalised. A
    file that repeats a vertex per face around it (an OBJ or STL without shared normals: the
    loader keeps a copy per face) gave each copy rays of its own, so copies at one point drew
    different values: a speckle of triangles over a smooth bowl's inside. Only copies are
    averaged, no neighbours: V's sharp changes (a contact, a slab's foot) stay where the
    refinement put them. ``unit`` False: as ``_fill_covered``'s."""
    out = on_welded(values, faces, welded(data[:, :3], data[:, 3:6]), lambda v, f: v)
    if not unit:
        return out
    length = np.linalg.norm(out[:, :3], axis=1, keepdims=True)
    out[:, :3] = np.where(length > 1e-12, out[:, :3] / np.maximum(length, 1e-30), values[:, :3])
    return out


def bake_visibility(mesh, rays: int = DEFAULT_RAYS, edge_fraction: float = DEFAULT_EDGE_FRACTION,
                    max_vertices: int = DEFAULT_MAX_VERTICES, seed: int = 0,
                    coarse_fraction: float = DEFAULT_COARSE_FRACTION, bounce_rays: int = DEFAULT_BOUNCE_RAYS,
                    threshold: float = DEFAULT_THRESHOLD, light_through=None) -> MeshVisibility:
    """Visibility per vertex, the mesh refined where it changes. Every part is first split to
    edges of ``coarse_fraction`` of the bounding-box diagonal (``refine_part``); then, level by
    level (MAX_LEVELS at most), ``rays`` cosine-weighted rays from each new vertex against the
    mesh (Embree, float32) give V and the bent normal, and an edge is split where V differs by more
    than ``threshold`` across it (or the bent normals by more than 25 degrees) while it is longer
    than ``edge_fraction`` of the diagonal. Last, ``bounce_rays`` rays from every vertex against the
    refined mesh find what each sees for the bounce. Seeded: the same mesh gives the same values.
    ``light_through``: per part, the share of light it lets through (transmission, a blended
    part's 1 - alpha; default 0, opaque): those parts are not occluders of V and the bent normal;
    a ray whose first hit among them is part k counts light_through[k] of a free ray (one wall:
    a closed glass counts t, not t^2; what lies beyond it is the opaque parts' test, made first)."""
    start = time.perf_counter()
    lo, hi = mesh.bounds()
    size = float(np.linalg.norm(hi - lo)) or 1.0
    eps = eps_of(size)
    rng = np.random.default_rng(seed)
    per_part_limit = max(max_vertices // max(len(mesh.parts), 1), 1000)
    through = np.zeros(len(mesh.parts)) if light_through is None else np.clip(np.asarray(light_through, float), 0, 1)
    tris = [np.asarray(p.positions, np.float64)[np.asarray(p.indices, np.int64)] for p in mesh.parts]
    clear = through > 0.0
    sided = [single_sided(p) for p in mesh.parts]
    one_way = [np.full(len(t), s) for t, s in zip(tris, sided)]
    outside = [_outside_sign(p.positions, p.normals, np.asarray(p.indices, np.int64)) for p in mesh.parts]
    opaque = [t for t, c in zip(tris, clear) if not c]
    occluders = _Occluders(np.concatenate(opaque), np.concatenate([o for o, c in zip(outside, clear) if not c]),
                           np.concatenate([w for w, c in zip(one_way, clear) if not c])) if opaque else None
    see_through = None
    if clear.any():
        see_through = _Occluders(np.concatenate([t for t, c in zip(tris, clear) if c]),
                                 one_way=np.concatenate([w for w, c in zip(one_way, clear) if c]))
        through_of_triangle = np.concatenate([np.full(len(t), k) for t, c, k in zip(tris, clear, through) if c])
    else:
        through_of_triangle = None
    state = [refine_part(p, coarse_fraction * size, per_part_limit) for p in mesh.parts]
    values = [np.zeros((0, 5)) for _ in state]        # per vertex: bent normal, V, back-hit share
    cast = 0
    fine = edge_fraction * size
    if occluders is not None:
        occluders.near = COVERED_DISTANCE * fine
    cos_limit = math.cos(math.radians(25.0))
    for level in range(MAX_LEVELS + 1):
        split_any = False
        for i, (data, widths, faces) in enumerate(state):
            known = len(values[i])
            if known < len(data):
                values[i] = np.vstack([values[i], _values_at(data, faces, known, occluders, see_through,
                                                             through_of_triangle, rays, rng, eps)])
                cast += (len(data) - known) * rays
            if len(data) >= per_part_limit or level == MAX_LEVELS:
                continue
            p, val = data[:, :3], values[i]
            picked = {}

            def mark(e, p=p, val=val, picked=picked):
                long = np.linalg.norm(p[e[:, 0]] - p[e[:, 1]], axis=1) > fine
                dv = np.abs(val[e[:, 0], 3] - val[e[:, 1], 3]) > threshold
                db = np.einsum("ij,ij->i", val[e[:, 0], :3], val[e[:, 1], :3]) < cos_limit
                # A buried end (inside another part: its values are never seen, only
                # interpolated, see _fill_covered) does not compare; an edge from a buried end to
                # an open one is split, to bring a vertex to the buried part's edge.
                b0, b1 = val[e[:, 0], 4] >= COVERED_SHARE, val[e[:, 1], 4] >= COVERED_SHARE
                picked["edges"], picked["marked"] = e, long & (((dv | db) & ~b0 & ~b1) | (b0 != b1))
                return picked["marked"]

            split_data, split_faces, split = _split_step(data, faces, mark)
            if split and INTERPOLATION_TEST:
                # Keep a split only where the midpoint's value is not what the edge interpolates
                # linearly to (V by more than the threshold, the bent normal by 25 degrees): a
                # smooth ramp across an edge is drawn right by its two ends, and each split edge
                # costs llvmpipe two to four triangles a frame.
                new = _values_at(split_data, split_faces, len(data), occluders, see_through, through_of_triangle,
                                 rays, rng, eps)
                cast += len(new) * rays
                e = picked["edges"][picked["marked"]]
                lin_v = 0.5 * (val[e[:, 0], 3] + val[e[:, 1], 3])
                lin_b = val[e[:, 0], :3] + val[e[:, 1], :3]
                lin_b /= np.maximum(np.linalg.norm(lin_b, axis=1, keepdims=True), 1e-30)
                needed = (np.abs(new[:, 3] - lin_v) > threshold) | (np.einsum("ij,ij->i", new[:, :3], lin_b) < cos_limit)
                needed |= (val[e[:, 0], 4] >= COVERED_SHARE) != (val[e[:, 1], 4] >= COVERED_SHARE)
                keep = picked["marked"].copy()
                keep[keep] = needed
                split_data, split_faces, split = _split_step(data, faces, lambda _e, keep=keep: keep)
                values[i] = np.vstack([val, new[needed]])
            data, faces = split_data, split_faces
            state[i] = (data, widths, faces)
            split_any |= split
        if not split_any:
            break
    # Buried vertices (inside another part) take their open neighbours' values.
    buried = [val[:, 4] >= COVERED_SHARE for val in values]
    values = [_fill_covered(val[:, :4], f, b) for val, (_, _, f), b in zip(values, state, buried)]
    values = [_copies_averaged(val, f, d) for val, (d, _, f) in zip(values, state)]
    # The bounce: what each vertex's rays hit on the refined mesh, and the V and bent normal there.
    offsets = np.cumsum([0] + [len(d) for d, _, _ in state])
    all_p = np.concatenate([d[:, :3] for d, _, _ in state])
    all_n = np.concatenate([d[:, 3:6] for d, _, _ in state])
    all_n = all_n / np.maximum(np.linalg.norm(all_n, axis=1, keepdims=True), 1e-30)
    all_f = np.concatenate([f + o for (_, _, f), o in zip(state, offsets[:-1])])
    all_values = np.concatenate(values).astype(np.float32)
    refined = _Occluders(all_p[all_f],
                         one_way=np.concatenate([np.full(len(f), s) for (_, _, f), s in zip(state, sided)]))
    origins = np.concatenate([_origins(d[:, :3], all_n[a:b], f, eps)
                              for (d, _, f), a, b in zip(state, offsets[:-1], offsets[1:])])
    hit, uv, _ = refined.hemisphere(origins, all_n.astype(np.float32), bounce_rays, rng, eps)
    cast += hit.size
    count = len(all_p)
    rows, cols = np.nonzero(hit >= 0)
    corners = all_f[hit[rows, cols]]                                        # (H, 3)
    huv = uv[rows, cols]
    w = np.column_stack([1.0 - huv[:, 0] - huv[:, 1], huv[:, 0], huv[:, 1]]).astype(np.float32)
    at_hit = np.einsum("hk,hkc->hc", w, all_values[corners])                # (H, 4): bent, V
    bounce_weight = np.bincount(rows, at_hit[:, 3], minlength=count) / bounce_rays
    # The V_hit-weighted mean of the hits' bent normals, each leaned by cone_lean (its free
    # directions' reach along it), not normalised: its length (at most 1.5) says how much they
    # agree. E/pi is close to linear in the direction, so the hits' mean is E's even part plus the
    # length times its odd part along the mean (bounce_irradiance); E at the unit direction alone
    # took the hits on two facing partitions, whose bent normals half cancel, as all facing the
    # side the mean leans to.
    lean = at_hit[:, 3] * cone_lean(at_hit[:, 3])
    bounce_dir = np.column_stack([np.bincount(rows, at_hit[:, k] * lean, minlength=count) for k in range(3)])
    total = np.bincount(rows, at_hit[:, 3], minlength=count)[:, None]
    length = np.linalg.norm(bounce_dir, axis=1, keepdims=True)
    bounce_dir = np.where(length > 1e-8, bounce_dir / np.maximum(np.maximum(total, length), 1e-30), -all_n)
    for (d, _, f), b, a, z in zip(state, buried, offsets[:-1], offsets[1:]):
        bounce = np.column_stack([bounce_dir[a:z], bounce_weight[a:z]])
        filled = _copies_averaged(_fill_covered(bounce, f, b, unit=False), f, d, unit=False)
        bounce_dir[a:z], bounce_weight[a:z] = filled[:, :3], filled[:, 3]
    parts = []
    for (data, widths, faces), part, val, a, b, s in zip(state, mesh.parts, values, offsets[:-1], offsets[1:], sided):
        cols_ = np.split(data, np.cumsum(widths)[:-1], axis=1)
        cols_[1] = cols_[1] / np.maximum(np.linalg.norm(cols_[1], axis=1, keepdims=True), 1e-30)
        extra = cols_[4:]
        uvs1 = extra.pop(0) if part.uvs1 is not None else None
        colors = extra.pop(0) if part.colors is not None else None
        parts.append(PartVisibility(
            positions=cols_[0].astype(np.float32), normals=cols_[1].astype(np.float32),
            uvs=cols_[2].astype(np.float32), tangents=cols_[3].astype(np.float32), indices=faces.astype(np.uint32),
            uvs1=None if uvs1 is None else uvs1.astype(np.float32),
            colors=None if colors is None else colors.astype(np.float32),
            visibility=val[:, 3].astype(np.float32), bent_normal=val[:, :3].astype(np.float32),
            bounce_direction=bounce_dir[a:b].astype(np.float32),
            bounce_weight=bounce_weight[a:b].astype(np.float32), one_way=s))
    return MeshVisibility(parts, seconds=time.perf_counter() - start, rays=int(cast))


# ---- the suns on the occluders ------------------------------------------------------------------

MAX_SUNS = 4          # shaders/common/suns.glsl's MAX_SUNS: one vec4 per vertex holds them
SUN_BOUNCE_VERSION = 3   # 2: the second bounce (B2); 3: single-sided parts one-way (_cast)


def one_way_triangles(parts) -> np.ndarray:
    """(M,) bool over the merged faces of a bake's refined parts: the single-sided parts'
    (PartVisibility.one_way; _cast)."""
    return np.concatenate([np.full(len(np.asarray(p.indices).reshape(-1, 3)), bool(getattr(p, "one_way", False)))
                           for p in parts]) if parts else np.zeros(0, bool)


def merged_parts(parts):
    """The refined parts as one mesh for ray casting: (positions (N, 3) float64, the ray offset
    eps, per-part vertex offsets (P + 1,), per-part faces [(M_k, 3)], all faces (M, 3) in the merged
    numbering, unit normals (N, 3) float64)."""
    positions = np.concatenate([p.positions for p in parts]).astype(np.float64)
    lo, hi = positions.min(axis=0), positions.max(axis=0)
    eps = eps_of(float(np.linalg.norm(hi - lo)) or 1.0)
    offsets = np.cumsum([0] + [len(p.positions) for p in parts])
    faces = [np.asarray(p.indices, np.int64).reshape(-1, 3) for p in parts]
    all_f = np.concatenate([f + o for f, o in zip(faces, offsets[:-1])])
    all_n = np.concatenate([p.normals for p in parts]).astype(np.float64)
    all_n /= np.maximum(np.linalg.norm(all_n, axis=1, keepdims=True), 1e-30)
    return positions, eps, offsets, faces, all_f, all_n


class _Transmittance:
    """The merged refined parts (``merged_parts``) split by ``light_through`` (per part, 0 for
    opaque): an opaque triangle stops a ray; a see-through one passes its part's share, the first
    one a ray meets (as the bake's ``_free_rays``)."""

    def __init__(self, parts, positions: np.ndarray, faces, all_f: np.ndarray, light_through=None):
        through = np.zeros(len(parts)) if light_through is None else np.clip(np.asarray(light_through, float), 0, 1)
        part_of_triangle = np.concatenate([np.full(len(f), k) for k, f in enumerate(faces)])
        opaque = ~(through > 0.0)[part_of_triangle]
        one_way = one_way_triangles(parts)
        self.blockers = _Occluders(positions[all_f[opaque]], one_way=one_way[opaque]) if opaque.any() else None
        self.see_through = _Occluders(positions[all_f[~opaque]], one_way=one_way[~opaque]) if (~opaque).any() else None
        self.through = through[part_of_triangle[~opaque]]       # per see-through triangle

    def along(self, origins: np.ndarray, dirs: np.ndarray, eps: float) -> np.ndarray:
        """(R,) float64: the share of light that reaches each origin along its ray."""
        w = np.ones(len(dirs))
        if self.blockers is not None:
            b = self.blockers
            prim, _, _ = _cast(b.scene, origins, dirs, b.normals, eps, one_way=b.one_way)
            w = (prim < 0).astype(np.float64)
        if self.see_through is not None:
            t = self.see_through
            prim, _, _ = _cast(t.scene, origins, dirs, t.normals, eps, one_way=t.one_way)
            w = w * np.where(prim < 0, 1.0, self.through[np.maximum(prim, 0)])
        return w


def bake_sun_bounce(parts: list[PartVisibility], directions, bounce_rays: int = DEFAULT_BOUNCE_RAYS,
                    seed: int = 0, light_through=None) -> list[np.ndarray]:
    """Per part of a bake (``bake_visibility``'s refined parts, world space), (N, 8) float32: the
    light each compact source k of ``directions`` ((K, 3) unit world directions toward the suns,
    K <= MAX_SUNS; the rest 0) puts on what the vertex's ``bounce_rays`` cosine-weighted rays hit
    (the occluders), over the sun's power, as two bounces:
    - columns 0..3, B1_k: the mean over the rays that hit of S_k(hit) max(n_hit.l_k, 0) / pi,
      n_hit the hit face's normal turned toward the ray, S_k the hit's visibility of sun k (a
      shadow ray toward it, stopped by an opaque part, passing ``light_through`` of a see-through
      one, as the bake's V): the suns' E/pi on the occluders, direct;
    - columns 4..7, B2_k: the mean over the same hits of h(hit) B1_k(hit), h the share of a
      vertex's rays that hit, B1 interpolated at the hit from its triangle's vertices: the light
      the occluders get from their own sunlit occluders, over their albedo.
    An occluder of albedo a then shines a (B1 + a B2 + ...) P_k (P_k the sun's power, radiance
    integrated over its disk: the shader's u_sun_power, so the environment's intensity needs no
    new pass). 0 for a vertex none of whose rays hit. Seeded; each sun a delta light (its spread
    is not sampled)."""
    directions = np.asarray(directions, np.float64).reshape(-1, 3)[:MAX_SUNS]
    out = [np.zeros((len(p.positions), 2 * MAX_SUNS), np.float32) for p in parts]
    if not len(directions) or not parts:
        return out
    positions, eps, offsets, faces, all_f, all_n = merged_parts(parts)
    refined = _Occluders(positions[all_f], one_way=one_way_triangles(parts))
    transmittance = _Transmittance(parts, positions, faces, all_f, light_through)
    origins = np.concatenate([_origins(positions[a:b], all_n[a:b], f, eps)
                              for f, a, b in zip(faces, offsets[:-1], offsets[1:])])
    rng = np.random.default_rng(seed)
    count = len(positions)
    total = np.zeros((count, MAX_SUNS), np.float64)
    hits = np.zeros(count, np.int64)
    kept = []                       # per chunk: the hitting rays' vertex, triangle and barycentrics
    for rows, d, o in _ray_chunks(origins, all_n.astype(np.float32), bounce_rays, rng):
        prim, u, v = _cast(refined.scene, o, d, refined.normals, eps, one_way=refined.one_way)
        ray = np.nonzero(prim >= 0)[0]
        if not len(ray):
            continue
        tri = refined.triangles[prim[ray]].astype(np.float64)
        point = tri[:, 0] + u[ray, None] * (tri[:, 1] - tri[:, 0]) + v[ray, None] * (tri[:, 2] - tri[:, 0])
        face_n = refined.normals[prim[ray]].astype(np.float64)
        face_n *= np.where(np.einsum("ij,ij->i", face_n, d[ray]) > 0.0, -1.0, 1.0)[:, None]   # the side seen
        vertex = rows.start + ray // bounce_rays
        hits += np.bincount(vertex, minlength=count)
        kept.append((vertex, prim[ray], u[ray], v[ray]))
        start = (point + 2.0 * eps * face_n).astype(np.float32)
        for k, l in enumerate(directions):
            cos = face_n @ l
            lit = np.nonzero(cos > 0.0)[0]
            if not len(lit):
                continue
            o2 = np.ascontiguousarray(start[lit])
            d2 = np.ascontiguousarray(np.broadcast_to(l.astype(np.float32), (len(lit), 3)))
            shadow = transmittance.along(o2, d2, eps)
            total[:, k] += np.bincount(vertex[lit], shadow * cos[lit] / math.pi, minlength=count)
    first = total / np.maximum(hits, 1)[:, None]                       # B1 per vertex
    carried = first * (hits / bounce_rays)[:, None]                    # h B1: what a vertex passes on
    second = np.zeros_like(first)
    for vertex, prim, u, v in kept:
        w = np.column_stack([1.0 - u - v, u, v]).astype(np.float64)
        at_hit = np.einsum("hk,hkc->hc", w, carried[all_f[prim]])
        for k in range(MAX_SUNS):
            second[:, k] += np.bincount(vertex, at_hit[:, k], minlength=count)
    second /= np.maximum(hits, 1)[:, None]
    both = np.column_stack([first, second]).astype(np.float32)
    return [both[a:b] for a, b in zip(offsets[:-1], offsets[1:])]


def sun_bounce_key(visibility_key_: str, directions, bounce_rays: int = DEFAULT_BOUNCE_RAYS,
                   light_through=None) -> tuple[str, dict]:
    """The cache key of ``bake_sun_bounce`` over the bake ``visibility_key_`` for the suns'
    world ``directions`` (rounded to 1e-5: an environment's rotation or another map is another
    key; its intensity and the suns' powers are not in it, the shader multiplies them in)."""
    description = {"what": "sun-bounce", "version": SUN_BOUNCE_VERSION, "visibility": visibility_key_,
                   "directions": [[round(float(x), 5) for x in d] for d in
                                  np.asarray(directions, np.float64).reshape(-1, 3)[:MAX_SUNS]],
                   "bounce_rays": bounce_rays}
    if light_through is not None and any(float(t) > 0.0 for t in light_through):
        description["light_through"] = [round(float(t), 6) for t in light_through]
    text = json.dumps(description, sort_keys=True)
    return "alight-sun-bounce-" + hashlib.sha256(text.encode()).hexdigest(), description


# ---- the occluders' materials -------------------------------------------------------------------

OCCLUDER_MATERIAL_VERSION = 1   # bumped when bake_occluder_materials records other data


@dataclass(frozen=True)
class OccluderMaterial:
    """A part's material as the occluders' pass reads it (alight.render.visibility_parts.
    occluder_materials): the base colour (linear RGB, its texture's mean colour multiplied in),
    metallic (its texture's mean too), the dielectric F0, the emitted radiance (emissiveFactor
    times KHR_materials_emissive_strength times its texture's mean) and whether the part's vertex
    colours (COLOR_0) multiply the base colour."""

    base_color: tuple = (0.8, 0.8, 0.8)
    metallic: float = 0.0
    specular_f0: tuple = (0.04, 0.04, 0.04)
    emission: tuple = (0.0, 0.0, 0.0)
    vertex_colors: bool = False

    def described(self) -> list:
        return [round(float(x), 6) for x in (*self.base_color, self.metallic, *self.specular_f0, *self.emission)] \
            + [bool(self.vertex_colors)]


def bake_occluder_materials(parts: list[PartVisibility], materials, bounce_rays: int = DEFAULT_BOUNCE_RAYS,
                            seed: int = 0) -> list[np.ndarray]:
    """Per part of a bake (``bake_visibility``'s refined parts), (N, 8) float32: what the vertex's
    ``bounce_rays`` cosine-weighted rays hit, by the hit part's material (``materials``: one
    OccluderMaterial per part), interpolated at the hit from its triangle's vertices:
    - columns 0..2: the hits' albedo by ``occluder_base_albedo`` (their vertex colours in where
      they have them), each hit weighted by its V (the baked visibility there) plus 1e-3: the
      shader multiplies the albedo by the hits' mean V and E/pi, so the mean of a V is
      (sum a V / sum V) times the mean V; the 1e-3 gives the plain mean where every hit is dark;
    - column 3: 1 where a ray hit, else 0 (the shader keeps this surface's own albedo there, as
      it does for every vertex of a mesh drawn before this pass ran);
    - columns 4..6: the mean radiance the hits emit, over the rays that hit (what the occluded
      directions see of emission: the shader adds it to the occluders' radiance, which the
      occluded share 1 - V multiplies, as the bounce's; its light on further occluders is left
      out);
    - column 7: the share of the rays that hit.
    Before this pass the shader took every occluder to be this surface's material (one material
    per scene): a grey box lent its albedo to the red arrows on it (a bluish-white halo where the
    path tracer has a faint red glow), and emissive parts lit nothing. Seeded; copies of a vertex
    (``welded``) share their values. Where every part has one material (and no vertex colours)
    no ray is cast: the flag is V < 1 and the share of hits 1 - V."""
    out = [np.zeros((len(p.positions), 8), np.float32) for p in parts]
    if not parts:
        return out
    materials = list(materials)
    if all(m == materials[0] and not m.vertex_colors for m in materials):
        # One material (a single-material asset, the scene's material on every part): every hit
        # records the same values, so no ray is needed (DamagedHelmet's pass took 3.7 s). The
        # flag where the vertex is occluded at all (V < 1); the share of hits as 1 - V.
        m = materials[0]
        albedo = occluder_base_albedo(np.asarray(m.base_color, np.float64), float(m.metallic), np.asarray(m.specular_f0))
        for k, p in enumerate(parts):
            hit = (np.asarray(p.visibility, np.float64) < 1.0)[:, None]
            out[k] = np.column_stack([hit * albedo, hit, hit * np.asarray(m.emission, np.float64),
                                      1.0 - np.asarray(p.visibility, np.float64)]).astype(np.float32)
        return out
    positions, eps, offsets, faces, all_f, all_n = merged_parts(parts)
    albedo, emission = [], []
    for p, m in zip(parts, materials):
        base = np.broadcast_to(np.asarray(m.base_color, np.float64), (len(p.positions), 3))
        if m.vertex_colors and p.colors is not None:
            base = base * np.asarray(p.colors, np.float64)[:, :3]
        albedo.append(occluder_base_albedo(base, np.full(len(p.positions), float(m.metallic)), np.asarray(m.specular_f0)))
        emission.append(np.broadcast_to(np.asarray(m.emission, np.float64), (len(p.positions), 3)))
    albedo, emission = np.concatenate(albedo), np.concatenate(emission)
    visibility = np.concatenate([p.visibility for p in parts]).astype(np.float64)
    refined = _Occluders(positions[all_f], one_way=one_way_triangles(parts))
    origins = np.concatenate([_origins(positions[a:b], all_n[a:b], f, eps)
                              for f, a, b in zip(faces, offsets[:-1], offsets[1:])])
    hit, uv, _ = refined.hemisphere(origins, all_n.astype(np.float32), bounce_rays, np.random.default_rng(seed), eps)
    count = len(positions)
    rows, cols = np.nonzero(hit >= 0)
    corners = all_f[hit[rows, cols]]
    huv = uv[rows, cols].astype(np.float64)
    w = np.column_stack([1.0 - huv[:, 0] - huv[:, 1], huv[:, 0], huv[:, 1]])
    weight = np.einsum("hk,hk->h", w, visibility[corners]) + 1e-3
    a_hit = np.einsum("hk,hkc->hc", w, albedo[corners])
    e_hit = np.einsum("hk,hkc->hc", w, emission[corners])
    hits = np.bincount(rows, minlength=count).astype(np.float64)
    total = np.bincount(rows, weight, minlength=count)
    values = np.zeros((count, 8))
    for c in range(3):
        values[:, c] = np.bincount(rows, weight * a_hit[:, c], minlength=count) / np.maximum(total, 1e-30)
        values[:, 4 + c] = np.bincount(rows, e_hit[:, c], minlength=count) / np.maximum(hits, 1.0)
    values[:, 3] = hits > 0
    values[:, 7] = hits / bounce_rays
    for k, (p, f, a, b) in enumerate(zip(parts, faces, offsets[:-1], offsets[1:])):
        ids = welded(p.positions, p.normals)
        out[k] = on_welded(values[a:b], f, ids, lambda v, _f: v).astype(np.float32)
    return out


def occluder_materials_key(visibility_key_: str, materials, bounce_rays: int = DEFAULT_BOUNCE_RAYS) -> tuple[str, dict]:
    """The cache key of ``bake_occluder_materials`` over the bake ``visibility_key_`` for these
    ``materials`` (a new colour or emission is a new key; the geometry's bake is kept)."""
    description = {"what": "occluder-materials", "version": OCCLUDER_MATERIAL_VERSION,
                   "visibility": visibility_key_, "materials": [m.described() for m in materials],
                   "bounce_rays": bounce_rays}
    text = json.dumps(description, sort_keys=True)
    return "alight-occluder-materials-" + hashlib.sha256(text.encode()).hexdigest(), description

# ---- the cache ----------------------------------------------------------------------------------

VISIBILITY_FIELDS = ("positions", "normals", "uvs", "tangents", "indices", "uvs1", "colors",
           "visibility", "bent_normal", "bounce_direction", "bounce_weight")


def mesh_digest(mesh) -> str:
    """sha256 of the mesh's geometry (every part's vertex attributes and indices, in order)."""
    h = hashlib.sha256()
    for part in mesh.parts:
        for a in _attributes(part) + [np.asarray(part.indices, np.int64)]:
            h.update(str(a.shape).encode())
            h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def visibility_key(mesh, rays: int, edge_fraction: float, max_vertices: int,
                   light_through=None) -> tuple[str, dict]:
    """The cache key of a visibility bake and the description it hashes (``light_through``: as
    bake_visibility's; an all-opaque mesh keeps the key it had before the parameter existed)."""
    description = {"what": "visibility", "version": BAKE_VERSION, "mesh": mesh_digest(mesh), "rays": rays,
                   "edge_fraction": edge_fraction, "max_vertices": max_vertices,
                   "coarse_fraction": DEFAULT_COARSE_FRACTION, "bounce_rays": DEFAULT_BOUNCE_RAYS,
                   "threshold": DEFAULT_THRESHOLD}
    if light_through is not None and any(float(t) > 0.0 for t in light_through):
        description["light_through"] = [round(float(t), 6) for t in light_through]
    # The geometry's digest leaves the materials out: which parts are single-sided is said here.
    description["single_sided"] = [i for i, p in enumerate(mesh.parts) if single_sided(p)]
    text = json.dumps(description, sort_keys=True)
    return "alight-visibility-" + hashlib.sha256(text.encode()).hexdigest(), description


def refined_mesh_part(part, vis: PartVisibility):
    """A MeshPart with the refined geometry of ``vis`` and ``part``'s material, name and element."""
    return dataclasses.replace(part, positions=vis.positions, normals=vis.normals, uvs=vis.uvs,
                               tangents=vis.tangents, indices=vis.indices, uvs1=vis.uvs1, colors=vis.colors)
