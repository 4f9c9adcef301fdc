"""An OBJ's faces made explicit before trimesh reads them.

trimesh splits a polygon into a fan from its first vertex, which cuts across the notch of a
concave face (an L), and leaves the normals of a file without ``vn`` to us, where shared
vertices would be smoothed whatever the file's smoothing groups say. This pass rewrites the
``f`` statements so that trimesh reads exactly what the file means:

- every polygon of more than three vertices is triangulated by ear clipping (mapbox-earcut,
  the C++ earcut.hpp that Mapbox's renderers use) in the plane of its Newell normal; a polygon
  earcut cannot cut whole (self-intersecting, degenerate) keeps trimesh's fan;
- a face corner without a normal gets one: the face's own normal under ``s off`` / ``s 0``
  (the OBJ default, so a file with no ``s`` line is flat, as Blender and 3ds Max read it), or,
  inside smoothing group N, the area-weighted mean of the normals of the group's faces that
  share the vertex. The normals are appended as ``vn`` lines and every index is written
  absolute (negative, relative indices resolved first).

It also lists ``usemtl`` names no MTL defines (they are drawn with the current material).
A file whose faces are all triangles with normals is left as it is (``rewrite`` None), so the
common exported mesh costs one scan.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class ObjFaces:
    rewrite: bytes | None                 # the OBJ text to hand trimesh, None: the file as it is
    usemtl: dict[str, int] = field(default_factory=dict)   # material name -> first line number
    polygons: int = 0                     # faces of more than 3 vertices ear-clipped
    fan_fallbacks: int = 0                # of those, left as a fan (earcut could not cut them)


def _index(token: bytes, count: int) -> int:
    """A 1-based OBJ index (negative: relative to the ``count`` defined so far) as 0-based."""
    i = int(token)
    return count + i if i < 0 else i - 1


def newell_normal(points: np.ndarray) -> np.ndarray:
    """The (unnormalised) Newell normal of a polygon (N, 3): twice its vector area, so its length
    weights the face by area and it is right for concave and slightly non-planar polygons."""
    nxt = np.roll(points, -1, axis=0)
    return np.array([np.sum((points[:, 1] - nxt[:, 1]) * (points[:, 2] + nxt[:, 2])),
                     np.sum((points[:, 2] - nxt[:, 2]) * (points[:, 0] + nxt[:, 0])),
                     np.sum((points[:, 0] - nxt[:, 0]) * (points[:, 1] + nxt[:, 1]))])


def ear_clip(points: np.ndarray) -> np.ndarray | None:
    """Triangles (N-2, 3) of local corner indices covering the simple polygon ``points`` (N, 3),
    counter-clockwise about its Newell normal as the polygon is; None where earcut cannot cut it
    into N-2 triangles (degenerate or self-intersecting)."""
    import mapbox_earcut

    n = newell_normal(points)
    length = float(np.linalg.norm(n))
    if not length > 0.0:
        return None
    n = n / length
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(n, helper)
    u /= np.linalg.norm(u)
    v = np.cross(n, u)           # (u, v, n) right-handed: the polygon winds counter-clockwise in (u, v)
    flat = np.stack([points @ u, points @ v], axis=1).astype(np.float64)
    tris = np.asarray(mapbox_earcut.triangulate_float64(flat, np.array([len(points)], np.uint32)), np.int64)
    if tris.size != 3 * (len(points) - 2):
        return None
    tris = tris.reshape(-1, 3)
    a, b, c = flat[tris[:, 0]], flat[tris[:, 1]], flat[tris[:, 2]]
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    return np.where((cross < 0)[:, None], tris[:, ::-1], tris)


def _needs_pass(data: bytes) -> bool:
    """Whether any face lacks a normal or has more than three corners (a quick scan)."""
    for line in data.split(b"\n"):
        if line[:2] in (b"f ", b"f\t"):
            tokens = line.split(b"#", 1)[0].split()
            if len(tokens) > 4 or any(t.count(b"/") < 2 or t.endswith(b"/") for t in tokens[1:]):
                return True
    return False


def read_faces(data: bytes) -> ObjFaces:
    """The pass over an OBJ's text (see the module docstring). Malformed statements are left for
    trimesh to judge, unchanged."""
    usemtl: dict[str, int] = {}
    for number, line in enumerate(data.split(b"\n"), 1):
        if line.startswith(b"usemtl"):
            name = line[6:].split(b"#", 1)[0].strip().decode("utf-8", "replace")
            usemtl.setdefault(name, number)
    if not _needs_pass(data):
        return ObjFaces(None, usemtl)

    lines = data.split(b"\n")
    positions: list[tuple[float, float, float]] = []
    n_vt = n_vn = 0
    group = 0
    # per face statement: (line number, corners [(v, vt|None, vn|None)], smoothing group)
    faces: list[tuple[int, list, int]] = []
    for number, line in enumerate(lines):
        head = line.split(None, 1)[0] if line.strip() else b""
        if head == b"v":
            tokens = line.split()
            try:
                positions.append((float(tokens[1]), float(tokens[2]), float(tokens[3])))
            except (IndexError, ValueError):
                positions.append((0.0, 0.0, 0.0))
        elif head == b"vt":
            n_vt += 1
        elif head == b"vn":
            n_vn += 1
        elif head == b"s":
            value = line.split(b"#", 1)[0].split()[1:2]
            try:
                group = 0 if not value or value[0].lower() == b"off" else int(value[0])
            except ValueError:
                group = 1
        elif head == b"f":
            corners = []
            try:
                for token in line.split(b"#", 1)[0].split()[1:]:
                    parts = token.split(b"/")
                    v = _index(parts[0], len(positions))
                    vt = _index(parts[1], n_vt) if len(parts) > 1 and parts[1] else None
                    vn = _index(parts[2], n_vn) if len(parts) > 2 and parts[2] else None
                    corners.append((v, vt, vn))
            except ValueError:
                continue       # trimesh's to judge, as the file has it
            if len(corners) >= 3 and all(0 <= c[0] < len(positions) for c in corners):
                faces.append((number, corners, group))

    points = np.asarray(positions, np.float64).reshape(-1, 3)
    extra: list[np.ndarray] = []          # the vn lines to append, in order
    out = list(lines)
    polygons = fans = 0
    smooth_index: dict[tuple[int, int], int] = {}
    # Faces of one corner count at a time, so the normals and the quads' diagonals are numpy
    # operations over all of them (250k quads: a few seconds, not a minute of per-face calls).
    by_size: dict[int, list[int]] = {}
    for f, (_, corners, _) in enumerate(faces):
        by_size.setdefault(len(corners), []).append(f)
    smooth_sum: dict[tuple[int, int], np.ndarray] = {}
    unit_of = np.zeros((len(faces), 3))
    zero_of = np.zeros(len(faces), bool)
    for k, members in by_size.items():
        v = np.array([[c[0] for c in faces[f][1]] for f in members], np.int64)
        p = points[v]
        nxt = np.roll(p, -1, axis=1)
        nn = np.stack([np.sum((p[..., 1] - nxt[..., 1]) * (p[..., 2] + nxt[..., 2]), axis=1),
                       np.sum((p[..., 2] - nxt[..., 2]) * (p[..., 0] + nxt[..., 0]), axis=1),
                       np.sum((p[..., 0] - nxt[..., 0]) * (p[..., 1] + nxt[..., 1]), axis=1)], axis=1)
        length = np.linalg.norm(nn, axis=1)
        idx = np.asarray(members)
        zero_of[idx] = length == 0.0          # (NaN positions are kept: the loader refuses them)
        unit_of[idx] = np.where((length > 0)[:, None], nn / np.where(length > 0, length, 1.0)[:, None], (0, 1, 0))
        for row, f in enumerate(members):
            _, corners, grp = faces[f]
            if grp and any(c[2] is None for c in corners):
                for c in corners:
                    key = (grp, c[0])
                    smooth_sum[key] = smooth_sum.get(key, 0.0) + nn[row]
    quad_split = _quad_diagonals(faces, by_size.get(4, []), points)
    # Coplanar flat faces share one vn (fewer vertices): their unit normals, rounded, made unique.
    needs = np.array([any(c[2] is None for c in corners) for _, corners, _ in faces], bool)
    flat = needs & ~zero_of & np.array([grp == 0 for _, _, grp in faces], bool)
    flat_vn = np.full(len(faces), -1, np.int64)
    if flat.any():
        keys, inverse = np.unique(np.round(unit_of[flat], 9), axis=0, return_inverse=True)
        extra.extend(keys)
        flat_vn[flat] = n_vn + inverse.reshape(-1)

    def unit(vec) -> np.ndarray:
        length = float(np.linalg.norm(vec))
        return vec / length if length > 0 else np.array([0.0, 1.0, 0.0])

    for f, (number, corners, grp) in enumerate(faces):
        if needs[f]:
            if zero_of[f]:
                out[number] = b""      # no area, no normal: nothing to draw (dropped as before)
                continue
            if grp == 0:
                fv = int(flat_vn[f])
                corners = [(v, vt, fv if vn is None else vn) for v, vt, vn in corners]
            else:
                filled = []
                for v, vt, vn in corners:
                    if vn is None:
                        key2 = (grp, v)
                        if key2 not in smooth_index:
                            extra.append(unit(smooth_sum[key2]))
                            smooth_index[key2] = n_vn + len(extra) - 1
                        vn = smooth_index[key2]
                    filled.append((v, vt, vn))
                corners = filled
        if len(corners) == 4:
            polygons += 1
            tris = _QUAD_TRIANGLES[quad_split[f]]
        elif len(corners) > 4:
            polygons += 1
            tris = ear_clip(points[[c[0] for c in corners]])
            if tris is None:
                fans += 1
                tris = [(0, i, i + 1) for i in range(1, len(corners) - 1)]
        else:
            tris = ((0, 1, 2),)
        words = [_corner(c) for c in corners]
        out[number] = b"\n".join(b"f " + words[a] + b" " + words[b] + b" " + words[c] for a, b, c in tris)
    tail = [b"vn %.9g %.9g %.9g" % tuple(n) for n in extra]
    text = b"\n".join(out + tail) + b"\n"
    return ObjFaces(text, usemtl, polygons, fans)


# A quad (a, b, c, d) cut along a-c or along b-d.
_QUAD_TRIANGLES = {0: ((0, 1, 2), (0, 2, 3)), 1: ((1, 2, 3), (1, 3, 0))}


def _quad_diagonals(faces, members: list[int], points: np.ndarray) -> dict[int, int]:
    """For each quad, 0 to cut it along a-c, 1 along b-d: a-c unless it leaves the quad (a
    concave quad whose reflex corner is b or d), the ear clipping of a 4-gon, for all at once.
    The diagonal a-c lies inside iff b and d are on opposite sides of it in the quad's plane."""
    if not members:
        return {}
    v = np.array([[c[0] for c in faces[f][1]] for f in members], np.int64)
    a, b, c, d = (points[v[:, i]] for i in range(4))
    n = np.cross(c - a, d - b)                      # the quad's normal (twice its vector area)
    side_b = np.einsum("ij,ij->i", np.cross(c - a, b - a), n)
    side_d = np.einsum("ij,ij->i", np.cross(c - a, d - a), n)
    use_bd = (side_b * side_d >= 0)                  # same side (or on it): a-c is outside the quad
    return {f: int(x) for f, x in zip(members, use_bd)}


def _corner(c: tuple[int, int | None, int | None]) -> bytes:
    v, vt, vn = c
    return b"%d/%s/%s" % (v + 1, b"" if vt is None else b"%d" % (vt + 1), b"" if vn is None else b"%d" % (vn + 1))
