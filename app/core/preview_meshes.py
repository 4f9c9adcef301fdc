"""The built-in preview meshes beyond sphere, cube and plane (alight.core.mesh): a shader ball,
a rounded cube and a cloth-like drape, built from numpy arrays (no file, no trimesh), each with
uvs, tangents and a 3/4 view (``Mesh.view``).

- ``shader_ball``: a surface of revolution, a ball on a pedestal with a groove round its
  equator, so concave light (occlusion, inter-reflection) shows beside convex light; closed.
- ``rounded_cube``: a cube with rounded edges and corners (the signed-distance rounded box:
  each point of a subdivided cube pushed out from the inner box by the bevel radius); closed,
  one uv square per face as ``cube`` has.
- ``drape``: a square of cloth fallen over a hidden ball, with radial folds; open (both sides drawn).
"""

from __future__ import annotations

import numpy as np

from alight.core.mesh import FROM_ABOVE, THREE_QUARTER, Mesh, _part, compute_tangents, smooth_normals


# --- shader ball ---------------------------------------------------------------------------

def _line(p0, p1, n: int) -> tuple[np.ndarray, np.ndarray]:
    """A straight piece of a profile in the (r, y) half-plane: (n, 2) points and unit normals,
    the normal on the right of the direction of travel (outward for a profile going up)."""
    t = np.linspace(0.0, 1.0, n)[:, None]
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    d = (p1 - p0) / np.linalg.norm(p1 - p0)
    return p0 + t * (p1 - p0), np.tile([d[1], -d[0]], (n, 1))


def _arc(radius: float, a0: float, a1: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """A piece of a circle about the origin of the (r, y) half-plane from angle a0 to a1 (radians
    above the horizontal), going up: normals point out of the circle."""
    a = np.linspace(a0, a1, n)
    normal = np.stack([np.cos(a), np.sin(a)], -1)
    return normal * radius, normal


def _revolve(pieces, segments: int, name: str) -> Mesh:
    """Turn profile pieces about +Y: u round the axis as ``sphere`` runs it (seam at -Z), v the
    arc length up the profile. Each piece has its own vertices (a hard edge between pieces);
    triangles of zero area on the axis are left out."""
    lengths = [float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) for p, _ in pieces]
    total, start = sum(lengths), 0.0
    positions, normals, uvs, tangents, indices = [], [], [], [], []
    base = 0
    u = np.linspace(0.0, 1.0, segments + 1)
    phi = 2.0 * np.pi * u
    sin, cos = np.sin(phi), np.cos(phi)
    for (points, nrm), length in zip(pieces, lengths):
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
        v = (start + arc) / total
        start += length
        r, y = points[:, 0:1], points[:, 1:2]
        positions.append(np.stack([-r * sin, np.broadcast_to(y, r.shape[:1] + sin.shape), -r * cos], -1).reshape(-1, 3))
        normals.append(np.stack([-nrm[:, 0:1] * sin, np.broadcast_to(nrm[:, 1:2], r.shape[:1] + sin.shape),
                                 -nrm[:, 0:1] * cos], -1).reshape(-1, 3))
        uvs.append(np.stack(np.broadcast_arrays(u[None, :], v[:, None]), -1).reshape(-1, 2))
        tangents.append(np.tile(np.stack([-cos, np.zeros_like(cos), sin, np.ones_like(cos)], -1), (len(points), 1)))
        rows = len(points)
        i, j = np.meshgrid(np.arange(rows - 1), np.arange(segments), indexing="ij")
        a = base + i * (segments + 1) + j
        b, c = a + 1, a + segments + 1
        d = c + 1
        quads_r = np.repeat(np.arange(rows - 1), segments)
        # j + 1 (b) is to the right seen from outside, ring i + 1 (c) above: CCW is (a, b, d), (a, d, c).
        first = np.stack([a, b, d], -1).reshape(-1, 3)
        second = np.stack([a, d, c], -1).reshape(-1, 3)
        keep_first = r[quads_r, 0] > 1e-9                  # ring i on the axis: (a, b) coincide
        keep_second = r[quads_r + 1, 0] > 1e-9             # ring i + 1 on the axis: (c, d) coincide
        indices += [first[keep_first], second[keep_second]]
        base += rows * (segments + 1)
    return Mesh([_part(name, np.concatenate(positions), np.concatenate(normals), np.concatenate(uvs),
                       np.concatenate(tangents), np.concatenate(indices))], name, view=THREE_QUARTER)


def shader_ball(segments: int = 128) -> Mesh:
    """A ball of radius 0.85 at the origin with a groove round its equator (0.16 high, 0.15 deep),
    on a neck and a round pedestal reaching down to y = -1.3. Closed; the profile's pieces meet
    at hard edges (the groove's and the pedestal's rims)."""
    R, rg, hg = 0.85, 0.70, 0.08                        # ball radius; groove floor radius, half height
    neck_r, foot_r, foot_top, foot_bottom = 0.22, 0.72, -1.12, -1.30
    a_neck = -np.arccos(neck_r / R)
    a_groove = np.arcsin(hg / R)
    pieces = [
        _line((0.0, foot_bottom), (foot_r, foot_bottom), 12),      # the pedestal's base, facing down
        _line((foot_r, foot_bottom), (foot_r, foot_top), 4),        # its side
        _line((foot_r, foot_top), (neck_r, foot_top), 10),          # its top, facing up
        _line((neck_r, foot_top), (neck_r, R * np.sin(a_neck)), 6),  # the neck
        _arc(R, a_neck, -a_groove, 40),                             # the lower half of the ball
        _line((R * np.cos(a_groove), -hg), (rg, -hg), 4),           # the groove's floor, facing up
        _line((rg, -hg), (rg, hg), 4),                              # its back wall
        _line((rg, hg), (R * np.cos(a_groove), hg), 4),             # its ceiling, facing down
        _arc(R, a_groove, np.pi / 2, 48),                           # the upper half
    ]
    return _revolve(pieces, segments, "shader_ball")


# --- rounded cube --------------------------------------------------------------------------

def _band_grid(bevel: float, flat: int, band: int) -> np.ndarray:
    """Coordinates on [-1, 1], denser in the two bevel bands (|x| > 1 - bevel) than on the flat."""
    inner = 1.0 - bevel
    return np.concatenate([np.linspace(-1.0, -inner, band + 1)[:-1], np.linspace(-inner, inner, flat + 1),
                           np.linspace(inner, 1.0, band + 1)[1:]])


def rounded_cube(size: float = 2.0, bevel: float = 0.2, flat: int = 4, band: int = 8) -> Mesh:
    """A cube of edge ``size`` centred at the origin whose edges and corners are rounded with a
    radius of ``bevel`` times the half edge. Each face is a grid; a grid point q of the unit cube
    goes to c + bevel * (q - c) / |q - c| with c = clamp(q, -(1 - bevel), 1 - bevel), which is
    the rounded box's surface with its exact normal. Closed; uvs (0,0)..(1,1) per face as
    ``cube``'s; tangents from the uvs (compute_tangents)."""
    from alight.core.mesh import _CUBE_FACES

    g = _band_grid(bevel, flat, band)
    n = len(g)
    su, sv = np.meshgrid(g, g)          # row = v, column = u
    positions, normals, uvs, indices = [], [], [], []
    for k, (nf, tf) in enumerate(_CUBE_FACES):
        nf, tf = np.array(nf, float), np.array(tf, float)
        bf = np.cross(nf, tf)
        q = nf + su[..., None] * tf + sv[..., None] * bf
        c = np.clip(q, -(1.0 - bevel), 1.0 - bevel)
        out = q - c
        out /= np.linalg.norm(out, axis=-1, keepdims=True).clip(1e-12)
        positions.append(((c + bevel * out) * (size / 2.0)).reshape(-1, 3))
        normals.append(out.reshape(-1, 3))
        uvs.append(np.stack([(su + 1) / 2, (sv + 1) / 2], -1).reshape(-1, 2))
        i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="ij")
        a = k * n * n + i * n + j
        indices += [np.stack([a, a + 1, a + n + 1], -1).reshape(-1, 3), np.stack([a, a + n + 1, a + n], -1).reshape(-1, 3)]
    p, nr, uv, idx = (np.concatenate(x) for x in (positions, normals, uvs, indices))
    return Mesh([_part("rounded_cube", p, nr, uv, compute_tangents(p, nr, uv, idx), idx)], "rounded_cube",
                view=THREE_QUARTER)


# --- drape ---------------------------------------------------------------------------------

def drape_height(x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The cloth's height (world units) over the floor point (x, z): a soft dome where it lies on
    a hidden ball of radius about 0.6, falling off outward, with eight radial folds that grow
    toward the hem."""
    r = np.hypot(x, z)
    dome = 0.75 * np.exp(-(r / 0.75) ** 2)
    folds = 0.06 * np.sin(8.0 * np.arctan2(z, x)) * np.clip((r - 0.35) / 0.8, 0.0, 1.0)
    return dome + folds - 0.3


def drape(size: float = 2.4, cells: int = 96) -> Mesh:
    """A square of cloth ``size`` wide (XZ, facing +Y) laid over a hidden ball (drape_height):
    ``cells`` squares a side, u along +X and v along -Z as ``plane``'s, area-weighted normals,
    tangents from the uvs. Open: the renderer draws both sides."""
    t = np.linspace(-size / 2.0, size / 2.0, cells + 1)
    x, z = np.meshgrid(t, t[::-1])      # row 0 at +Z: rows run along -Z, as v does
    y = drape_height(x, z)
    positions = np.stack([x, y, z], -1).reshape(-1, 3)
    u = (x / size + 0.5).reshape(-1)
    v = (0.5 - z / size).reshape(-1)
    uvs = np.stack([u, v], -1)
    n = cells + 1
    i, j = np.meshgrid(np.arange(cells), np.arange(cells), indexing="ij")
    a = i * n + j                        # rows go toward -Z (v up), columns toward +X (u)
    idx = np.concatenate([np.stack([a, a + 1, a + n], -1).reshape(-1, 3),     # CCW seen from +Y
                          np.stack([a + 1, a + n + 1, a + n], -1).reshape(-1, 3)])
    normals = smooth_normals(positions, idx)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True).clip(1e-12)
    return Mesh([_part("drape", positions, normals, uvs, compute_tangents(positions, normals, uvs, idx), idx)],
                "drape", view=FROM_ABOVE)
