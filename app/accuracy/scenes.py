"""Test scenes where light is blocked, built in code so tests and benchmarks share them.

    corner:  a floor, two walls (back -Z, left -X) and a box standing in the corner
    bowl:    a thick open bowl (a lathed profile), its opening toward +Y
    product: a capsule standing on a wide ground plane

Each is one material-less mesh (docs/conventions.md: +Y up, counter-clockwise front faces, the
default camera on +Z looks at it): the material comes from the command line. Written as OBJ
with normals by trimesh: flat faces carry their face normal (vertices are not shared across a
crease), curved ones trimesh's smooth vertex normals.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

SCENES = ("corner", "bowl", "product")
# The view each scene is measured from (alight render/reference --orbit/--elevation): the
# corner and the product from above and the side, the bowl from above to see into it.
SCENE_VIEWS = {"corner": (30.0, 25.0), "bowl": (0.0, 45.0), "product": (20.0, 20.0)}


def _quad(a, b, c, d) -> tuple[np.ndarray, np.ndarray]:
    """Corners a, b, c, d counter-clockwise seen from the front: 4 vertices, 2 triangles."""
    v = np.array([a, b, c, d], np.float64)
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def _box(lo, hi) -> list[tuple[np.ndarray, np.ndarray]]:
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    return [
        _quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),   # +Z
        _quad((x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0)),   # -Z
        _quad((x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1)),   # +X
        _quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),   # -X
        _quad((x0, y1, z1), (x1, y1, z1), (x1, y1, z0), (x0, y1, z0)),   # +Y
        _quad((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),   # -Y
    ]


def _flat(quads):
    import trimesh

    verts, faces, normals = [], [], []
    base = 0
    for v, f in quads:
        n = np.cross(v[1] - v[0], v[2] - v[0])
        n /= np.linalg.norm(n)
        verts.append(v)
        faces.append(f + base)
        normals.append(np.repeat(n[None], len(v), axis=0))
        base += len(v)
    return trimesh.Trimesh(np.concatenate(verts), np.concatenate(faces), vertex_normals=np.concatenate(normals),
                           process=False)


def corner():
    """Floor y = 0 over [-1, 1]^2, back wall z = -1 and left wall x = -1 (height 1.2), and a box
    0.6 wide, 0.7 high near the corner."""
    floor = _quad((-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1))
    back = _quad((-1, 0, -1), (1, 0, -1), (1, 1.2, -1), (-1, 1.2, -1))
    left = _quad((-1, 0, 1), (-1, 0, -1), (-1, 1.2, -1), (-1, 1.2, 1))
    return _flat([floor, back, left, *_box((-0.55, 0.0, -0.55), (0.05, 0.7, 0.05))[:5]])   # no bottom face


def bowl(sections: int = 96):
    """A bowl of outer radius 1 and wall 0.12 (a hemisphere shell with a flat rim), open to +Y."""
    import trimesh

    outer = [(np.sin(t), -np.cos(t)) for t in np.linspace(0.0, np.pi / 2, 24)]
    inner = [(0.88 * np.sin(t), -0.88 * np.cos(t)) for t in np.linspace(np.pi / 2, 0.0, 24)]
    profile = np.array([(1e-4, -1.0)] + outer[1:] + inner[:-1] + [(1e-4, -0.88)])
    mesh = trimesh.creation.revolve(profile, sections=sections)   # about +Z, (r, z) profile
    mesh.apply_transform(trimesh.transformations.rotation_matrix(-np.pi / 2, (1, 0, 0)))   # +Z -> +Y
    mesh.apply_translation((0.0, 1.0, 0.0))
    return _smooth(mesh)


def product():
    """A capsule (radius 0.3, 1.2 tall) standing on a 4 x 4 ground plane at y = 0."""
    import trimesh

    body = trimesh.creation.capsule(height=0.6, radius=0.3, count=(48, 48))
    body.apply_transform(trimesh.transformations.rotation_matrix(-np.pi / 2, (1, 0, 0)))
    body.apply_translation((0.0, 0.6, 0.0))
    ground = _flat([_quad((-2, 0, 2), (2, 0, 2), (2, 0, -2), (-2, 0, -2))])
    body = _smooth(body)
    return trimesh.util.concatenate([ground, body])


def _smooth(mesh):
    import trimesh

    from alight.core.mesh import smooth_normals

    mesh.merge_vertices()
    normals = smooth_normals(np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64))
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    return trimesh.Trimesh(mesh.vertices, mesh.faces, vertex_normals=normals, process=False)


def build(name: str):
    """The scene ``name`` (one of SCENES) as a trimesh.Trimesh."""
    if name not in SCENES:
        raise ValueError(f"unknown scene '{name}' (one of {', '.join(SCENES)})")
    return {"corner": corner, "bowl": bowl, "product": product}[name]()


def write_scene(name: str, folder: str | os.PathLike) -> Path:
    """Write scene ``name`` to ``folder/name.obj`` (normals, no material) and return the path."""
    path = Path(folder) / f"{name}.obj"
    path.parent.mkdir(parents=True, exist_ok=True)
    text = build(name).export(file_type="obj", include_normals=True, include_texture=False)
    tmp = path.with_suffix(".obj.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)
    return path
