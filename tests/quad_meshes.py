"""Small meshes of flat quads for the occlusion tests, built in memory (no file): a box's sides
and parts made of quads."""

from __future__ import annotations

import numpy as np

from alight.core.mesh import FileMaterial, MeshPart


def box_quads(lo, hi) -> list[tuple]:
    """A box's four sides and its top (no bottom: it stands on the floor), each quad's 4 corners
    counter-clockwise seen from outside."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    return [((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),
            ((x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0)),
            ((x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1)),
            ((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),
            ((x0, y1, z1), (x1, y1, z1), (x1, y1, z0), (x0, y1, z0))]


def quad_part(quads, name: str, material: FileMaterial) -> MeshPart:
    """Quads (4 corners, counter-clockwise seen from the front) as a flat-shaded part: each quad's
    face normal at its 4 vertices, uvs 0, tangents +x."""
    verts, normals, faces = [], [], []
    for q in quads:
        q = np.asarray(q, np.float64)
        n = np.cross(q[1] - q[0], q[2] - q[0])
        base = sum(len(v) for v in verts)
        verts.append(q)
        normals.append(np.repeat((n / np.linalg.norm(n))[None], 4, axis=0))
        faces.append(np.array([[0, 1, 2], [0, 2, 3]]) + base)
    v = np.concatenate(verts).astype(np.float32)
    return MeshPart(name, v, np.concatenate(normals).astype(np.float32), np.zeros((len(v), 2), np.float32),
                    np.tile(np.float32([1, 0, 0, 1]), (len(v), 1)), np.concatenate(faces).astype(np.uint32),
                    material)
