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

It also lists ``usemtl`` names no MTL defines (they are drawn with the default material).
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
    # Normals for corners without one: flat per face, or per (group, vertex) accumulated.
    new_normals: list[np.ndarray] = []
    smooth_sum: dict[tuple[int, int], np.ndarray] = {}
    face_normal: list[np.ndarray] = []
    for _, corners, grp in faces:
        nn = newell_normal(points[[c[0] for c in corners]])
        face_normal.append(nn)
        if grp and any(c[2] is None for c in corners):
            for c in corners:
                key = (grp, c[0])
                smooth_sum[key] = smooth_sum.get(key, 0.0) + nn
    smooth_index: dict[tuple[int, int], int] = {}

    def unit(vec) -> np.ndarray:
        length = float(np.linalg.norm(vec))
        return vec / length if length > 0 else np.array([0.0, 1.0, 0.0])

    out = list(lines)
    polygons = fans = 0
    flat_index: dict[tuple[float, float, float], int] = {}
    for (number, corners, grp), nn in zip(faces, face_normal):
        if any(c[2] is None for c in corners):
            if np.linalg.norm(nn) == 0.0:   # (NaN positions are kept: the loader refuses them)
                out[number] = b""      # no area, no normal: nothing to draw (dropped as before)
                continue
            if grp == 0:
                n = unit(nn)
                key = tuple(np.round(n, 9))      # coplanar faces share one vn: fewer vertices
                if key not in flat_index:
                    new_normals.append(n)
                    flat_index[key] = n_vn + len(new_normals) - 1
                flat = flat_index[key]
                corners = [(v, vt, flat if vn is None else vn) for v, vt, vn in corners]
            else:
                filled = []
                for v, vt, vn in corners:
                    if vn is None:
                        key = (grp, v)
                        if key not in smooth_index:
                            new_normals.append(unit(smooth_sum[key]))
                            smooth_index[key] = n_vn + len(new_normals) - 1
                        vn = smooth_index[key]
                    filled.append((v, vt, vn))
                corners = filled
        if len(corners) > 3:
            polygons += 1
            tris = ear_clip(points[[c[0] for c in corners]])
            if tris is None:
                fans += 1
                tris = np.array([(0, i, i + 1) for i in range(1, len(corners) - 1)])
        else:
            tris = np.array([(0, 1, 2)])
        out[number] = b"\n".join(b"f " + b" ".join(_corner(corners[i]) for i in tri) for tri in tris)
    tail = [b"vn %.9g %.9g %.9g" % tuple(n) for n in new_normals]
    text = b"\n".join(out + tail) + b"\n"
    return ObjFaces(text, usemtl, polygons, fans)


def _corner(c: tuple[int, int | None, int | None]) -> bytes:
    v, vt, vn = c
    return b"%d/%s/%s" % (v + 1, b"" if vt is None else b"%d" % (vt + 1), b"" if vn is None else b"%d" % (vn + 1))
