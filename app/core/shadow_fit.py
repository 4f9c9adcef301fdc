"""Where a shadow map looks from, and whether a mesh needs one: pure functions on numpy arrays.

Matrices here are for column vectors (``clip = M @ [x, y, z, 1]``), OpenGL clip space (z in
[-w, w]); app/render/shadows.py uploads their transposes, as GLSL reads columns.

A shadow view covers the scene's bounding sphere, never the camera's frustum: the maps then do
not change when the camera moves (no swimming edges), and a still scene's maps are drawn once.
The directional fit's centre is still snapped to whole texels (Valient 2008, "Stable Rendering of
Cascaded Shadow Maps", ShaderX6), so a scene whose bounds grow or move shifts the map by whole
texels and its edges stay put where geometry has not moved.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# The six faces of a point light's cube, as (forward, up) pairs: +X, -X, +Y, -Y, +Z, -Z (the
# order shaders/common/shadows.glsl's cube_face picks them in).
CUBE_FACES = (
    ((1.0, 0.0, 0.0), (0.0, -1.0, 0.0)), ((-1.0, 0.0, 0.0), (0.0, -1.0, 0.0)),
    ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)), ((0.0, -1.0, 0.0), (0.0, 0.0, -1.0)),
    ((0.0, 0.0, 1.0), (0.0, -1.0, 0.0)), ((0.0, 0.0, -1.0), (0.0, -1.0, 0.0)),
)
KIND_ORTHO, KIND_PERSPECTIVE = 0, 1


@dataclass(frozen=True)
class ShadowView:
    """One depth map's projection. ``matrix``: (4, 4) world -> clip (column vectors).
    ``kind``: KIND_ORTHO (a directional light or a sun; depth is linear) or KIND_PERSPECTIVE
    (spot, a point light's cube face). ``near``/``far``: the depth range in world units along the
    view. ``texel``: world size of one texel (ortho), or of one texel at unit distance
    (perspective). ``source``: the source's size as the penumbra sees it: tan of the angular
    radius (ortho), radius in world units (perspective; 0 for a delta light). ``resolution``:
    texels along each side."""

    matrix: np.ndarray
    kind: int
    near: float
    far: float
    texel: float
    source: float
    resolution: int


def look_at(eye, forward, up) -> np.ndarray:
    """(4, 4) view matrix looking from ``eye`` along ``forward`` (right-handed, -Z forward)."""
    f = np.asarray(forward, np.float64)
    f = f / np.linalg.norm(f)
    u = np.asarray(up, np.float64)
    s = np.cross(f, u)
    if np.linalg.norm(s) < 1e-6:     # up parallel to forward: any other up
        s = np.cross(f, (1.0, 0.0, 0.0) if abs(f[0]) < 0.9 else (0.0, 0.0, 1.0))
    s = s / np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ np.asarray(eye, np.float64)
    return m


def orthographic(half_width: float, near: float, far: float) -> np.ndarray:
    m = np.eye(4)
    m[0, 0] = m[1, 1] = 1.0 / half_width
    m[2, 2] = -2.0 / (far - near)
    m[2, 3] = -(far + near) / (far - near)
    return m


def perspective(fov_deg: float, near: float, far: float) -> np.ndarray:
    t = 1.0 / math.tan(math.radians(fov_deg) / 2.0)
    m = np.zeros((4, 4))
    m[0, 0] = m[1, 1] = t
    m[2, 2] = -(far + near) / (far - near)
    m[2, 3] = -2.0 * far * near / (far - near)
    m[3, 2] = -1.0
    return m


def directional_view(direction, centre, radius: float, resolution: int, angular_radius: float = 0.0,
                     receivers=None) -> ShadowView:
    """An orthographic view along ``direction`` (where light travels) holding the sphere
    (``centre``, ``radius``) of the casters, its centre snapped to whole texels in the light's
    plane. ``angular_radius``: the source's (radians; 0 for a delta light). ``receivers``:
    (centre, radius) of a sphere of surfaces that only take the shadow (the ground): the view's
    depth range reaches them, its width does not, since a directional light puts the casters'
    shadow inside their own footprint across the light; a receiver outside the map is lit."""
    d = np.asarray(direction, np.float64)
    d = d / np.linalg.norm(d)
    radius = max(float(radius), 1e-6) * 1.02     # a little room for the PCF kernel at the rim
    texel = 2.0 * radius / resolution
    # A fixed frame in the light's plane (the same up for every fit), then the centre rounded to texels.
    basis = look_at((0.0, 0.0, 0.0), d, (0.0, 1.0, 0.0))[:3, :3]
    local = basis @ np.asarray(centre, np.float64)
    local[:2] = np.round(local[:2] / texel) * texel
    snapped = basis.T @ local
    distance = 2.0 * radius
    eye = snapped - d * distance
    near, far = distance - radius, distance + radius
    if receivers is not None:
        r_centre, r_radius = receivers
        far = max(far, float(np.dot(np.asarray(r_centre, np.float64) - eye, d)) + float(r_radius) * 1.02)
    matrix = orthographic(radius, near, far) @ look_at(eye, d, (0.0, 1.0, 0.0))
    return ShadowView(matrix, KIND_ORTHO, near, far, texel, math.tan(angular_radius), resolution)


def _depth_range(position, centre, radius: float) -> tuple[float, float]:
    distance = float(np.linalg.norm(np.asarray(centre, np.float64) - np.asarray(position, np.float64)))
    far = distance + radius * 1.02
    near = max(distance - radius * 1.02, far * 1e-3)
    return near, far


def spot_view(position, direction, outer_cone_deg: float, centre, radius: float, resolution: int,
              source_radius: float = 0.0) -> ShadowView:
    """A perspective view from a spot light holding its outer cone (and a guard band of a few
    texels for the PCF kernel), at most 170 degrees wide."""
    near, far = _depth_range(position, centre, radius)
    half = min(math.radians(outer_cone_deg), math.radians(85.0))
    half = math.atan(math.tan(half) * (1.0 + 8.0 / resolution))
    matrix = perspective(math.degrees(2.0 * half), near, far) @ look_at(position, direction, (0.0, 1.0, 0.0))
    return ShadowView(matrix, KIND_PERSPECTIVE, near, far, 2.0 * math.tan(half) / resolution, source_radius, resolution)


def point_views(position, centre, radius: float, resolution: int, source_radius: float = 0.0) -> list[ShadowView]:
    """A point light's six cube faces (CUBE_FACES), each a little wider than 90 degrees so that
    the PCF kernel near a face's edge reads texels of the same face."""
    near, far = _depth_range(position, centre, radius)
    tan_half = 1.0 + 8.0 / resolution
    fov = math.degrees(2.0 * math.atan(tan_half))
    projection = perspective(fov, near, far)
    return [ShadowView(projection @ look_at(position, forward, up), KIND_PERSPECTIVE, near, far,
                       2.0 * tan_half / resolution, source_radius, resolution)
            for forward, up in CUBE_FACES]


def vogel_disk(n: int) -> np.ndarray:
    """(n, 2) taps on the unit disk, Vogel's spiral: tap k at radius sqrt((k + 0.5) / n), angle
    k times the golden angle (shaders/common/shadows.glsl's SHADOW_TAPS_n)."""
    k = np.arange(n, dtype=np.float64)
    r = np.sqrt((k + 0.5) / n)
    a = 2.39996323 * k
    return np.stack([r * np.cos(a), r * np.sin(a)], axis=1)


def cube_face(vector) -> int:
    """The index into CUBE_FACES of the face a direction (from the light) falls on: its major axis."""
    v = np.asarray(vector, np.float64)
    axis = int(np.argmax(np.abs(v)))
    return 2 * axis + (0 if v[axis] >= 0.0 else 1)


def can_shadow_itself(parts, closed=None, faces: int = 2000, vertices: int = 20000, edges=None) -> bool:
    """Whether any part of a mesh can cast a shadow on the mesh: False only where every face's
    plane has the whole mesh on one side of it (to 1e-5 of the mesh's size) and the mesh is
    closed (alight.core.mesh.is_closed), or where it is flat. Such a surface bounds a convex
    solid, and a point of a convex solid's surface that faces a light (n.l > 0) sees it
    unoccluded, so shadow maps would change nothing. An open shell fails (a bowl's inside is
    shaded from both sides and its rim shadows it).

    ``parts``: [(positions (N, 3), indices (M, 3))]. Linear in the mesh. First a seeded sample of
    ``faces`` faces against one of ``vertices`` vertices (all of them below those counts): a
    plane with vertices on both sides answers True whether the mesh is closed or not, so most
    meshes that can shadow themselves (a bumpy 1M-triangle sphere) stop here, before any weld
    or sort. Otherwise the parts' closedness and every edge, tested locally (the vertex across
    it behind the face's plane: ``_locally_convex``), decide: a closed surface convex at every
    edge is convex (several solids side by side are what the sample is for; testing every face
    against every vertex took minutes on a 1.3M-triangle sphere).

    ``closed``: the parts' closedness where the caller knows it (else computed here, only when
    the sample did not answer); ``edges``: per part, its alight.core.mesh.closed_edges (None where
    open), which then serve both the closedness and the local test (one weld and one sort)."""
    points = np.concatenate([np.asarray(p, np.float64) for p, _ in parts]) if parts else np.zeros((0, 3))
    if len(points) < 4:
        return False
    centre = points.mean(axis=0)
    centred = points - centre
    size = float(np.abs(centred).max())
    if size == 0.0:
        return False
    eps = 1e-5 * size
    values = np.linalg.eigvalsh(centred.T @ centred)
    if values[0] <= 1e-10 * values[-1]:
        return False                 # flat: one plane cannot shadow itself
    if _sampled_planes_split(parts, centred, centre, size, eps, faces, vertices):
        return True
    if edges is None:
        if closed is not None and not all(closed):
            return True
        from alight.core.mesh import closed_edges

        edges = []
        for positions, indices in parts:
            edges.append(closed_edges(positions, indices))
            if edges[-1] is None and closed is None:
                return True          # open: a rim can shadow the inside
    elif not all(e is not None for e in edges):
        return True
    return not all(_locally_convex(positions, indices, eps, e) for (positions, indices), e in zip(parts, edges))


def _sampled_planes_split(parts, centred, centre, size: float, eps: float, faces: int, vertices: int) -> bool:
    """Whether some face's plane has (sampled) vertices more than ``eps`` on both sides of it:
    up to ``faces`` faces against up to ``vertices`` vertices, seeded samples beyond."""
    rng = np.random.default_rng(0)
    if len(centred) > vertices:
        centred = centred[rng.choice(len(centred), vertices, replace=False)]
    total = sum(len(np.asarray(i).reshape(-1, 3)) for _, i in parts)
    share = min(1.0, faces / max(total, 1))
    for positions, indices in parts:
        rows = np.asarray(indices, np.int64).reshape(-1, 3)
        if share < 1.0:
            rows = rows[rng.random(len(rows)) < share]
        tri = np.asarray(positions, np.float64)[rows]
        normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        length = np.linalg.norm(normals, axis=1)
        keep = length > 1e-12 * size * size
        normals = normals[keep] / length[keep, None]
        origins = tri[keep, 0] - centre
        for start in range(0, len(normals), 256):
            n = normals[start:start + 256]
            distance = centred @ n.T - np.einsum("ij,ij->i", n, origins[start:start + 256])[None, :]
            if ((distance.max(axis=0) > eps) & (distance.min(axis=0) < -eps)).any():
                return True
    return False


def _locally_convex(positions, indices, eps: float, edges=None) -> bool:
    """Whether a closed, consistently wound part bends the same way at every edge: across each
    edge, the third vertex of one face lies on the same side of the other face's plane (within
    ``eps``) as everywhere else. Vertices at equal positions are welded (UV seams) and the 3M
    edges sorted by alight.core.mesh.closed_edges (``edges``, computed here when not given):
    linear but for the sort's log."""
    if edges is None:
        from alight.core.mesh import closed_edges

        edges = closed_edges(positions, indices)
        if edges is None:
            return False          # (the caller said closed; a part that is not is no convex solid)
    p = np.asarray(positions, np.float64).reshape(-1, 3)
    tri = edges.faces
    if len(tri) == 0:
        return True
    # Each face's plane n.x = c, in float32 and one coordinate at a time (contiguous 1-D
    # gathers and products: np.cross and einsum on (M, 3) rows took most of this test's time);
    # the gathers are memory-bound (3M edges at 1M faces) and the test's tolerance is 1e-5 of
    # the mesh's size. Centred: float32 keeps 1e-7 of the size, not of the offset.
    x, y, z = np.ascontiguousarray((p - p.mean(axis=0)).T.astype(np.float32))
    t0, t1, t2 = (np.ascontiguousarray(tri[:, k]) for k in range(3))
    ax, ay, az = x[t0], y[t0], z[t0]
    ux, uy, uz = x[t1] - ax, y[t1] - ay, z[t1] - az
    vx, vy, vz = x[t2] - ax, y[t2] - ay, z[t2] - az
    nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
    del ux, uy, uz, vx, vy, vz
    length = np.maximum(np.sqrt(nx * nx + ny * ny + nz * nz), 1e-30)
    nx /= length
    ny /= length
    nz /= length
    offsets = nx * ax + ny * ay + nz * az
    del ax, ay, az, length
    # One face of each edge against the vertex across it: an edge bends the same way seen from
    # either face, so one side of each pair suffices.
    f, v = edges.face, edges.across
    d = nx[f] * x[v] + ny[f] * y[v] + nz[f] * z[v] - offsets[f]
    return bool(d.max() <= eps or d.min() >= -eps)
