"""Per-vertex ambient occlusion from depth maps seen from many directions: pure numpy.

A vertex's occlusion is the cosine-weighted share of directions from which it is seen, over
directions spread evenly on the sphere (a Fibonacci lattice): ``sum max(n.d, 0) V(d) / sum
max(n.d, 0)``, V(d) = 1 where the vertex is the nearest surface along d in the orthographic
depth map seen from d (app/render/occlusion.py draws them on the GPU). This is visibility of an
environment that is infinitely far, the ``ambient occlusion`` a glTF occlusion texture holds,
so the two combine by their minimum (each already holds the larger-scale occlusion it sees; a
product would count the same blocker twice)."""

from __future__ import annotations

import numpy as np

from alight.core.shadow_fit import ShadowView


def sphere_directions(n: int) -> np.ndarray:
    """(n, 3) unit vectors spread evenly on the sphere (the Fibonacci lattice)."""
    k = np.arange(n, dtype=np.float64) + 0.5
    z = 1.0 - 2.0 * k / n
    r = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    a = np.pi * (3.0 - np.sqrt(5.0)) * k
    return np.stack([r * np.cos(a), r * np.sin(a), z], axis=1)


def visible_from(view: ShadowView, depth: np.ndarray, positions: np.ndarray, normals: np.ndarray,
                 toward: np.ndarray) -> np.ndarray:
    """(N,) bool: whether each vertex is the nearest surface in ``depth`` ((R, R) values in [0, 1],
    row 0 at the bottom, as GL reads) of the orthographic ``view`` looking along -``toward``.
    Vertices are moved off the surface along their normal by 1.5 texels, and compared with a
    bias of a texel times (1 + 2 tan theta), theta the angle between normal and ``toward``."""
    n_dot_d = normals @ toward
    p = positions + normals * (1.5 * view.texel) * np.sign(n_dot_d)[:, None]
    clip = np.hstack([p, np.ones((len(p), 1))]) @ view.matrix.T
    ndc = clip[:, :3] / clip[:, 3:4]
    res = depth.shape[0]
    ij = np.clip(((ndc[:, :2] * 0.5 + 0.5) * res).astype(np.int64), 0, res - 1)
    stored = depth[ij[:, 1], ij[:, 0]]
    cos = np.clip(np.abs(n_dot_d), 1e-3, 1.0)
    tan = np.minimum(np.sqrt(1.0 - cos * cos) / cos, 8.0)
    bias = view.texel * (1.0 + 2.0 * tan) / (view.far - view.near)
    return (ndc[:, 2] * 0.5 + 0.5) <= stored + bias


def accumulate(weights_sum: np.ndarray, visible_sum: np.ndarray, normals: np.ndarray, toward: np.ndarray,
               visible: np.ndarray) -> None:
    """Add direction ``toward``'s cosine weight to ``weights_sum`` and, where visible, to
    ``visible_sum`` (both (N,), in place)."""
    w = np.maximum(normals @ toward, 0.0)
    weights_sum += w
    visible_sum += w * visible


def occlusion(weights_sum: np.ndarray, visible_sum: np.ndarray) -> np.ndarray:
    """(N,) float32 in [0, 1]: 1 unoccluded."""
    return np.where(weights_sum > 0.0, visible_sum / np.maximum(weights_sum, 1e-30), 1.0).astype(np.float32)
