"""MikkTSpace tangents (Morten Mikkelsen, "Simulation of Wrinkled Surfaces Revisited", 2008, and
the reference implementation mikktspace.c that Blender and the glTF exporters use), in numpy.

glTF 2.0 (section 3.7.2.1) says tangents that a file leaves out SHOULD be generated with "default
MikkTSpace algorithms"; normal maps baked against MikkTSpace only look right with the same
tangents. No maintained Python binding installs here (pymikktspace 0.3.0, the only one on PyPI,
is from 2021 and fails to build with Cython 3), so this follows mikktspace.c step by step:

1. corners with identical position, normal and uv are one vertex (the reference welds them too);
   triangles whose corners weld together are degenerate and take a neighbour's result at the end;
2. per triangle, the first-order derivatives dP/du, dP/dv (its eq. 18, 19), the sign of the uv
   area (orientation) and whether the triangle is usable (non-zero uv area and derivatives);
3. neighbours across edges (same welded vertices, opposite directions);
4. around every vertex, triangles connected through neighbours with the same orientation form a
   group; unusable triangles join the first group that reaches them (the reference's one order
   dependence, kept);
5. a group's tangent is the angle-weighted mean of its triangles' dP/du projected into the
   normal's plane; the bitangent sign is +1 for orientation-preserving groups, else -1.

So a vertex shared by triangles of opposite uv orientation (a mirrored uv seam) gets two
tangents, one per side: ``generate_tangents`` returns them per corner, and ``split_vertices``
splits the vertex buffer where corners of one vertex disagree. The reference's sub-groups only
split a group where two triangles' tangents point exactly opposite (its default angular
threshold is 180 degrees); here such a group is averaged whole.
"""

from __future__ import annotations

import numpy as np

_FLT_MIN = np.float32(1.17549435e-38)


def _not_zero(x: np.ndarray) -> np.ndarray:
    return np.abs(x) > _FLT_MIN


def _normalize_rows(v: np.ndarray) -> np.ndarray:
    """Unit rows; rows of zero length stay zero (the reference's VNotZero guard)."""
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(length > _FLT_MIN, v / np.where(length > _FLT_MIN, length, 1.0), 0.0)


def _weld(positions, normals, uvs, faces) -> np.ndarray:
    """Welded vertex index per corner (M, 3): equal position, normal and uv (bitwise, -0 as +0).
    Corners of one input vertex are equal already, so the vertices are welded, not the corners."""
    key = np.concatenate([positions, normals, uvs], axis=1).astype(np.float32) + np.float32(0.0)
    _, inverse = np.unique(np.ascontiguousarray(key).view(np.dtype((np.void, key.dtype.itemsize * 8))),
                           return_inverse=True)
    return inverse.reshape(-1)[faces]


def _triangle_info(p: np.ndarray, t: np.ndarray):
    """Per triangle: unit dP/du, dP/dv times the orientation sign, orientation, usable (float32,
    as the reference computes them)."""
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    t21, t31 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    area = t21[:, 0] * t31[:, 1] - t21[:, 1] * t31[:, 0]
    v_os = t31[:, 1:2] * d1 - t21[:, 1:2] * d2        # eq. 18
    v_ot = -t31[:, 0:1] * d1 + t21[:, 0:1] * d2       # eq. 19
    orient = area > 0
    sign = np.where(orient, np.float32(1.0), np.float32(-1.0))[:, None]
    len_os, len_ot = np.linalg.norm(v_os, axis=1), np.linalg.norm(v_ot, axis=1)
    nz_area = _not_zero(area)
    v_os = np.where((nz_area & _not_zero(len_os))[:, None], v_os * sign / np.where(len_os > 0, len_os, 1)[:, None], 0)
    v_ot = np.where((nz_area & _not_zero(len_ot))[:, None], v_ot * sign / np.where(len_ot > 0, len_ot, 1)[:, None], 0)
    abs_area = np.where(nz_area, np.abs(area), 1.0)
    usable = nz_area & _not_zero(len_os / abs_area) & _not_zero(len_ot / abs_area)
    return v_os.astype(np.float32), v_ot.astype(np.float32), orient, usable


def _neighbours(w: np.ndarray) -> np.ndarray:
    """(T, 3) the triangle across edge i (corner i to i + 1), or -1: each directed edge pairs with
    the first unpaired opposite edge in (min vertex, max vertex, triangle) order, as the
    reference's BuildNeighborsFast does."""
    t = len(w)
    a, b = w, np.roll(w, -1, axis=1)
    lo, hi = np.minimum(a, b).ravel(), np.maximum(a, b).ravel()
    face = np.repeat(np.arange(t), 3)
    order = np.lexsort((face, hi, lo))
    lo_s, hi_s = lo[order], hi[order]
    out = np.full(3 * t, -1, np.int64)
    starts = np.flatnonzero(np.r_[True, (lo_s[1:] != lo_s[:-1]) | (hi_s[1:] != hi_s[:-1])])
    sizes = np.diff(np.r_[starts, len(order)])
    forward = a.ravel() < b.ravel()   # which way the edge runs
    # Groups of two: the common case (a manifold edge). Pair when the directions are opposite.
    two = starts[sizes == 2]
    e1, e2 = order[two], order[two + 1]
    ok = forward[e1] != forward[e2]
    out[e1[ok]], out[e2[ok]] = face[e2[ok]], face[e1[ok]]
    # Non-manifold edges (three or more triangles): the reference's pairing loop, in order.
    for s, n in zip(starts[sizes > 2], sizes[sizes > 2]):
        entries = order[s:s + n]
        for i, ea in enumerate(entries):
            if out[ea] != -1:
                continue
            for eb in entries[i + 1:]:
                if out[eb] == -1 and forward[eb] != forward[ea]:
                    out[ea], out[eb] = face[eb], face[ea]
                    break
    return out.reshape(t, 3)


def _corner_of(w: np.ndarray, tri: np.ndarray, vertex: np.ndarray) -> np.ndarray:
    """The corner (0..2) of triangle ``tri`` whose welded vertex is ``vertex``."""
    return np.argmax(w[tri] == vertex[:, None], axis=1)


def _groups_connected(w, nb, orient, usable) -> np.ndarray:
    """Group label per corner (T*3) among usable triangles: the components of 'same vertex,
    neighbours, same orientation', which is what the reference's recursive assignment finds
    around every vertex that no unusable triangle touches."""
    t = len(w)
    corner = np.arange(3 * t)
    f, i = corner // 3, corner % 3
    pairs = []
    for edge in (i, (i + 2) % 3):          # the two edges that meet at corner i
        g = nb[f, edge]
        ok = g >= 0
        ok[ok] &= (orient[g[ok]] == orient[f[ok]]) & usable[g[ok]] & usable[f[ok]]
        src = corner[ok]
        dst = 3 * g[ok] + _corner_of(w, g[ok], w[f[ok], i[ok]])
        pairs.append((src, dst))
    a = np.concatenate([p[0] for p in pairs])
    b = np.concatenate([p[1] for p in pairs])
    labels = corner.copy()
    while True:   # min-label propagation with pointer jumping: a few rounds for vertex fans
        m = np.minimum(labels[a], labels[b])
        new = labels.copy()
        np.minimum.at(new, a, m)
        np.minimum.at(new, b, m)
        new = new[new]
        if np.array_equal(new, labels):
            break
        labels = new
    return labels


def _groups_sequential(w, nb, orient, usable, affected) -> tuple[dict, np.ndarray]:
    """The reference's Build4RuleGroups and AssignRecur, in its order, around the vertices in
    ``affected`` (those an unusable triangle touches; elsewhere the components are the answer):
    unusable triangles take the orientation of the first group that reaches them. Returns
    ({corner: group}, the orientation per triangle as assigned)."""
    orient = orient.copy()
    touching = np.flatnonzero(affected[w].any(axis=1)).tolist()
    wl = {f: w[f].tolist() for f in touching}
    nbl = {f: nb[f].tolist() for f in touching}
    usable_l = {f: bool(usable[f]) for f in touching}
    affected_set = set(np.flatnonzero(affected).tolist())
    assigned: dict[int, int] = {}
    group_orient: list[bool] = []

    def assign(start_tri: int, vertex: int, group: int) -> None:
        stack = [start_tri]
        while stack:
            tri = stack.pop()
            c = wl[tri].index(vertex)
            if 3 * tri + c in assigned:
                continue
            if not usable_l[tri] and not any(3 * tri + k in assigned for k in range(3)):
                orient[tri] = group_orient[group]
            if orient[tri] != group_orient[group]:
                continue
            assigned[3 * tri + c] = group
            right, left = nbl[tri][(c + 2) % 3], nbl[tri][c]
            # The reference recurses left first, then right: a stack pops in reverse order.
            if right >= 0:
                stack.append(right)
            if left >= 0:
                stack.append(left)

    for f in touching:
        if not usable_l[f]:
            continue
        for c in range(3):
            vertex = wl[f][c]
            if vertex not in affected_set or 3 * f + c in assigned:
                continue
            group = len(group_orient)
            group_orient.append(bool(orient[f]))
            assigned[3 * f + c] = group
            for neighbour in (nbl[f][c], nbl[f][(c + 2) % 3]):
                if neighbour >= 0:
                    assign(neighbour, vertex, group)
    return assigned, orient


def generate_tangents(positions: np.ndarray, normals: np.ndarray, uvs: np.ndarray,
                      faces: np.ndarray) -> np.ndarray:
    """MikkTSpace tangents per corner: (M, 3, 4) float32, xyz unit and orthogonal to the normal,
    w = +1 or -1 with bitangent = w * cross(n, t) (glTF 2.0's convention).

    ``positions`` (N, 3), ``normals`` (N, 3) unit, ``uvs`` (N, 2) in the uv convention whose +v
    the normal map's green channel points along (alight's OpenGL uvs), ``faces`` (M, 3) indices.
    """
    positions = np.asarray(positions, np.float32)
    normals = np.asarray(normals, np.float32)
    uvs = np.asarray(uvs, np.float32)
    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    m = len(faces)
    out = np.zeros((m, 3, 4), np.float32)
    if m == 0:
        return out
    w_all = _weld(positions, normals, uvs, faces)
    degenerate = (w_all[:, 0] == w_all[:, 1]) | (w_all[:, 1] == w_all[:, 2]) | (w_all[:, 0] == w_all[:, 2])
    good = np.flatnonzero(~degenerate)
    w = w_all[good]
    p, n, t = positions[faces[good]], normals[faces[good]], uvs[faces[good]]
    v_os, v_ot, orient, usable = _triangle_info(p, t)
    nb = _neighbours(w) if len(w) else np.zeros((0, 3), np.int64)
    labels = _groups_connected(w, nb, orient, usable)
    if not usable.all():
        affected = np.zeros(int(w.max()) + 1, bool)
        affected[w[~usable].ravel()] = True
        labels[affected[w].ravel()] = -1
        assigned, orient = _groups_sequential(w, nb, orient, usable, affected)
        if assigned:
            corners = np.fromiter(assigned.keys(), np.int64, len(assigned))
            labels[corners] = 3 * len(w) + np.fromiter(assigned.values(), np.int64, len(assigned))

    # EvalTspace: angle-weighted sum over the group's usable triangles of dP/du projected into
    # the plane of the vertex normal.
    tri = np.arange(len(w))
    corner_n = n.reshape(-1, 3).astype(np.float64)
    os_c = np.repeat(v_os, 3, axis=0).astype(np.float64)
    os_c = _normalize_rows(os_c - corner_n * np.sum(corner_n * os_c, axis=1, keepdims=True))
    pos = p.astype(np.float64)
    prev, nxt = pos[:, [2, 0, 1]], pos[:, [1, 2, 0]]
    e1 = (prev - pos).reshape(-1, 3)
    e2 = (nxt - pos).reshape(-1, 3)
    e1 = _normalize_rows(e1 - corner_n * np.sum(corner_n * e1, axis=1, keepdims=True))
    e2 = _normalize_rows(e2 - corner_n * np.sum(corner_n * e2, axis=1, keepdims=True))
    angle = np.arccos(np.clip(np.sum(e1 * e2, axis=1), -1.0, 1.0))
    contributes = (labels >= 0) & np.repeat(usable, 3)
    weights = np.where(contributes, angle, 0.0)
    lab = np.where(labels >= 0, labels, 0)
    size = int(lab.max()) + 1
    sums = np.stack([np.bincount(lab, weights=os_c[:, k] * weights, minlength=size) for k in range(3)], axis=1)
    tangent = _normalize_rows(sums[lab])
    # Corners no group reached, or whose group summed to zero: any vector in the normal's plane
    # (the reference leaves (1, 0, 0) there, which need not be).
    missing = (labels < 0) | (np.linalg.norm(tangent, axis=1) == 0)
    if missing.any():
        axis = np.where((np.abs(corner_n[missing, 0]) < 0.9)[:, None], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
        fallback = axis - corner_n[missing] * np.sum(corner_n[missing] * axis, axis=1, keepdims=True)
        tangent[missing] = _normalize_rows(fallback)
    sign = np.where(np.repeat(orient, 3), 1.0, -1.0)
    result = np.concatenate([tangent, sign[:, None]], axis=1).reshape(-1, 3, 4)
    out[good] = result.astype(np.float32)

    if degenerate.any():
        # DegenEpilogue: a degenerate triangle's corner takes the result of the first good
        # corner with the same welded vertex.
        flat_w = w.reshape(-1)
        first = {}
        for idx, vert in enumerate(flat_w.tolist()):
            first.setdefault(vert, idx)
        flat_out = out[good].reshape(-1, 4)
        for f in np.flatnonzero(degenerate):
            for c in range(3):
                k = first.get(int(w_all[f, c]))
                if k is not None:
                    out[f, c] = flat_out[k]
                else:
                    nrm = normals[faces[f, c]].astype(np.float64)
                    axis = np.array([1.0, 0.0, 0.0]) if abs(nrm[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
                    tv = axis - nrm * np.dot(nrm, axis)
                    out[f, c] = (*(tv / max(np.linalg.norm(tv), 1e-30)), 1.0)
    return out


def split_vertices(faces: np.ndarray, corner_tangents: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices split where corners of one vertex carry different tangents.

    Returns (source vertex per new vertex (K,), new faces (M, 3) int64, tangents (K, 4) float32):
    gather every other attribute with the first array.
    """
    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    tangents = np.ascontiguousarray(corner_tangents, np.float32).reshape(-1, 4)
    corner_vertex = faces.reshape(-1)
    count = int(corner_vertex.max()) + 1 if len(corner_vertex) else 0
    # Each vertex keeps the tangent of its first corner; only corners that disagree with it (the
    # other side of a mirrored seam) become new vertices, one per distinct (vertex, tangent).
    first = np.full(count, -1, np.int64)
    first[corner_vertex[::-1]] = np.arange(len(corner_vertex))[::-1]
    used = first >= 0
    vertex_tangent = np.zeros((count, 4), np.float32)
    vertex_tangent[used] = tangents[first[used]]
    differs = np.flatnonzero(np.any(tangents != vertex_tangent[corner_vertex], axis=1))
    source = np.arange(count)
    new_index = corner_vertex.copy()
    out_tangents = vertex_tangent
    if len(differs):
        key = np.empty(len(differs), np.dtype([("vertex", "<i8"), ("tangent", "V16")]))
        key["vertex"] = corner_vertex[differs]
        key["tangent"] = tangents[differs].view("V16").reshape(-1)
        pick, inverse = np.unique(key.view("V24"), return_index=True, return_inverse=True)[1:]
        source = np.concatenate([source, corner_vertex[differs[pick]]])
        out_tangents = np.concatenate([vertex_tangent, tangents[differs[pick]]])
        new_index[differs] = count + inverse.reshape(-1)
    return source, new_index.reshape(-1, 3), out_tangents
