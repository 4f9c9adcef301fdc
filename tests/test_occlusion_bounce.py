"""The occluders' irradiance from the bake's mean bent normal (bounce_irradiance): a back wall
between two partitions (EmissiveStrengthTest's bays) under a sky brighter on one side. The
bounce's one fetch at the hits' mean direction, normalised, took the hits on both partitions as
all facing the brighter side: the wall beside the partition that faces it was lit by up to twice
the traced light (EmissiveStrengthTest's lighter patches, docs/explanation/occlusion.md)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("embreex")

from alight.core import visibility as vis  # noqa: E402
from alight.core.mesh import FileMaterial, Mesh  # noqa: E402
from tests.gpu import evaluate  # noqa: E402
from tests.quad_meshes import quad_part  # noqa: E402

# Radiance linear in the direction: L(l) = 1 + SLOPE l.x (bright at +x), so E(n)/pi = 1 + (2/3) SLOPE n.x.
SLOPE = 0.9


GREY_DIFFUSE = FileMaterial(base_color=(0.7, 0.7, 0.7), metallic=0.0, roughness=1.0)


def _bay() -> Mesh:
    """A back wall z = 0 (x in [-1.5, 1.5], y in [0, 3], facing +z) and two partitions x = +-1.5
    reaching out to z = 2, facing into the bay."""
    wall = [((-1.5, 0, 0), (1.5, 0, 0), (1.5, 3, 0), (-1.5, 3, 0))]
    left = [((-1.5, 0, 0), (-1.5, 3, 0), (-1.5, 3, 2), (-1.5, 0, 2))]     # faces +x
    right = [((1.5, 0, 0), (1.5, 0, 2), (1.5, 3, 2), (1.5, 3, 0))]        # faces -x
    return Mesh([quad_part(wall, "wall", GREY_DIFFUSE), quad_part(left + right, "partitions", GREY_DIFFUSE)], "bay")


def _cosine_rays(n: np.ndarray, count: int, rng) -> np.ndarray:
    """(len(n), count, 3) cosine-weighted directions about each unit normal."""
    local = vis.cosine_directions(count)
    t, s = vis._frame(n)
    angle = rng.uniform(0.0, 2.0 * np.pi, len(n))[:, None]
    x = local[None, :, 0] * np.cos(angle) - local[None, :, 1] * np.sin(angle)
    y = local[None, :, 0] * np.sin(angle) + local[None, :, 1] * np.cos(angle)
    return x[..., None] * t[:, None] + y[..., None] * s[:, None] + local[None, :, 2, None] * n[:, None]


def _traced_occluders(mesh: Mesh, points: np.ndarray, normal: np.ndarray, rays: int = 256, hit_rays: int = 256):
    """Per point, the mean over its cosine-weighted rays of what they hit sends back of the sky,
    one bounce per unit albedo (0 for a ray that escapes): the hits' visible irradiance / pi,
    L(l) over their own free rays, traced."""
    rng = np.random.default_rng(3)
    tris = np.concatenate([np.asarray(p.positions, np.float64)[np.asarray(p.indices, np.int64).reshape(-1, 3)]
                           for p in mesh.parts])
    occ = vis._Occluders(tris)
    eps = 1e-4
    d = _cosine_rays(np.repeat(normal[None], len(points), 0), rays, rng).reshape(-1, 3)
    o = np.repeat(points + eps * normal, rays, 0)
    prim, u, v = vis._cast(occ.scene, o.astype(np.float32), d.astype(np.float32), occ.normals, eps)
    h = prim >= 0
    tri = tris[prim[h]]
    at = tri[:, 0] + u[h, None] * (tri[:, 1] - tri[:, 0]) + v[h, None] * (tri[:, 2] - tri[:, 0])
    hn = occ.normals[prim[h]].astype(np.float64)
    hn = np.where((np.einsum("ij,ij->i", hn, d[h]) > 0.0)[:, None], -hn, hn)
    d2 = _cosine_rays(hn, hit_rays, rng).reshape(-1, 3)
    o2 = np.repeat(at + eps * hn, hit_rays, 0)
    p2, _, _ = vis._cast(occ.scene, o2.astype(np.float32), d2.astype(np.float32), occ.normals, eps)
    seen = ((1.0 + SLOPE * d2[:, 0]) * (p2 < 0)).reshape(len(at), hit_rays).mean(axis=1)
    out = np.zeros(len(points))
    np.add.at(out, np.repeat(np.arange(len(points)), rays)[h], seen)
    return out / rays


def test_the_occluders_beside_a_partition_are_lit_as_traced():
    mesh = _bay()
    baked = vis.bake_visibility(mesh)
    wall = baked.parts[0]
    p = wall.positions.astype(np.float64)
    near = (np.abs(p[:, 0]) < 1.3) & (p[:, 1] > 0.8) & (p[:, 1] < 2.2)
    assert near.sum() >= 20
    b = wall.bounce_direction[near].astype(np.float64)
    w = wall.bounce_weight[near].astype(np.float64)
    length = np.linalg.norm(b, axis=1)
    unit = b / length[:, None]
    # The hits on the two partitions half cancel: the mean is well short of a unit vector.
    assert np.median(length) < 0.9
    irradiance = lambda n: 1.0 + (2.0 / 3.0) * SLOPE * n[:, :1]  # noqa: E731  (E/pi, grey)
    drawn = w * vis.bounce_irradiance(length, irradiance(unit), irradiance(-unit))[:, 0]
    traced = _traced_occluders(mesh, p[near], np.array([0.0, 0.0, 1.0]))
    left = p[near, 0] < 0.0          # beside the partition that faces the bright side
    ratio = [drawn[side].mean() / traced[side].mean() for side in (left, ~left)]
    assert 0.85 < min(ratio) and max(ratio) < 1.12, ratio
    assert ratio[0] / ratio[1] < 1.25, ratio
    # The one fetch at the unit mean direction (before): the bright side's half lit about 1.4x
    # as much as the other, against the traced light.
    before = w * irradiance(unit)[:, 0]
    was = [before[side].mean() / traced[side].mean() for side in (left, ~left)]
    assert was[0] / was[1] > 1.3, was


def test_bounce_irradiance_matches_its_numpy_twin():
    rng = np.random.default_rng(11)
    n = 300
    rows = np.column_stack([rng.uniform(0.0, 1.6, n), rng.uniform(0.0, 3.0, n), rng.uniform(0.0, 3.0, n),
                            rng.uniform(0.0, 3.0, n)])
    gpu = evaluate(12, rows, shader="accuracy/evaluate_occlusion.comp")[:, :3]
    along = np.column_stack([rows[:, 1], rows[:, 3], rows[:, 3]])
    against = np.repeat(rows[:, 2:3], 3, axis=1)
    np.testing.assert_allclose(gpu, vis.bounce_irradiance(rows[:, 0], along, against), atol=1e-5)
    # Linear in the direction: E's mean over directions d_i is (E(u) + E(-u))/2 + |m| (E(u) - E(-u))/2.
    e = lambda d: 2.0 + 0.7 * d[:, 0] - 0.2 * d[:, 2]  # noqa: E731
    dirs = rng.normal(size=(50, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    m = dirs.mean(axis=0)
    u = (m / np.linalg.norm(m))[None]
    np.testing.assert_allclose(vis.bounce_irradiance(np.linalg.norm(m)[None], e(u)[:, None], e(-u)[:, None])[0, 0],
                               e(dirs).mean(), rtol=1e-9)
