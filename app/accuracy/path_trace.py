"""A path tracer for whole scenes: docs/conventions.md's BRDF with visibility and inter-reflection.

``alight reference`` sums the environment per pixel with no occlusion: exact on a convex mesh,
blind to a corner, a bowl or a box on a floor. This module traces the same scene (the camera,
environment, lights and material factors of ``alight render``) with Intel's Embree
(``embreex``) for the rays and numpy for the rest:

    f = kd base/pi + D F G / (4 (n.l)(n.v)),  kd = (1 - F)(1 - metallic)    (docs/conventions.md)
    D: GGX (Walter et al. 2007), alpha = r^2; G: Smith with Schlick-GGX, k = r^2/2 for the
    environment and for light bouncing between surfaces (the ground truth's k), k = (r+1)^2/8
    for punctual lights (as the renderer and ``alight reference``); F: Schlick at v.h per direction.

Estimator (Veach 1997, chapter 9): at every surface vertex, next-event estimation of the
environment (a texel drawn in proportion to luminance x solid angle, a direction uniform in
it) and of each punctual light, each with a shadow ray; one BRDF sample (GGX half vectors by
D(h)(n.h), or cosine, picked by the lobes' estimated weights) carries the path on and, where it
escapes, picks up the environment. The environment's two strategies are combined with the power
heuristic. Paths end after ``max_bounces`` surface vertices, or earlier by Russian roulette
from the third on. Every number comes from one ``numpy.random.Generator(PCG64(seed))`` in a
fixed order: the same seed gives the same image to the bit on the same machine.

The environment is piecewise constant over its texels, looked up at the nearest texel, as the
exact reference sums it (docs/conventions.md's mapping and rotation); background pixels show the
environment along the camera ray, alpha is the covered fraction of the pixel's samples.
Transmission (KHR_materials_transmission's factor) is a thin wall: the share t (1 - metallic) of
what meets it goes straight on, chosen with that probability, shadow rays carry the product of
the walls' shares (no refraction, no Fresnel loss on the way through; alight's shadows and bake
weigh parts the same way, alight.render.visibility_parts.light_through).
KHR_materials_clearcoat's coat is traced as docs/layer_clearcoat.md defines it (the renderer's
and the exact reference's layering, alight.core.layers.clearcoat): f = f_base (1 - c F_c(n.v))
+ c F_c(n.v) D_c G_c / (4 (n.l)(n.v)), F0 = 0.04, the coat's normal the base's (no maps), with a
third lobe to sample (GGX at the coat's roughness, picked by c F_c(n.v) against the base's albedo).
The glTF material's maps apply per hit as the renderer applies them (alight.accuracy.path_trace_maps:
base colour x COLOR_0, metallicRoughness, emissive, normal, the coat's R and G; bilinear, no
mipmaps), and an alphaMode MASK part's texels below its cutoff are no surface for any ray. The
occlusion texture is not applied: it is baked visibility, which the paths find themselves.
Not modelled (refused or said in one warning line): the other layers (sheen, anisotropy,
iridescence, ...), the layers' other maps (transmission, specular, clearcoat normal, ...: their
factors apply), the user's maps (--map), alpha BLEND (opaque), the probe view.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from alight.accuracy.path_trace_maps import MASK_PASSES, SurfaceMaps, part_maps
from alight.core.layers.clearcoat import clearcoat_fresnel
from alight.core.mesh import single_sided
from alight.core.shading import (
    D_GGX,
    MIN_N_DOT_V,
    MIN_PUNCTUAL_ROUGHNESS,
    G1_SchlickGGX,
    k_direct,
    k_ibl,
    punctual_light,
    range_attenuation,
    spot_attenuation,
)
from alight.errors import AlightError

PI = math.pi
LUMA = np.array([0.2126, 0.7152, 0.0722])
# The smallest roughness traced: alpha = 1e-4 keeps D and its pdf finite in float64 while the
# lobe is narrower than any 1k map's texel (a mirror for every purpose here).
MIN_TRACE_ROUGHNESS = 0.01
# Paths traced together (memory ~ 2 kB per path at peak).
BATCH = 1 << 17
# From this surface vertex on, Russian roulette may end a path.
ROULETTE_FROM = 3


@dataclass
class TraceSettings:
    """``samples`` per pixel; ``max_bounces`` surface vertices per path (1: direct light only);
    ``seed`` of the generator; ``jitter``: samples spread over the pixel (False: its centre,
    as the exact reference and the G-buffer sample it)."""

    samples: int = 256
    max_bounces: int = 8
    seed: int = 0
    jitter: bool = True
    visibility: bool = True   # False: shadow rays always pass and paths stop after one vertex


@dataclass
class TraceResult:
    """``linear``: (H, W, 4) float32 radiance, row 0 at the top, alpha the covered fraction."""

    linear: np.ndarray
    samples: int
    seconds: dict[str, float] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


def _import_embree():
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
    except ImportError:
        raise AlightError("the path tracer needs Embree's Python binding: pip install 'alight[reference]' "
                          "(or pip install embreex)") from None
    return rtcore_scene, TriangleMesh


# --- the BRDF (docs/conventions.md), vectorised over paths ------------------------------------------

def _dot(a, b):
    return np.einsum("ij,ij->i", a, b)


def _rows(x, sub):
    """x[sub], or None for a lobe the scene does not have (the coat's arrays)."""
    return None if x is None else x[sub]


def _normalize(v):
    return v / np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-30)


def brdf_cos(n, v, l, base, metallic, roughness, f0, clearcoat=None, clearcoat_roughness=None):
    """docs/conventions.md's f(l, v) (n.l) with the ground truth's k = r^2/2; (N, 3). n, v, l: (N, 3)
    unit vectors; base, f0: (N, 3); metallic, roughness: (N,). n.v is floored at MIN_N_DOT_V and
    |l + v| at 1e-7, as the exact reference does. clearcoat, clearcoat_roughness (N,): the coat
    over it (coat_cos), or None."""
    n_dot_l = _dot(n, l)
    n_dot_v = np.maximum(_dot(n, v), MIN_N_DOT_V)
    lv = l + v
    h = lv / np.maximum(np.linalg.norm(lv, axis=1, keepdims=True), 1e-7)
    n_dot_h = _dot(n, h)
    v_dot_h = np.clip(_dot(v, h), 0.0, 1.0)
    F = f0 + (1.0 - f0) * ((1.0 - v_dot_h) ** 5)[:, None]
    kd = (1.0 - F) * (1.0 - metallic)[:, None]
    a2 = roughness ** 4
    d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0
    D = a2 / (PI * d * d)
    k = roughness * roughness / 2.0
    nl = np.maximum(n_dot_l, 1e-12)
    G = (n_dot_v / (n_dot_v * (1.0 - k) + k)) * (nl / (nl * (1.0 - k) + k))
    spec = (D * G / (4.0 * nl * n_dot_v))[:, None] * F
    out = (kd * base / PI + spec) * n_dot_l[:, None]
    if clearcoat is not None:
        out = out * coat_base_weight(n, v, clearcoat)[:, None] + coat_cos(n, v, l, clearcoat, clearcoat_roughness,
                                                                           False)[:, None]
    return np.where((n_dot_l > 0.0)[:, None], out, 0.0)


def coat_base_weight(n, v, clearcoat):
    """What the coat lets through to the base: 1 - c F_c(n.v); (N,)."""
    return 1.0 - clearcoat * clearcoat_fresnel(_dot(n, v))


def coat_cos(n, v, l, clearcoat, clearcoat_roughness, punctual):
    """The coat's c F_c(n.v) D G / (4 (n.l)(n.v)) (n.l), as alight.core.layers.clearcoat's
    clearcoat_light per row (D's roughness floored at MIN_PUNCTUAL_ROUGHNESS, k = r^2/2, or the
    punctual k and floor for a light); (N,), 0 where n.l <= 0."""
    n_dot_l = _dot(n, l)
    n_dot_v = np.maximum(_dot(n, v), MIN_N_DOT_V)
    h = _normalize(l + v)
    n_dot_h = np.maximum(_dot(n, h), 0.0)
    r = np.maximum(clearcoat_roughness, MIN_PUNCTUAL_ROUGHNESS)
    k = k_direct(r) if punctual else k_ibl(r)
    nl = np.maximum(n_dot_l, 1e-12)
    lobe = D_GGX(n_dot_h, r) * G1_SchlickGGX(n_dot_v, k) * G1_SchlickGGX(nl, k) / (4.0 * n_dot_v)
    out = clearcoat * clearcoat_fresnel(_dot(n, v)) * lobe
    return np.where(n_dot_l > 0.0, out, 0.0)


def _coat_probability(n_dot_v, base, metallic, f0, clearcoat):
    """The chance of sampling the coat's lobe: its weight c F_c(n.v) against what the base under
    it reflects (its Fresnel and diffuse albedo, times 1 - c F_c), in [0.05, 0.95] where a coat
    is present, else 0."""
    fc = clearcoat * clearcoat_fresnel(n_dot_v)
    F = f0 + (1.0 - f0) * ((1.0 - np.clip(n_dot_v, 0.0, 1.0)) ** 5)[:, None]
    under = (F + (1.0 - F) * (1.0 - metallic)[:, None] * base) @ LUMA * (1.0 - fc)
    p = fc / np.maximum(fc + under, 1e-12)
    return np.where(clearcoat > 0.0, np.clip(p, 0.05, 0.95), 0.0)


def _specular_probability(n_dot_v, base, metallic, f0):
    """The chance of sampling the GGX lobe: its Fresnel weight at n.v against the diffuse
    albedo's, kept in [0.05, 0.95] while both are present (1 for a metal)."""
    F = f0 + (1.0 - f0) * ((1.0 - np.clip(n_dot_v, 0.0, 1.0)) ** 5)[:, None]
    s = F @ LUMA
    d = ((1.0 - F) * (1.0 - metallic)[:, None] * base) @ LUMA
    p = s / np.maximum(s + d, 1e-12)
    return np.where(d <= 0.0, 1.0, np.clip(p, 0.05, 0.95))


def _frame(n):
    """An orthonormal (t, b) around each unit n (Duff et al. 2017)."""
    sign = np.where(n[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + sign * n[:, 0] ** 2 * a, sign * b, -sign * n[:, 0]], axis=1)
    bb = np.stack([b, sign + n[:, 1] ** 2 * a, -n[:, 1]], axis=1)
    return t, bb


def _ggx_reflection_pdf(n_dot_h, v_dot_h, roughness):
    a2 = roughness ** 4
    d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0
    return a2 / (PI * d * d) * n_dot_h / (4.0 * v_dot_h)


def brdf_pdf(n, v, l, roughness, p_spec, p_coat=None, coat_roughness=None):
    """Solid-angle pdf of ``sample_brdf``'s mixture at l; (N,)."""
    n_dot_l = _dot(n, l)
    h = _normalize(l + v)
    n_dot_h = np.clip(_dot(n, h), 0.0, 1.0)
    v_dot_h = np.maximum(_dot(v, h), 1e-12)
    pdf_spec = _ggx_reflection_pdf(n_dot_h, v_dot_h, roughness)
    pdf_diff = np.maximum(n_dot_l, 0.0) / PI
    pdf = p_spec * pdf_spec + (1.0 - p_spec) * pdf_diff
    if p_coat is not None:
        pdf_coat = _ggx_reflection_pdf(n_dot_h, v_dot_h, np.maximum(coat_roughness, MIN_PUNCTUAL_ROUGHNESS))
        pdf = p_coat * pdf_coat + (1.0 - p_coat) * pdf
    return np.where(n_dot_l > 0.0, pdf, 0.0)


def sample_brdf(n, v, roughness, p_spec, xi, p_coat=None, coat_roughness=None):
    """Directions l (N, 3): GGX half vectors drawn by D(h)(n.h) (Walter et al. 2007) reflected
    about h with chance p_spec, else cosine-weighted; xi (N, 3) uniform in [0, 1). With p_coat,
    the coat's GGX lobe (roughness floored as coat_cos's D) first, with that chance."""
    t, b = _frame(n)
    xi0 = xi[:, 0]
    coat = np.zeros(len(xi0), bool)
    if p_coat is not None:
        coat = xi0 < p_coat
        xi0 = np.where(coat, xi0 / np.maximum(p_coat, 1e-12), (xi0 - p_coat) / np.maximum(1.0 - p_coat, 1e-12))
        xi0 = np.clip(xi0, 0.0, 1.0 - 1e-12)
        roughness = np.where(coat, np.maximum(coat_roughness, MIN_PUNCTUAL_ROUGHNESS), roughness)
    a2 = roughness ** 4
    phi = 2.0 * PI * xi[:, 1]
    spec = (xi0 < p_spec) | coat
    u = np.where(spec, xi0 / np.maximum(p_spec, 1e-12), (xi0 - p_spec) / np.maximum(1.0 - p_spec, 1e-12))
    u = np.clip(u, 0.0, 1.0 - 1e-12)
    # GGX: cos^2(theta_h) = (1 - u) / (1 + (a^2 - 1) u); cosine: cos^2(theta) = 1 - u
    cos2_h = (1.0 - xi[:, 2]) / (1.0 + (a2 - 1.0) * xi[:, 2])
    cos2 = np.where(spec, cos2_h, 1.0 - u)
    cos_t = np.sqrt(np.clip(cos2, 0.0, 1.0))
    sin_t = np.sqrt(np.clip(1.0 - cos2, 0.0, 1.0))
    local = (np.cos(phi) * sin_t)[:, None] * t + (np.sin(phi) * sin_t)[:, None] * b + cos_t[:, None] * n
    h = local
    reflected = 2.0 * _dot(v, h)[:, None] * h - v
    return np.where(spec[:, None], reflected, local)


# --- the environment: lookup and importance sampling ---------------------------------------------

class EnvironmentSampler:
    """An equirect map (H, W, 3) as docs/conventions.md maps it, piecewise constant per texel, turned
    by ``rotation_deg`` and scaled by ``intensity``; texels drawn in proportion to luminance x
    solid angle (plus 1% of a uniform choice, so no lit direction has pdf 0)."""

    def __init__(self, radiance: np.ndarray, rotation_deg: float = 0.0, intensity: float = 1.0):
        self.radiance = np.asarray(radiance, np.float64)[..., :3] * float(intensity)
        h, w = self.radiance.shape[:2]
        self.h, self.w = h, w
        theta = np.arange(h + 1) * (PI / h)
        self.cos_edges = np.cos(theta)
        self.solid_angle = (2.0 * PI / w) * (self.cos_edges[:-1] - self.cos_edges[1:])   # (H,) per texel
        t = math.radians(rotation_deg)
        self.c, self.s = math.cos(t), math.sin(t)
        lum = np.maximum(self.radiance @ LUMA, 0.0) * self.solid_angle[:, None]
        total = float(lum.sum())
        weights = lum.ravel() / total if total > 0.0 else np.zeros(lum.size)
        uniform = np.repeat(self.solid_angle / (4.0 * PI), w) / 1.0
        self.p = 0.99 * weights + 0.01 * uniform if total > 0.0 else uniform
        self.p /= self.p.sum()
        self.cdf = np.cumsum(self.p)
        self.cdf[-1] = 1.0

    def _to_map(self, d):
        # docs/conventions.md: light from world d is the map's radiance in R_y(-deg) d.
        c, s = self.c, -self.s
        return np.stack([c * d[:, 0] + s * d[:, 2], d[:, 1], -s * d[:, 0] + c * d[:, 2]], axis=1)

    def _to_world(self, d):
        c, s = self.c, self.s
        return np.stack([c * d[:, 0] + s * d[:, 2], d[:, 1], -s * d[:, 0] + c * d[:, 2]], axis=1)

    def _texel(self, d_world):
        d = self._to_map(d_world)
        u = 0.5 + np.arctan2(d[:, 0], -d[:, 2]) / (2.0 * PI)
        v = np.arccos(np.clip(d[:, 1], -1.0, 1.0)) / PI
        col = np.clip((u * self.w).astype(np.int64), 0, self.w - 1)
        row = np.clip((v * self.h).astype(np.int64), 0, self.h - 1)
        return row, col

    def lookup(self, d_world):
        """Radiance (N, 3) arriving from world directions d (N, 3)."""
        row, col = self._texel(d_world)
        return self.radiance[row, col]

    def pdf(self, d_world):
        """Solid-angle pdf (N,) of ``sample`` at d."""
        row, col = self._texel(d_world)
        return self.p[row * self.w + col] / self.solid_angle[row]

    def sample(self, xi):
        """World directions (N, 3), their radiance (N, 3) and pdf (N,); xi (N, 3) uniform."""
        index = np.minimum(np.searchsorted(self.cdf, xi[:, 0], side="right"), self.p.size - 1)
        row, col = np.divmod(index, self.w)
        phi = (col + xi[:, 1]) * (2.0 * PI / self.w) - PI
        cos_t = self.cos_edges[row] + xi[:, 2] * (self.cos_edges[row + 1] - self.cos_edges[row])
        sin_t = np.sqrt(np.clip(1.0 - cos_t * cos_t, 0.0, 1.0))
        d_map = np.stack([sin_t * np.sin(phi), cos_t, -sin_t * np.cos(phi)], axis=1)
        return self._to_world(d_map), self.radiance[row, col], self.p[index] / self.solid_angle[row]


# --- the scene as triangles ---------------------------------------------------------------------------

@dataclass
class _Geometry:
    v0: np.ndarray          # (M, 3) float64 triangle corners
    e1: np.ndarray
    e2: np.ndarray
    normals: np.ndarray     # (M, 3, 3) vertex normals per corner
    ng: np.ndarray          # (M, 3) unit geometric normals (counter-clockwise front)
    material: np.ndarray    # (M,) index into the material table
    table: dict             # name -> (K, ...) arrays: base, metallic, roughness, f0, emissive
    scale: float            # the scene's size, for ray offsets
    one_way: np.ndarray | None = None   # (M,) bool: single-sided triangles (alight.core.mesh.single_sided)
    maps: SurfaceMaps | None = None     # the parts' texture maps, COLOR_0 and alpha masks (None: factors only)


def scene_geometry(scene) -> tuple[_Geometry, list[str]]:
    """The scene's triangles, per-part material factors (as the renderer resolves them) and
    maps (``_Geometry.maps``: None where no part has a traced map, COLOR_0 or alpha mask), and
    one-line warnings about what the path tracer leaves out."""
    from alight.render.variants import part_material

    mesh = scene.mesh
    warnings: list[str] = []
    corners, normals, mats, sided = [], [], [], []
    table = {k: [] for k in ("base", "metallic", "roughness", "f0", "specular_f0", "emissive", "through", "clearcoat",
                             "clearcoat_roughness")}
    # The user's maps (--map, --texture-set) are not traced.
    user_maps = bool(getattr(scene, "texture_maps", None))
    layered = blended = False
    untraced: set[str] = set()
    surface_maps = SurfaceMaps()
    for index, part in enumerate(mesh.parts):
        m, maps_apply = part_material(scene, part)
        if m.layers() - {"transmission", "clearcoat"}:
            layered = True
        # KHR_materials_transmission as a thin wall: the share t (1 - metallic) goes straight on
        # (no refraction, no Fresnel loss), the rest meets the base BRDF.
        table["through"].append(float(m.transmission) * (1.0 - float(m.metallic)))
        fm = part.material
        if maps_apply and fm is not None:
            blended |= fm.alpha_mode == "BLEND"
        tri = np.asarray(part.indices, np.int64).reshape(-1, 3)
        pm, left_out = part_maps(part, m, maps_apply, scene.use_file_materials)
        untraced |= left_out
        surface_maps.add(part, tri, pm)
        pos = np.asarray(part.positions, np.float64)
        corners.append(pos[tri])
        normals.append(np.asarray(part.normals, np.float64)[tri])
        mats.append(np.full(len(tri), index, np.int64))
        sided.append(np.full(len(tri), single_sided(part)))
        table["base"].append(m.base_color)
        table["metallic"].append(m.metallic)
        r = float(m.roughness)
        if r < MIN_TRACE_ROUGHNESS:
            warnings.append(f"{mesh.source}: roughness {r:g} is traced as {MIN_TRACE_ROUGHNESS} (a mirror)")
        table["roughness"].append(max(r, MIN_TRACE_ROUGHNESS))
        table["f0"].append(m.f0())
        table["specular_f0"].append(m.specular_f0)
        table["emissive"].append(m.emissive)
        table["clearcoat"].append(float(m.clearcoat))
        table["clearcoat_roughness"].append(max(float(m.clearcoat_roughness), MIN_TRACE_ROUGHNESS))
    if layered:
        raise AlightError(f"{mesh.source}: the path tracer has the base BRDF and the clearcoat only (no sheen, anisotropy, "
                          "iridescence; "
                          "transmission as a thin wall); use the exact reference (--integrator exact) for layered "
                          "materials")
    if user_maps:
        warnings.append(f"{mesh.source}: the path tracer leaves out the user's texture maps (--map, --texture-set): "
                        "the material factors apply")
    if untraced:
        warnings.append(f"{mesh.source}: the path tracer leaves out these texture maps (their factors apply): "
                        + ", ".join(sorted(untraced)))
    if blended:
        warnings.append(f"{mesh.source}: the path tracer draws alpha BLEND parts as opaque")
    tris = np.concatenate(corners)
    v0, v1, v2 = tris[:, 0], tris[:, 1], tris[:, 2]
    ng = np.cross(v1 - v0, v2 - v0)
    keep = np.linalg.norm(ng, axis=1) > 0.0
    lo, hi = mesh.bounds()
    geom = _Geometry(v0=v0[keep], e1=(v1 - v0)[keep], e2=(v2 - v0)[keep], normals=np.concatenate(normals)[keep],
                     ng=_normalize(ng[keep]), material=np.concatenate(mats)[keep],
                     table={k: np.asarray(v, np.float64) for k, v in table.items()},
                     scale=float(max(np.linalg.norm(hi - lo), 1e-6)), one_way=np.concatenate(sided)[keep],
                     maps=surface_maps.finish(keep))
    return geom, warnings


class _Rays:
    """Embree's scene, queried in float32 for hits and shadow rays. Single-sided triangles
    (``geom.one_way``) are one-way: a camera ray passes the ones it meets from behind (the camera
    pass culls their back faces); for every other ray (shadow rays, the paths' bounces) they stop
    light only where it meets their front, as a shadow map culling the faces turned away from its
    light draws them: a ray from a surface that meets one's front is not stopped by it (the light
    coming back along the ray meets its back). The occlusion bake's rays do the same
    (alight.core.visibility._cast): a bounce that is stopped sees the first surface it met (a
    closed part's near wall), one that is not escapes. Where an alphaMode MASK part's alpha is
    below its cutoff there is no surface: every ray passes on (``geom.maps.cut_away``)."""

    def __init__(self, geom: _Geometry):
        rtcore_scene, TriangleMesh = _import_embree()
        self.scene = rtcore_scene.EmbreeScene()
        tris = np.stack([geom.v0, geom.v0 + geom.e1, geom.v0 + geom.e2], axis=1).astype(np.float32)
        self._mesh = TriangleMesh(scene=self.scene, vertices=tris)
        one_way = geom.one_way
        self.one_way = one_way if one_way is not None and one_way.any() else None
        self.ng = geom.ng
        self.eps = 1e-5 * geom.scale
        self.masked = None if geom.maps is None else geom.maps.masked_triangles(geom.material)
        self._geom = geom

    def _run(self, origins, dirs):
        out = self.scene.run(np.ascontiguousarray(origins, np.float32), np.ascontiguousarray(dirs, np.float32),
                             output=1)
        prim = np.asarray(out["primID"], np.int64)
        geom = np.asarray(out["geomID"], np.int64)
        prim = np.where(geom < 0, -1, prim)
        t, u, v = (np.asarray(out[k], np.float64) for k in ("tfar", "u", "v"))
        return prim, t, u, v

    def hit(self, origins, dirs, camera=False, seen: bool = True, passes: int = 8):
        """Triangle index (-1: none), distance, barycentrics u, v of each ray. ``camera`` (one
        bool, or one per ray): the rays are the camera's; the others, with ``seen``, report the
        first surface they meet where the light is stopped (a bounce), without it what stops the
        light (a shadow ray): the class's docstring. A ray still on a one-way face after
        ``passes`` re-casts (MASK_PASSES where a part has an alpha mask) stops there; a ray past
        a masked-out texel goes on as if the triangle were not there, for every kind of ray."""
        prim, t, u, v = self._run(origins, dirs)
        if self.one_way is None and self.masked is None:
            return prim, t, u, v
        origins = np.asarray(origins, np.float64)
        dirs = np.asarray(dirs, np.float64)
        camera = np.broadcast_to(np.asarray(camera, bool), (len(prim),))
        first = (prim.copy(), t.copy(), u.copy(), v.copy())
        # whether ``first`` holds a surface (a masked-out hit is none: the first one past it is)
        found = np.zeros(len(prim), bool)
        if self.masked is not None:
            passes = max(passes, MASK_PASSES)
        for _ in range(passes):
            hit = np.flatnonzero(prim >= 0)
            skip = np.zeros(len(hit), bool)
            if self.one_way is not None:
                facing = np.einsum("ij,ij->i", dirs[hit], self.ng[prim[hit]])
                skip = self.one_way[prim[hit]] & np.where(camera[hit], facing > 0.0, facing < 0.0)
            cut = np.zeros(len(hit), bool)
            if self.masked is not None:
                on = np.flatnonzero(self.masked[prim[hit]])
                if len(on):
                    h = hit[on]
                    cut[on] = self._geom.maps.cut_away(prim[h], u[h], v[h], self._geom.material)
            new = hit[~cut & ~found[hit]]
            for now, was in zip((prim, t, u, v), first):
                was[new] = now[new]
            found[new] = True
            skip |= cut
            again = hit[skip]
            if not len(again):
                break
            start = t[again] + 0.05 * self.eps   # (a thin part's far side may lie closer than eps)
            p2, t2, u2, v2 = self._run(origins[again] + dirs[again] * start[:, None], dirs[again])
            prim[again], t[again], u[again], v[again] = p2, t2 + start, u2, v2
        if seen:
            keep = ~camera & (prim >= 0) & found
            for now, was in zip((prim, t, u, v), first):
                now[keep] = was[keep]
        return prim, t, u, v

    def blocked(self, origins, dirs, dists):
        """True where something lies between each origin and its distance along dir."""
        if len(origins) == 0:
            return np.zeros(0, bool)
        prim, t, _, _ = self.hit(origins, dirs, seen=False)
        return (prim >= 0) & (t < dists)

    def transmittance(self, origins, dirs, dists, through, eps: float, walls: int = 8):
        """The share of light that reaches each origin from its distance along dir: 0 behind an
        opaque triangle, the product of ``through`` (per triangle) of the thin walls crossed."""
        out = np.ones(len(origins))
        todo = np.arange(len(origins))
        o, left = np.array(origins, np.float64), np.array(dists, np.float64)
        for _ in range(walls):
            if len(todo) == 0:
                break
            prim, t, _, _ = self.hit(o[todo], dirs[todo], seen=False)
            hit = (prim >= 0) & (t < left[todo])
            out[todo[hit]] *= through[prim[hit]]
            go = hit & (out[todo] > 0.0)
            todo, t = todo[go], t[go]
            o[todo] = o[todo] + dirs[todo] * (t + eps)[:, None]
            left[todo] -= t + eps
        out[todo] = 0.0     # more walls than counted: dark
        return out


def _camera_rays(camera, aspect, width, height, pix, rng, jitter):
    """World origins and unit directions for pixel indices pix (row-major from the top row),
    unprojected through the camera's view-projection matrix (pyrr's row-vector layout)."""
    inv = np.linalg.inv(np.asarray(camera.view_projection(aspect), np.float64))
    row, col = np.divmod(pix, width)
    off = rng.random((len(pix), 2)) if jitter else np.full((len(pix), 2), 0.5)
    x = 2.0 * (col + off[:, 0]) / width - 1.0
    y = 1.0 - 2.0 * (row + off[:, 1]) / height
    ones = np.ones_like(x)
    near = np.stack([x, y, -ones, ones], axis=1) @ inv
    far = np.stack([x, y, ones, ones], axis=1) @ inv
    near = near[:, :3] / near[:, 3:]
    far = far[:, :3] / far[:, 3:]
    return near, _normalize(far - near)


def _light_terms(light, p):
    """Unit directions toward the light (N, 3), incident radiance (N, 3) and shadow distance (N,)."""
    color = np.asarray(light.color, np.float64) * float(light.intensity)
    if light.kind == "directional":
        d = -np.asarray(light.vector, np.float64)
        d = np.broadcast_to(d / max(np.linalg.norm(d), 1e-30), p.shape)
        return d, np.broadcast_to(color, p.shape), np.full(len(p), np.inf)
    to = np.asarray(light.vector, np.float64) - p
    d2 = np.maximum(np.einsum("ij,ij->i", to, to), 1e-30)
    dist = np.sqrt(d2)
    l = to / dist[:, None]
    scale = range_attenuation(d2, light.range) / d2
    if light.kind == "spot":
        axis = np.asarray(light.direction, np.float64)
        axis = axis / max(np.linalg.norm(axis), 1e-30)
        cos_inner = math.cos(math.radians(light.inner_cone_deg))
        cos_outer = math.cos(math.radians(light.outer_cone_deg))
        s = 1.0 / max(0.001, cos_inner - cos_outer)
        scale = scale * spot_attenuation(-(l @ axis), s, -cos_outer * s)
    return l, color[None, :] * scale[:, None], dist


def trace(scene, radiance: np.ndarray | None, width: int, height: int,
          settings: TraceSettings | None = None) -> TraceResult:
    """Path-trace ``scene`` (camera view; ``scene.mesh`` required) lit by ``radiance`` ((H, 2H, 3)
    equirect, or None) and ``scene.lights``; see the module's docstring."""
    settings = settings or TraceSettings()
    if scene.view != "camera" or scene.mesh is None:
        raise AlightError("--integrator path: the path tracer renders the camera view of a mesh (the probe view "
                          "has nothing to occlude; use the exact reference)")
    if settings.samples < 1:
        raise AlightError(f"--samples: {settings.samples} must be at least 1")
    t0 = time.perf_counter()
    from alight.core.scene import default_camera

    geom, warnings = scene_geometry(scene)
    rays = _Rays(geom)
    if scene.camera is not None:
        camera = scene.camera
    else:   # as the renderer frames it (a built-in from its 3/4 view)
        camera = default_camera(scene.mesh, width / height)
    env = None
    if radiance is not None and scene.ibl_enabled and scene.env_intensity > 0.0:
        env = EnvironmentSampler(radiance, scene.env_rotation_deg, scene.env_intensity)
    t1 = time.perf_counter()
    rng = np.random.Generator(np.random.PCG64(settings.seed))
    npix = width * height
    total = npix * settings.samples
    accum = np.zeros((npix, 3))
    cover = np.zeros(npix)
    eps = 1e-5 * geom.scale
    tb = geom.table
    clear_parts = bool((tb["through"] > 0.0).any())
    through_of_triangle = tb["through"][geom.material]
    coated = bool((tb["clearcoat"] > 0.0).any())

    def shadow(origins, dirs, dists):
        """1 where the light is seen, 0 behind an opaque triangle, the thin walls' product between."""
        if not clear_parts:
            return (~rays.blocked(origins, dirs, dists)).astype(np.float64)
        return rays.transmittance(origins, dirs, dists, through_of_triangle, eps)
    # One dimension of the environment's and of the BRDF's samples is stratified over a pixel's
    # samples (sample s in [s, s + 1) / N, shifted per pixel and per strategy: Cranley-Patterson
    # rotation): it divides the noise of a compact sun by about 2 at 256 samples.
    shifts = rng.random((2, npix))
    for start in range(0, total, BATCH):
        idx = np.arange(start, min(total, start + BATCH))
        pix = idx % npix     # sample s of every pixel, then sample s + 1: a batch covers the image evenly
        stratum = idx // npix

        def stratified(xi, which, alive_paths):
            s_ = stratum[alive_paths]
            return np.mod((s_ + xi) / settings.samples + shifts[which, pix[alive_paths]], 1.0)
        origin, direction = _camera_rays(camera, width / height, width, height, pix, rng, settings.jitter)
        throughput = np.ones((len(pix), 3))
        radiance_sum = np.zeros((len(pix), 3))
        alive = np.arange(len(pix))
        prev_pdf = None   # the BRDF pdf of the ray that led here (None: the camera ray)
        for bounce in range(settings.max_bounces if settings.visibility else 1):
            # camera rays: the first, and those gone straight on through thin walls (pdf inf)
            prim, dist, bu, bv = rays.hit(origin, direction,
                                          camera=True if prev_pdf is None else np.isinf(prev_pdf))
            miss = prim < 0
            if bounce == 0:
                np.add.at(cover, pix[alive[~miss]], 1.0)
            if env is not None and miss.any():
                d = direction[miss]
                L = env.lookup(d)
                if prev_pdf is None:
                    w = np.ones(len(d))
                else:
                    pb = prev_pdf[miss]
                    pe = env.pdf(d)
                    seen = np.isinf(pb)     # a camera ray through thin walls: no other strategy
                    pb = np.where(seen, 1.0, pb)
                    w = np.where(seen, 1.0, pb * pb / np.maximum(pb * pb + pe * pe, 1e-300))
                radiance_sum[alive[miss]] += throughput[miss] * L * w[:, None]
            keep = ~miss
            alive, prim, dist, bu, bv = alive[keep], prim[keep], dist[keep], bu[keep], bv[keep]
            origin, direction, throughput = origin[keep], direction[keep], throughput[keep]
            if len(alive) == 0:
                break
            p = origin + direction * dist[:, None]
            nv = geom.normals[prim]
            n = _normalize((1.0 - bu - bv)[:, None] * nv[:, 0] + bu[:, None] * nv[:, 1] + bv[:, None] * nv[:, 2])
            ng = geom.ng[prim]
            v = -direction
            back = _dot(ng, v) < 0.0   # seen from behind: both normals turn to the viewer
            ng = np.where(back[:, None], -ng, ng)
            n = np.where(back[:, None], -n, n)
            m = geom.material[prim]
            if clear_parts:
                # a thin wall: the share it lets through goes straight on (chosen with that probability)
                on = rng.random(len(alive)) < tb["through"][m]
                if on.any():
                    nxt = np.flatnonzero(on)
                    passing = (alive[nxt], p[nxt] + direction[nxt] * eps, direction[nxt], throughput[nxt],
                               None if prev_pdf is None else prev_pdf[keep][nxt])
                    stay = ~on
                    alive, prim, dist, bu, bv, p, n, ng, v, m = (x[stay] for x in (alive, prim, dist, bu, bv, p, n, ng,
                                                                                  v, m))
                    origin, direction, throughput = origin[stay], direction[stay], throughput[stay]
                else:
                    passing = None
            base, metal, rough, f0 = tb["base"][m], tb["metallic"][m], tb["roughness"][m], tb["f0"][m]
            # the coat's weight and roughness, or None for every lobe function when no part has one
            coat, coat_rough = (tb["clearcoat"][m], tb["clearcoat_roughness"][m]) if coated else (None, None)
            emissive = tb["emissive"][m]
            if geom.maps is not None:
                base, metal, rough, emissive, coat, coat_rough, n = geom.maps.shade(
                    prim, bu, bv, m, n, base, metal, rough, emissive, coat, coat_rough, MIN_TRACE_ROUGHNESS)
                f0 = tb["specular_f0"][m] * (1.0 - metal)[:, None] + base * metal[:, None]   # Material.f0 per hit
            radiance_sum[alive] += throughput * emissive
            p_off = p + ng * eps
            last = bounce + 1 >= settings.max_bounces or not settings.visibility
            n_dot_v = _dot(n, v)
            p_spec = _specular_probability(n_dot_v, base, metal, f0)
            p_coat = _coat_probability(n_dot_v, base, metal, f0, coat) if coated else None
            # next-event estimation: the environment
            if env is not None:
                xi = rng.random((len(alive), 3))
                xi[:, 0] = stratified(xi[:, 0], 0, alive)
                l, L, pe = env.sample(xi)
                ok = (_dot(ng, l) > 0.0) & (_dot(n, l) > 0.0)
                seen = np.ones(len(alive))
                if settings.visibility and ok.any():
                    sub = np.flatnonzero(ok)
                    seen[sub] = shadow(p_off[sub], l[sub], np.full(len(sub), np.inf))
                    ok &= seen > 0.0
                if ok.any():
                    sub = np.flatnonzero(ok)
                    f = seen[sub, None] * brdf_cos(n[sub], v[sub], l[sub], base[sub], metal[sub], rough[sub], f0[sub],
                                                   _rows(coat, sub), _rows(coat_rough, sub))
                    pb = brdf_pdf(n[sub], v[sub], l[sub], rough[sub], p_spec[sub], _rows(p_coat, sub),
                                  _rows(coat_rough, sub))
                    # power heuristic: (f L / pe) pe^2 / (pe^2 + pb^2), where a BRDF sample follows;
                    # at a path's last vertex the environment sample is the only strategy
                    if last:
                        w = 1.0 / pe[sub]
                    else:
                        w = pe[sub] / np.maximum(pe[sub] ** 2 + pb * pb, 1e-300)
                    radiance_sum[alive[sub]] += throughput[sub] * f * L[sub] * w[:, None]
            # next-event estimation: the punctual lights (k = (r+1)^2/8, as the renderer)
            for light in scene.lights:
                l, Li, ldist = _light_terms(light, p)
                ok = (_dot(ng, l) > 0.0) & (_dot(n, l) > 0.0) & (Li.max(axis=1) > 0.0)
                seen = np.ones(len(alive))
                if settings.visibility and ok.any():
                    sub = np.flatnonzero(ok)
                    seen[sub] = shadow(p_off[sub], l[sub], ldist[sub] - 2.0 * eps)
                    ok &= seen > 0.0
                if ok.any():
                    sub = np.flatnonzero(ok)
                    lit = punctual_light(n[sub], v[sub], l[sub], base[sub], metal[sub],
                                         np.maximum(rough[sub], MIN_PUNCTUAL_ROUGHNESS), tb["specular_f0"][m[sub]], Li[sub])
                    if coated:
                        lit = (lit * coat_base_weight(n[sub], v[sub], coat[sub])[:, None]
                               + coat_cos(n[sub], v[sub], l[sub], coat[sub], coat_rough[sub], True)[:, None] * Li[sub])
                    radiance_sum[alive[sub]] += seen[sub, None] * throughput[sub] * lit
            if last:
                break
            # the BRDF sample that carries the path on
            xi = rng.random((len(alive), 3))
            xi[:, 2] = stratified(xi[:, 2], 1, alive)
            l = sample_brdf(n, v, rough, p_spec, xi, p_coat, coat_rough)
            pb = brdf_pdf(n, v, l, rough, p_spec, p_coat, coat_rough)
            ok = (_dot(ng, l) > 0.0) & (pb > 0.0)
            f = brdf_cos(n, v, l, base, metal, rough, f0, coat, coat_rough)
            throughput = throughput * f / np.maximum(pb, 1e-300)[:, None]
            if bounce + 1 >= ROULETTE_FROM:
                q = np.clip(throughput.max(axis=1), 0.05, 0.95)
                survive = rng.random(len(alive)) < q
                throughput = throughput / q[:, None]
                ok &= survive
            ok &= throughput.max(axis=1) > 0.0
            alive, origin, direction, throughput, prev_pdf = alive[ok], p_off[ok], l[ok], throughput[ok], pb[ok]
            if clear_parts and passing is not None:
                a_, o_, d_, t_, pp_ = passing
                alive, origin, direction, throughput = (np.concatenate([x, y]) for x, y in
                                                        ((alive, a_), (origin, o_), (direction, d_), (throughput, t_)))
                prev_pdf = np.concatenate([prev_pdf, pp_ if pp_ is not None else np.full(len(a_), np.inf)])
            if len(alive) == 0:
                break
        np.add.at(accum, pix, radiance_sum)
    t2 = time.perf_counter()
    out = np.zeros((npix, 4), np.float32)
    out[:, :3] = accum / settings.samples
    out[:, 3] = cover / settings.samples
    return TraceResult(out.reshape(height, width, 4), settings.samples,
                       {"setup": t1 - t0, "trace": t2 - t1}, warnings)

