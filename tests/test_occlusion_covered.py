"""A thin part lying on a big flat face (OrientationTest's arrows on its cube): the bake must not
darken the face beyond where the part's shadow lies.

The face's refined vertices that fall under the part (in a thin gap below it, inside it where it
sinks into the face, or level with its bottom) see nothing but the part: V ~ 0. Nothing of them is
drawn but their share of their triangles' interpolation, and that ran jagged black blotches out
to the next vertex beyond the part (a bright smear by the bounce off the part's inside). Now such
covered vertices take their open neighbours' values (visibility._fill_covered).

Measured here without the GPU, as the rasteriser draws it: V interpolated linearly over the
refined triangles of the face, at points of the face around the part, against V ray-traced at
those points (1024 cosine rays each against the scene's own triangles). The test writes its own
OBJ (trimesh) and reads it with alight's loader."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("embreex")
trimesh = pytest.importorskip("trimesh")

from alight.core import visibility as vis  # noqa: E402
from alight.exchange.meshes import load_mesh  # noqa: E402

HALF = (1.5, 0.15, 0.4)      # the part: a thin box 3 x 0.3 x 0.8 lying on the face,
CENTRE = (0.3, -0.2)         # at this (x, z),
ANGLE = np.radians(30.0)     # turned about +Y, across the face's refined edges (as the arrows lie)


def _plane_and_box(path, bottom: float):
    """A 10 x 10 face of two triangles at y = 0 facing +Y and a closed box (flat normals) whose
    bottom is at y = ``bottom``, as one OBJ."""
    plane = trimesh.Trimesh(np.array([[-5, 0, -5], [-5, 0, 5], [5, 0, 5], [5, 0, -5]], np.float64),
                            np.array([[0, 1, 2], [0, 2, 3]]), process=False)
    box = trimesh.creation.box(extents=2.0 * np.array(HALF))
    box.apply_transform(trimesh.transformations.rotation_matrix(ANGLE, [0.0, 1.0, 0.0]))
    box.apply_translation([CENTRE[0], bottom + HALF[1], CENTRE[1]])
    box.unmerge_vertices()
    both = trimesh.util.concatenate([plane, box])
    normals = np.vstack([np.tile([0.0, 1.0, 0.0], (4, 1)), box.face_normals.repeat(3, axis=0)])
    mesh = trimesh.Trimesh(both.vertices, both.faces, vertex_normals=normals, process=False)
    path.write_text(mesh.export(file_type="obj", include_normals=True, include_texture=False))
    return path


def _face_triangles(baked):
    """The refined face's triangles (positions (T, 3, 3), V (T, 3)): those at y = 0 facing up."""
    tris, vals = [], []
    for p in baked.parts:
        f = np.asarray(p.indices, np.int64).reshape(-1, 3)
        pos, n = np.asarray(p.positions, np.float64)[f], np.asarray(p.normals, np.float64)[f]
        face = (np.abs(pos[..., 1]).max(axis=1) < 1e-6) & (n[..., 1].min(axis=1) > 0.99)
        tris.append(pos[face])
        vals.append(np.asarray(p.visibility, np.float64)[f][face])
    return np.concatenate(tris), np.concatenate(vals)


def _interpolated(points, tris, vals):
    """V at points (P, 3) of the face, linearly over the refined triangle holding each (x, z)."""
    a, b, c = tris[:, 0][:, [0, 2]], tris[:, 1][:, [0, 2]], tris[:, 2][:, [0, 2]]
    q = points[:, None, [0, 2]]
    det = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    u = ((q - a)[..., 0] * (c - a)[:, 1] - (q - a)[..., 1] * (c - a)[:, 0]) / det
    v = ((b - a)[:, 0] * (q - a)[..., 1] - (b - a)[:, 1] * (q - a)[..., 0]) / det
    inside = (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9)
    k = inside.argmax(axis=1)
    assert inside.any(axis=1).all()
    rows = np.arange(len(points))
    uu, vv = u[rows, k], v[rows, k]
    return (1 - uu - vv) * vals[k, 0] + uu * vals[k, 1] + vv * vals[k, 2]


def _traced(mesh, points, rays: int = 1024):
    tris = np.concatenate([np.asarray(p.positions, np.float64)[np.asarray(p.indices, np.int64).reshape(-1, 3)]
                           for p in mesh.parts])
    occluders = vis._Occluders(tris)
    up = np.tile([0.0, 1.0, 0.0], (len(points), 1))
    hit, _, _ = occluders.hemisphere((points + 1e-4 * up).astype(np.float32), up.astype(np.float32), rays,
                                     np.random.default_rng(1), 1e-4)
    return (hit < 0).mean(axis=1)


def _points_around_the_part(margin: float = 0.03, reach: float = 1.0):
    """A grid of the face's points outside the part's footprint by at least ``margin``, within
    ``reach`` of it."""
    x, z = np.meshgrid(np.linspace(-3.0, 3.6, 133), np.linspace(-2.5, 2.1, 93))
    points = np.column_stack([x.ravel(), np.zeros(x.size), z.ravel()])
    qx, qz = points[:, 0] - CENTRE[0], points[:, 2] - CENTRE[1]
    dx = np.abs(qx * np.cos(ANGLE) - qz * np.sin(ANGLE)) - HALF[0]     # in the box's own axes
    dz = np.abs(qx * np.sin(ANGLE) + qz * np.cos(ANGLE)) - HALF[2]
    outside = np.hypot(np.maximum(dx, 0), np.maximum(dz, 0))
    return points[(outside > margin) & (outside < reach)]


@pytest.mark.parametrize("bottom", [0.004, 0.0, -0.1], ids=["thin gap", "level", "sunk"])
def test_a_part_lying_on_a_big_face_does_not_blotch_it(tmp_path, bottom):
    mesh = load_mesh(str(_plane_and_box(tmp_path / "plane_and_box.obj", bottom)))
    baked = vis.bake_visibility(mesh)
    tris, vals = _face_triangles(baked)
    points = _points_around_the_part()
    drawn = _interpolated(points, tris, vals)
    truth = _traced(mesh, points)
    darker = truth - drawn
    # Before: V ~ 0 under the part, interpolated out to the next vertex: the face drawn darker
    # than it is by 0.51 to 0.54 next to the part's edge (now 0.10 to 0.11: the wall's foot, a
    # ramp drawn linearly, and the rays' noise).
    assert darker.max() < 0.2, (darker.max(), points[darker.argmax()], truth[darker.argmax()])
    # and not a blanket brightening: on average the drawn V follows the traced one.
    assert np.abs(darker).mean() < 0.06, np.abs(darker).mean()
