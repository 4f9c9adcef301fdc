"""The visible sky weight: the share of the environment's *light* a vertex sees, per channel.

The visibility bake's V (app/core/visibility.py) is the cosine-weighted share of the *directions*
a vertex sees the sky in. Under a strongly non-uniform map the two differ: inside a bowl under
newport_loft (bright windows near the horizon) the floor sees the dim ceiling, not the windows,
and V times the irradiance at the bent normal lit it with light it cannot see. So, per vertex of
a bake and per RGB channel, over the same kind of cosine-weighted rays (DEFAULT_RAYS about the
vertex normal):

    W = sum_rays free(l) L(l) / sum_rays L(l)

``free``: 1 where the ray escapes, 0 where an opaque part stops it, a see-through part's share
(as the bake's V); L: the environment's radiance in direction l, read from a small mip of the
IBL's source cube without its compact sources (``SKY_TEXELS`` texels a face, the cube the
irradiance map is made from), the environment rotation applied (CONVENTIONS.md: the radiance
from world direction d is the map's in R_y(-deg) d). Under a uniform environment W is exactly
the same rays' V.

Two passes, cached apart (app/render/visibility_parts.py): ``sky_rays`` casts the rays once per
bake (their free shares as uint8 and each vertex's frame angle, so the directions can be made
again), ``sky_weight`` reads the environment along them (numpy, no ray): a new map or rotation
reruns only the second. Vertices none of whose rays escape (buried in another part) take their
neighbours' values (as the bake's _fill_covered); then ``SMOOTHING_ROUNDS`` rounds of averaging
over mesh neighbours cut the rays' noise (numerator and denominator alike, so a uniform
environment still gives V).

The shader (shaders/common/occlusion.glsl's sky_visibility; its numpy twin
alight.core.visibility.sky_visibility, with the other shader terms' twins)
gets W and the same rays' V per vertex and uses ``min(V_c W / V_rays, 1)`` per channel in place
of V_c (the combined visibility) on the irradiance at the shading normal: under a uniform
environment W / V_rays = 1 and it is V_c as before; elsewhere W / V_rays is the visible sky's
mean radiance over the hemisphere's. The occluded share (1 - V_c, directions) still sees the
bounce, and the specular occlusion keeps the visibility cone of V (both geometric).
"""

from __future__ import annotations

import hashlib
import json
import math

import numpy as np

from alight.core.shading import rotate_world_to_map
from alight.core.visibility import _frame, _origins, _Transmittance, cosine_directions, fill_rings, merged_parts
from alight.core.visibility import on_welded, welded  # noqa: F401  (the weight's fill and smoothing run welded)
from alight.core.visibility import sky_visibility  # noqa: F401  (the shader term's twin lives with the others)

SKY_WEIGHT_VERSION = 4   # 2: filled and smoothed on the welded mesh (welded); 3: single-sided parts one-way;
                         # 4: welded's crease angle 30 -> 10 degrees
SKY_TEXELS = 16          # texels per cube face read back (the source cube's box mip of that size)
SMOOTHING_ROUNDS = 2     # rounds of averaging over mesh neighbours
SKY_SEED = 7             # the rays' own seed (another set than the bake's)


# ---- the environment as a small cube --------------------------------------------------------

def cube_texel_directions(size: int) -> np.ndarray:
    """Unit directions of a cube level's texel centres, (6, size, size, 3), OpenGL's face order
    +X -X +Y -Y +Z -Z, row 0 the first row in memory (common/cubemap.glsl's cube_texel_direction,
    as alight.ibl.bake.read_cube returns the faces)."""
    c = 2.0 * (np.arange(size) + 0.5) / size - 1.0
    t, s = np.meshgrid(c, c, indexing="ij")
    one = np.ones_like(s)
    faces = [(one, -t, -s), (-one, -t, s), (s, one, t), (s, -one, -t), (s, -t, one), (-s, -t, -one)]
    d = np.stack([np.stack(f, axis=-1) for f in faces])
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def cube_lookup(texels: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """The nearest texel of ``texels`` (6, S, S, C) in each of ``directions`` (..., 3) (map
    space): (..., C). The inverse of ``cube_texel_directions``."""
    d = np.asarray(directions, np.float64)
    size = texels.shape[1]
    flat = d.reshape(-1, 3)
    a = np.abs(flat)
    axis = np.argmax(a, axis=1)
    major = np.maximum(a[np.arange(len(flat)), axis], 1e-30)
    x, y, z = flat[:, 0] / major, flat[:, 1] / major, flat[:, 2] / major
    positive = flat[np.arange(len(flat)), axis] >= 0.0
    face = 2 * axis + (~positive)
    # (s, t) per face, from the face table of cube_texel_directions.
    s = np.select([face == 0, face == 1, face == 2, face == 3, face == 4], [-z, z, x, x, x], -x)
    t = np.select([face == 0, face == 1, face == 2, face == 3, face == 4], [-y, -y, z, -z, -y], -y)
    col = np.clip(((s + 1.0) * 0.5 * size).astype(np.int64), 0, size - 1)
    row = np.clip(((t + 1.0) * 0.5 * size).astype(np.int64), 0, size - 1)
    return texels[face, row, col].reshape(d.shape[:-1] + (texels.shape[-1],))


def texels_digest(texels: np.ndarray) -> str:
    """sha256 of the read-back texels (float32): the cache key's environment."""
    a = np.ascontiguousarray(texels, np.float32)
    return hashlib.sha256(str(a.shape).encode() + a.tobytes()).hexdigest()


def uniform_texels(value=(1.0, 1.0, 1.0), size: int = SKY_TEXELS) -> np.ndarray:
    return np.broadcast_to(np.asarray(value, np.float32), (6, size, size, 3)).copy()


# ---- the rays -----------------------------------------------------------------------------

def ray_directions(normals: np.ndarray, angles: np.ndarray, rays: int) -> np.ndarray:
    """(N, R, 3) world directions of each vertex's rays: visibility.cosine_directions(rays) about
    +Z, turned onto the unit normal in the frame spun by the vertex's angle (as the bake's
    _ray_chunks)."""
    n = np.asarray(normals, np.float64)
    t, b = _frame(n)
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    t, b = c * t + s * b, c * b - s * t
    frame = np.stack([t, b, n], axis=1)                    # (N, 3, 3): rows t, b, n
    return np.einsum("rk,nkc->nrc", cosine_directions(rays), frame)


def sky_rays(parts, rays: int, seed: int = SKY_SEED, light_through=None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per part of a bake (PartVisibility: refined, world space), (free (N, R) uint8: each ray's
    free share times 255, angle (N,) float32: the frame's spin, for ``ray_directions``): ``rays``
    cosine-weighted rays about each vertex normal from the bake's ray origins, against the
    refined mesh (Embree). An opaque part stops a ray; a see-through one (``light_through`` per
    part, as the bake's) passes its share of the first one met."""
    out = [(np.zeros((len(p.positions), rays), np.uint8), np.zeros(len(p.positions), np.float32)) for p in parts]
    if not parts or not sum(len(p.positions) for p in parts):
        return out
    positions, eps, offsets, faces, all_f, all_n = merged_parts(parts)
    transmittance = _Transmittance(parts, positions, faces, all_f, light_through)
    origins = np.concatenate([_origins(positions[a:b], all_n[a:b], f, eps)
                              for f, a, b in zip(faces, offsets[:-1], offsets[1:])])
    rng = np.random.default_rng(seed)
    count = len(positions)
    angles = rng.uniform(0.0, 2.0 * math.pi, count)
    free = np.empty((count, rays), np.uint8)
    chunk = max(1, 262_144 // rays)
    for s0 in range(0, count, chunk):
        s1 = min(s0 + chunk, count)
        d = np.ascontiguousarray(ray_directions(all_n[s0:s1], angles[s0:s1], rays).reshape(-1, 3), np.float32)
        o = np.ascontiguousarray(np.repeat(origins[s0:s1], rays, axis=0))
        w = transmittance.along(o, d, eps)
        free[s0:s1] = np.round(w * 255.0).astype(np.uint8).reshape(s1 - s0, rays)
    angles = angles.astype(np.float32)
    return [(free[a:b], angles[a:b]) for a, b in zip(offsets[:-1], offsets[1:])]


# ---- the weight -----------------------------------------------------------------------------

def _neighbour_edges(faces: np.ndarray) -> np.ndarray:
    """(E, 2) both ways (from, to), each edge of the (M, 3) ``faces`` once per direction."""
    f = np.asarray(faces, np.int64).reshape(-1, 3)
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    e = np.unique(np.sort(e, axis=1), axis=0)
    return np.concatenate([e, e[:, ::-1]])


def smooth(values: np.ndarray, edges: np.ndarray, rounds: int) -> np.ndarray:
    """``rounds`` rounds of each row becoming the mean of itself and its mesh neighbours
    (``edges``: ``_neighbour_edges``)."""
    out = np.array(values, np.float64, copy=True)
    if rounds <= 0 or not len(out):
        return out
    count = len(out)
    degree = np.bincount(edges[:, 1], minlength=count).astype(np.float64)
    for _ in range(rounds):
        sums = np.column_stack([np.bincount(edges[:, 1], out[edges[:, 0], k], minlength=count)
                                for k in range(out.shape[1])])
        out = (out + sums) / (1.0 + degree)[:, None]
    return out


def vertex_sky_weight(free: np.ndarray, directions: np.ndarray, texels: np.ndarray,
                      rotation_deg: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per vertex, unsmoothed: (sum free L (N, 3), sum L (N, 3), the rays' V (N,)); ``free``
    (N, R) in [0, 1], ``directions`` (N, R, 3) world, ``texels`` (6, S, S, 3) map space."""
    f = np.asarray(free, np.float64)
    radiance = cube_lookup(texels, rotate_world_to_map(directions, rotation_deg)).astype(np.float64)
    total = radiance.sum(axis=1)
    seen = np.einsum("nr,nrc->nc", f, radiance)
    return seen, total, f.mean(axis=1)


def sky_weight(free: np.ndarray, angles: np.ndarray, normals: np.ndarray, faces: np.ndarray, texels: np.ndarray,
               rotation_deg: float = 0.0, rounds: int = SMOOTHING_ROUNDS, chunk: int = 4096,
               positions: np.ndarray | None = None) -> np.ndarray:
    """One part's (N, 4) float32: W (rgb) and the same rays' V, both filled where no ray escapes
    and smoothed alike. ``free`` (N, R) uint8 (``sky_rays``) or float in [0, 1]; ``angles``,
    ``normals`` (N, 3) the bake's vertex normals; ``faces`` (M, 3); ``texels`` (6, S, S, 3), the
    environment in map space; ``rotation_deg``: the environment's rotation. ``positions`` (N, 3):
    the fill and the smoothing run on the welded mesh (``welded``), copies of a vertex alike."""
    free = np.asarray(free)
    scale = 1.0 / 255.0 if free.dtype == np.uint8 else 1.0
    n = np.asarray(normals, np.float64)
    n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    count, rays = free.shape
    seen = np.zeros((count, 3))
    total = np.zeros((count, 3))
    vis = np.zeros(count)
    for s0 in range(0, count, chunk):
        s1 = min(s0 + chunk, count)
        d = ray_directions(n[s0:s1], np.asarray(angles[s0:s1], np.float64), rays)
        seen[s0:s1], total[s0:s1], vis[s0:s1] = vertex_sky_weight(free[s0:s1] * scale, d, texels, rotation_deg)
    dark = total <= 1e-30 * np.maximum(total.max(), 1e-30)
    w = np.where(dark, vis[:, None], seen / np.where(dark, 1.0, total))
    values = np.column_stack([w, vis])
    ids = None if positions is None else welded(positions, n)

    def fill_and_smooth(v, f):
        # the rows none of whose rays escape take their neighbours' (as the bake's _fill_covered, no direction)
        edges = _neighbour_edges(f)
        return smooth(fill_rings(v, v[:, 3] <= 0.0, edges), edges, rounds)

    return on_welded(values, faces, ids, fill_and_smooth).astype(np.float32)


def sky_weight_key(visibility_key_: str, texels_digest_: str, rotation_deg: float, rays: int,
                   rounds: int = SMOOTHING_ROUNDS) -> tuple[str, dict]:
    """The cache key of the weight of the bake ``visibility_key_`` under an environment."""
    description = {"what": "sky-weight", "version": SKY_WEIGHT_VERSION, "visibility": visibility_key_,
                   "environment": texels_digest_, "rotation": round(float(rotation_deg) % 360.0, 6),
                   "rays": rays, "rounds": rounds, "seed": SKY_SEED, "welded": True}
    text = json.dumps(description, sort_keys=True)
    return "alight-sky-weight-" + hashlib.sha256(text.encode()).hexdigest(), description


def sky_rays_key(visibility_key_: str, rays: int, light_through=None) -> tuple[str, dict]:
    """The cache key of ``sky_rays`` over the bake ``visibility_key_``."""
    description = {"what": "sky-rays", "version": SKY_WEIGHT_VERSION, "visibility": visibility_key_,
                   "rays": rays, "seed": SKY_SEED}
    if light_through is not None and any(float(t) > 0.0 for t in light_through):
        description["light_through"] = [round(float(t), 6) for t in light_through]
    text = json.dumps(description, sort_keys=True)
    return "alight-sky-rays-" + hashlib.sha256(text.encode()).hexdigest(), description
