"""Per-vertex visibility for still previews: ambient occlusion, bent normals and one diffuse bounce.

For every vertex of a mesh part, cosine-weighted rays over the hemisphere of its normal are cast
against the whole mesh with Intel Embree (``embreex``; 2-core figures in docs/occl_notes.md). Each
vertex gets
- ``visibility`` V: the cosine-weighted unoccluded fraction, (1/pi) * integral of V(l) (n.l) dl,
  the ambient occlusion of the diffuse term;
- ``bent_normal``: the mean unoccluded direction; with V it is the visibility cone of Jimenez et
  al. 2016 ("Practical Real-Time Strategies for Accurate Indirect Occlusion"): a cone around the
  bent normal holding cosine-weighted visibility V has cos(aperture) = sqrt(1 - V);
- ``bounce``: one diffuse inter-reflection. A ray that hits the mesh sees the hit point's diffuse
  radiance, albedo * V_hit * E(bent_hit)/pi (the hit's own occluded irradiance, one bounce). Its
  mean over all rays is stored as (direction, weight): ``bounce_weight`` = mean of V_hit over
  all rays (0 for the unoccluded ones) and ``bounce_direction`` = the V_hit-weighted mean of
  bent_hit. The shader reads albedo * bounce_weight * E(bounce_direction)/pi: exact under a
  uniform environment, and close elsewhere since E/pi is smooth (its first two SH bands are
  linear in the direction). The hit's albedo is taken to be the shading point's (one material
  per scene, as the test scenes and most product shots; docs/occl_notes.md).

A per-vertex bake needs vertices where the occlusion changes: ``refine_part`` first splits the
part's triangles whose edges are longer than a fraction of the mesh's size (every attribute
interpolated linearly, which the rasteriser does anyway, so the picture without occlusion is
unchanged). Baked once per mesh content and settings and cached (``VisibilityCache``) like the
IBL bake. Convex meshes cannot occlude themselves (``self_occludes``): they pay nothing.

The shader side is shaders/common/occlusion.glsl; its numpy twins are ``cone_aperture_cos``,
``specular_occlusion`` and ``occluded_diffuse`` here (tests/test_occlusion.py holds them equal).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import time
from dataclasses import dataclass

import numpy as np

from alight.errors import AlightError

# Bake settings (all in the cache key).
DEFAULT_RAYS = 192            # rays per vertex: V's noise is about sqrt(V(1-V)/N) <= 0.036
DEFAULT_EDGE_FRACTION = 1.0 / 40.0   # refine edges longer than this times the bounding-box diagonal
DEFAULT_MAX_VERTICES = 400_000       # refinement stops growing a mesh past this
BAKE_VERSION = 1
OCCLUSION_MODES = ("auto", "on", "off")


@dataclass
class PartVisibility:
    """One part's refined geometry (world space, as MeshPart's fields) and its per-vertex
    visibility: ``visibility`` (N,) in [0, 1]; ``bent_normal`` (N, 3) unit; ``bounce_direction``
    (N, 3) unit; ``bounce_weight`` (N,) in [0, 1]."""

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


def combined_visibility(visibility, occlusion_texture):
    """The diffuse visibility with a glTF occlusion texture: the smaller of the two. Both estimate
    the same quantity for the same geometry (the texture is this mesh's own baked AO), so
    multiplying would darken a crease twice; the minimum keeps the texture's finer detail where it
    is darker and the ray-traced value where the texture misses an occluder (another part)."""
    return np.minimum(np.asarray(visibility, np.float64), np.asarray(occlusion_texture, np.float64))


def occluded_diffuse(albedo, visibility, irradiance_bent, bounce_weight, irradiance_bounce):
    """The diffuse IBL's incident term (E/pi per unit albedo, then times albedo): what arrives
    unblocked, V * E(bent)/pi, plus the one bounce, albedo * w * E(bounce_direction)/pi."""
    a = np.asarray(albedo, np.float64)
    return a * (np.asarray(visibility)[..., None] * irradiance_bent
                + a * np.asarray(bounce_weight)[..., None] * irradiance_bounce)


# ---- which meshes need it -----------------------------------------------------------------------

def self_occludes(parts, faces: int = 2000, vertices: int = 20000, tolerance: float = 1e-4) -> bool:
    """Whether a face of the mesh can see another part of it: some vertex lies in front of some
    face's plane (by more than ``tolerance`` times the mesh's size). False for a convex mesh and a
    flat one, whose faces see only the sky. Up to ``faces`` faces against up to ``vertices``
    vertices (seeded samples beyond those counts, for big meshes)."""
    positions = np.concatenate([np.asarray(p.positions, np.float64) for p in parts])
    if len(positions) < 4:
        return False
    size = float(np.linalg.norm(positions.max(axis=0) - positions.min(axis=0))) or 1.0
    rng = np.random.default_rng(0)
    centroids, normals = [], []
    for p in parts:
        tri = np.asarray(p.positions, np.float64)[np.asarray(p.indices, np.int64)]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        length = np.linalg.norm(n, axis=1)
        keep = length > 1e-12 * size * size
        centroids.append(tri[keep].mean(axis=1))
        normals.append(n[keep] / length[keep, None])
    centroids = np.concatenate(centroids)
    normals = np.concatenate(normals)
    if len(centroids) > faces:
        pick = rng.choice(len(centroids), faces, replace=False)
        centroids, normals = centroids[pick], normals[pick]
    if len(positions) > vertices:
        positions = positions[rng.choice(len(positions), vertices, replace=False)]
    for start in range(0, len(centroids), 256):
        c, n = centroids[start:start + 256], normals[start:start + 256]
        offset = np.einsum("ij,ij->i", c, n)
        ahead = positions @ n.T - offset                  # (V, C): > 0 in front of the face
        if (ahead > tolerance * size).any():
            return True
    return False


def wants_occlusion(mesh, mode: str) -> bool:
    """``mode`` 'on': bake unless the mesh is the built-in sphere; 'off': never; 'auto': where
    the mesh occludes itself (``self_occludes``)."""
    if mode not in OCCLUSION_MODES:
        raise AlightError(f"--occlusion: '{mode}' is not one of {', '.join(OCCLUSION_MODES)}")
    if mode == "off" or mesh is None or mesh.lod_sphere is not None:
        return False
    return mode == "on" or self_occludes(mesh.parts)


# ---- refinement ----------------------------------------------------------------------------------

def _attributes(part) -> list[np.ndarray]:
    cols = [part.positions, part.normals, part.uvs, part.tangents]
    if part.uvs1 is not None:
        cols.append(part.uvs1)
    if part.colors is not None:
        cols.append(part.colors)
    return [np.asarray(c, np.float64) for c in cols]


def refine_part(part, max_edge: float, max_vertices: int = DEFAULT_MAX_VERTICES):
    """The part's triangles split at their edges' midpoints (1 to 4, shared midpoints, so no
    cracks) while any edge is longer than ``max_edge``; a triangle whose edges are all short is
    kept, and an edge split on one side only is split on the other too (the neighbour becomes 2
    or 3 triangles: red-green refinement), so no T-junction remains. Every attribute is
    interpolated linearly, as the rasteriser does. Returns (attributes list, indices (M, 3))."""
    attrs = _attributes(part)
    widths = [a.shape[1] for a in attrs]
    data = np.hstack(attrs)
    faces = np.asarray(part.indices, np.int64).reshape(-1, 3)
    while len(data) < max_vertices and len(faces):
        p = data[:, :3]
        edges = np.stack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]], axis=1)   # (F, 3, 2)
        lengths = np.linalg.norm(p[edges[..., 0]] - p[edges[..., 1]], axis=2)
        split_face = (lengths > max_edge).any(axis=1)
        if not split_face.any():
            break
        # Every edge of a split face is split; the neighbours' matching edges with it.
        keys = np.sort(edges, axis=2).reshape(-1, 2)
        unique, inverse = np.unique(keys, axis=0, return_inverse=True)
        inverse = inverse.reshape(-1, 3)
        marked = np.zeros(len(unique), bool)
        marked[inverse[split_face].ravel()] = True
        mid_index = np.full(len(unique), -1, np.int64)
        mid_index[marked] = len(data) + np.arange(marked.sum())
        mids = 0.5 * (data[unique[marked, 0]] + data[unique[marked, 1]])
        data = np.vstack([data, mids])
        m = mid_index[inverse]                        # (F, 3): midpoint of edge (0-1, 1-2, 2-0) or -1
        a, b, c = faces[:, 0], faces[:, 1], faces[:, 2]
        out = []
        count = (m >= 0).sum(axis=1)
        full = count == 3
        out += [np.column_stack([a, m[:, 0], m[:, 2]])[full], np.column_stack([m[:, 0], b, m[:, 1]])[full],
                np.column_stack([m[:, 2], m[:, 1], c])[full], np.column_stack([m[:, 0], m[:, 1], m[:, 2]])[full]]
        out.append(faces[count == 0])
        for k in range(3):                            # one split edge k: (v_k, v_k+1) halves
            one = (count == 1) & (m[:, k] >= 0)
            v0, v1, v2 = faces[one, k], faces[one, (k + 1) % 3], faces[one, (k + 2) % 3]
            mk = m[one, k]
            out += [np.column_stack([v0, mk, v2]), np.column_stack([mk, v1, v2])]
        for k in range(3):                            # two split edges: all but edge k
            two = (count == 2) & (m[:, k] < 0)
            v0, v1, v2 = faces[two, k], faces[two, (k + 1) % 3], faces[two, (k + 2) % 3]
            m12, m20 = m[two, (k + 1) % 3], m[two, (k + 2) % 3]
            out += [np.column_stack([m12, v2, m20]), np.column_stack([v0, v1, m12]),
                    np.column_stack([v0, m12, m20])]
        faces = np.vstack([o for o in out if len(o)])
    split = np.cumsum(widths)[:-1]
    cols = np.split(data, split, axis=1)
    cols[1] = cols[1] / np.maximum(np.linalg.norm(cols[1], axis=1, keepdims=True), 1e-30)
    return cols, faces


# ---- the bake -------------------------------------------------------------------------------

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


def _cast(scene, origins, dirs, face_normals, eps, retries: int = 2):
    """First hits (triangle index, -1 for none; Embree's barycentric u, v). A ray that starts on
    or just behind a triangle (its own, or a wall its vertex stands against) and leaves through
    it in the direction of its normal hits it at t ~ 0: such hits are skipped by casting again
    from just past them."""
    out = scene.run(origins, dirs, output=1)
    prim = np.where(np.asarray(out["geomID"]) < 0, -1, np.asarray(out["primID"])).astype(np.int32)
    tfar = np.asarray(out["tfar"], np.float32)
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
    return prim, u, v


def bake_visibility(mesh, rays: int = DEFAULT_RAYS, edge_fraction: float = DEFAULT_EDGE_FRACTION,
                    max_vertices: int = DEFAULT_MAX_VERTICES, seed: int = 0) -> MeshVisibility:
    """Refine every part (``refine_part``) and cast ``rays`` cosine-weighted rays from each
    vertex against all parts (Embree, float32). Seeded: the same mesh gives the same values."""
    rtcore_scene, TriangleMesh = _import_embree()
    start = time.perf_counter()
    lo, hi = mesh.bounds()
    size = float(np.linalg.norm(hi - lo)) or 1.0
    per_part_limit = max(max_vertices // max(len(mesh.parts), 1), 1000)
    refined = [refine_part(p, edge_fraction * size, per_part_limit) for p in mesh.parts]
    positions = [cols[0] for cols, _ in refined]
    normals = [cols[1] for cols, _ in refined]
    offsets = np.cumsum([0] + [len(p) for p in positions])
    all_p = np.concatenate(positions)
    all_n = np.concatenate(normals)
    all_f = np.concatenate([f + o for (_, f), o in zip(refined, offsets[:-1])])
    scene = rtcore_scene.EmbreeScene()
    triangles = all_p[all_f].astype(np.float32)
    _mesh = TriangleMesh(scene=scene, vertices=triangles)   # noqa: F841 (kept alive with the scene)
    face_n = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    face_n /= np.maximum(np.linalg.norm(face_n, axis=1, keepdims=True), 1e-30)
    # Rays start off the surface (eps along n) and nudged toward the vertex's own faces: a vertex
    # on a crease (the floor's corner, where two walls stand) would otherwise start inside the
    # walls' planes, where a hit at t = 0 is a coin toss.
    centroid = np.zeros_like(all_p)
    face_centroid = np.repeat(all_p[all_f].mean(axis=1), 3, axis=0)
    for k in range(3):
        centroid[:, k] = np.bincount(all_f.ravel(), face_centroid[:, k], minlength=len(all_p))
    uses = np.bincount(all_f.ravel(), minlength=len(all_p))[:, None]
    toward = centroid / np.maximum(uses, 1) - all_p
    reach = np.linalg.norm(toward, axis=1, keepdims=True)
    nudge = toward / np.maximum(reach, 1e-30) * np.minimum(10.0 * eps_of(size), 0.5 * reach)
    origins = (all_p + nudge + eps_of(size) * all_n).astype(np.float32)
    local = cosine_directions(rays).astype(np.float32)
    rng = np.random.default_rng(seed)
    count = len(all_p)
    hit_face = np.empty((count, rays), np.int32)
    hit_uv = np.empty((count, rays, 2), np.float32)
    open_sum = np.zeros((count, 3), np.float64)
    eps = eps_of(size)
    chunk = max(1, 262_144 // rays)
    for s0 in range(0, count, chunk):
        n = all_n[s0:s0 + chunk]
        t, b = _frame(n)
        angle = rng.uniform(0.0, 2.0 * math.pi, len(n))
        c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
        t, b = c * t + s * b, c * b - s * t
        frame = np.stack([t, b, n], axis=1).astype(np.float32)        # (C, 3, 3): rows t, b, n
        d = np.ascontiguousarray((local @ frame).reshape(-1, 3))         # (C * R, 3)
        o = np.ascontiguousarray(np.repeat(origins[s0:s0 + chunk], rays, axis=0))
        prim, u, v = _cast(scene, o, d, face_n, eps)
        hit_face[s0:s0 + chunk] = prim.reshape(len(n), rays)
        hit_uv[s0:s0 + chunk] = np.stack([u, v], axis=-1).reshape(len(n), rays, 2)
        open_sum[s0:s0 + chunk] = (d * (prim < 0)[:, None]).reshape(len(n), rays, 3).sum(axis=1)
    open_ = hit_face < 0
    visibility = open_.mean(axis=1)
    length = np.linalg.norm(open_sum, axis=1, keepdims=True)
    bent = np.where(length > 1e-8, open_sum / np.maximum(length, 1e-30), all_n)
    # The bounce: each hit's V and bent normal, interpolated over its triangle.
    vertex_values = np.column_stack([bent, visibility]).astype(np.float32)    # (N, 4)
    bounce_weight = np.zeros(count)
    bounce_dir = np.zeros((count, 3))
    for s0 in range(0, count, chunk):
        hf = hit_face[s0:s0 + chunk]
        rows, cols = np.nonzero(hf >= 0)
        corners = all_f[hf[rows, cols]]                                    # (H, 3)
        uv = hit_uv[s0:s0 + chunk][rows, cols]
        w = np.column_stack([1.0 - uv[:, 0] - uv[:, 1], uv[:, 0], uv[:, 1]]).astype(np.float32)
        at_hit = np.einsum("hk,hkc->hc", w, vertex_values[corners])          # (H, 4): bent, V
        rows += s0
        bounce_weight += np.bincount(rows, at_hit[:, 3], minlength=count)
        for k in range(3):
            bounce_dir[:, k] += np.bincount(rows, at_hit[:, k] * at_hit[:, 3], minlength=count)
    bounce_weight /= rays
    length = np.linalg.norm(bounce_dir, axis=1, keepdims=True)
    bounce_dir = np.where(length > 1e-8, bounce_dir / np.maximum(length, 1e-30), -all_n)
    parts = []
    for (cols, faces), part, a, b in zip(refined, mesh.parts, offsets[:-1], offsets[1:]):
        extra = cols[4:]
        uvs1 = extra.pop(0) if part.uvs1 is not None else None
        colors = extra.pop(0) if part.colors is not None else None
        parts.append(PartVisibility(
            positions=cols[0].astype(np.float32), normals=cols[1].astype(np.float32), uvs=cols[2].astype(np.float32),
            tangents=cols[3].astype(np.float32), indices=faces.astype(np.uint32),
            uvs1=None if uvs1 is None else uvs1.astype(np.float32),
            colors=None if colors is None else colors.astype(np.float32),
            visibility=visibility[a:b].astype(np.float32), bent_normal=bent[a:b].astype(np.float32),
            bounce_direction=bounce_dir[a:b].astype(np.float32), bounce_weight=bounce_weight[a:b].astype(np.float32)))
    return MeshVisibility(parts, seconds=time.perf_counter() - start, rays=count * rays)


# ---- the cache ----------------------------------------------------------------------------------

_FIELDS = ("positions", "normals", "uvs", "tangents", "indices", "uvs1", "colors",
           "visibility", "bent_normal", "bounce_direction", "bounce_weight")


def mesh_digest(mesh) -> str:
    """sha256 of the mesh's geometry (every part's vertex attributes and indices, in order)."""
    h = hashlib.sha256()
    for part in mesh.parts:
        for a in _attributes(part) + [np.asarray(part.indices, np.int64)]:
            h.update(str(a.shape).encode())
            h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def visibility_key(mesh, rays: int, edge_fraction: float, max_vertices: int) -> tuple[str, dict]:
    """The cache key of a visibility bake and the description it hashes."""
    description = {"what": "visibility", "version": BAKE_VERSION, "mesh": mesh_digest(mesh), "rays": rays,
                   "edge_fraction": edge_fraction, "max_vertices": max_vertices}
    text = json.dumps(description, sort_keys=True)
    return "alight-visibility-" + hashlib.sha256(text.encode()).hexdigest(), description


def cached_visibility(mesh, cache=None, rays: int = DEFAULT_RAYS, edge_fraction: float = DEFAULT_EDGE_FRACTION,
                      max_vertices: int = DEFAULT_MAX_VERTICES) -> MeshVisibility:
    """``bake_visibility``, through ``cache`` (an ``alight.ibl.bake_cache.BakeCache``; None: no
    cache) keyed by the mesh's content and the bake settings (``visibility_key``)."""
    from alight.ibl.bake_cache import BadEntry, decode_entry, encode_entry

    key, description = visibility_key(mesh, rays, edge_fraction, max_vertices)
    if cache is not None:
        arrays = cache.load(key, description, "visibility bake")
        if arrays is not None:
            try:
                parts = []
                for i in range(len(mesh.parts)):
                    values = {f: arrays.get(f"{i}.{f}") for f in _FIELDS}
                    if any(values[f] is None for f in _FIELDS if f not in ("uvs1", "colors")):
                        raise BadEntry("a part's arrays are missing")
                    parts.append(PartVisibility(**values))
                return MeshVisibility(parts, from_cache=True)
            except BadEntry as exc:
                cache.reject(key, "visibility bake", str(exc))
    result = bake_visibility(mesh, rays, edge_fraction, max_vertices)
    if cache is not None:
        arrays = {f"{i}.{f}": getattr(p, f) for i, p in enumerate(result.parts) for f in _FIELDS
                  if getattr(p, f) is not None}
        cache.save(key, encode_entry(description, arrays))
    return result


def refined_mesh_part(part, vis: PartVisibility):
    """A MeshPart with the refined geometry of ``vis`` and ``part``'s material, name and element."""
    return dataclasses.replace(part, positions=vis.positions, normals=vis.normals, uvs=vis.uvs,
                               tangents=vis.tangents, indices=vis.indices, uvs1=vis.uvs1, colors=vis.colors)
