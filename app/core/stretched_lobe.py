"""The `stretched` IBL model's lobe table (``app/core/stretched_lobe.json``, written by
``tools/fit_stretched_lobe.py``) and the numpy twin of its lookup (``shaders/common/ibl.glsl``:
``stretched_prefiltered_radiance``).

The table: for the specular lobe's F0-scaled part (A) and its bias part (B), per (n.v,
roughness) texel centre (8 x 16), two round prefiltered fetches fitted to the real lobe in lobe
space: (a_lo, a_hi, w_hi, beta) = their signed angles (radians, toward the horizon positive) from
the lobe's mean direction in the plane of incidence, the second one's weight, and the fetches'
alpha over the material's. Rows below r = 0.2 are the round lookup (0, 0, 0, 1).

Below ``ROUGHNESS_START`` the model takes the single round fetch at the mean direction (the
`alight` model's) and blends to the two fetches by ``ROUGHNESS_FULL`` (``blend_weight``). The
pair was held back to r 0.3-0.5 for a ghost on a floor seen from 60 degrees at r 0.3; that ghost
was two cells of the table (their far fetch of 1% weight, carried by the bilinear lookup into the
neighbouring cell's 12-28% weight, set by hand since), and with them the pair is full from r 0.3
(benchmarks/results/stretched_pair_from_r02.md). The blend mixes the fetches' results: mixing the table toward the round lookup instead made lobes
that fit neither (royal_esplanade's floor at r 0.4: 104% off, both ends under 6%).
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np

TABLE_PATH = Path(__file__).with_name("stretched_lobe.json")

# The roughness range over which the single round fetch blends into the two fitted ones
# (shader defines STRETCHED_ROUGHNESS_START / _FULL, set by alight.render.variants.ibl_defines).
ROUGHNESS_START = 0.2
ROUGHNESS_FULL = 0.3


def blend_weight(roughness):
    """The two fetches' share of the prefiltered radiance at ``roughness`` (GLSL smoothstep from
    ROUGHNESS_START to ROUGHNESS_FULL): 0 below, 1 above; same shape as ``roughness``."""
    t = np.clip((np.asarray(roughness, np.float64) - ROUGHNESS_START) / (ROUGHNESS_FULL - ROUGHNESS_START), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


@functools.lru_cache(maxsize=1)
def lobe_table() -> np.ndarray:
    """(2, n_roughness, n_n_dot_v, 4) float32: parts A and B, rows roughness, columns n.v."""
    doc = json.loads(TABLE_PATH.read_text())
    table = np.asarray([doc["A"], doc["B"]], dtype=np.float32)
    if table.ndim != 4 or table.shape[0] != 2 or table.shape[3] != 4 or not np.isfinite(table).all():
        raise ValueError(f"{TABLE_PATH}: not a (2, R, N, 4) table of finite numbers")
    return table


def sample_table(part: np.ndarray, n_dot_v, roughness) -> np.ndarray:
    """Bilinear lookup of one part (R, N, 4) at texel-centre coordinates, clamped at the edges
    (GL_LINEAR with CLAMP_TO_EDGE, as the shader's texture()): (P, 4)."""
    rows, cols = part.shape[:2]
    x = np.clip(np.asarray(n_dot_v, np.float64) * cols - 0.5, 0.0, cols - 1.0)
    y = np.clip(np.asarray(roughness, np.float64) * rows - 0.5, 0.0, rows - 1.0)
    x0 = np.minimum(np.floor(x).astype(int), cols - 2) if cols > 1 else np.zeros_like(x, int)
    y0 = np.minimum(np.floor(y).astype(int), rows - 2) if rows > 1 else np.zeros_like(y, int)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    x1, y1 = np.minimum(x0 + 1, cols - 1), np.minimum(y0 + 1, rows - 1)
    p = part.astype(np.float64)
    top = p[y0, x0] * (1 - fx) + p[y0, x1] * fx
    bottom = p[y1, x0] * (1 - fx) + p[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


def pole_fade(n_dot_v, columns: int):
    """The fetches' angles' share at ``n_dot_v`` (shaders/common/ibl.glsl pole_fade): 1 up to the
    table's last n.v texel centre (1 - 0.5 / columns), 0 at n.v = 1, as sqrt(1 - n.v) ~ theta
    between. At normal incidence the lobe is round about n and the direction "toward the horizon"
    turns about the pole with the view, so an offset held there draws a pinch at the front of a
    ball (seen on a rough metal, r 0.6). An offset in proportion to theta (the lobe's asymmetry
    near the pole) is a smooth vector field over the ball's front. Cost, measured against the
    exact answer on the probe (4 maps x gold, silver, water x r 0.4/0.6/0.9, the twins of
    tests/test_ibl_models.py): mean relMAE 4.04% -> 4.11% (a linear fade: 4.15%), worst newport_loft
    silver r 0.6 4.99% -> 5.7%; the lecture's mean is 33.4%. The pinch's error was small in area
    and the probe's metric cannot see it; the eye does."""
    return np.sqrt(np.clip((1.0 - np.asarray(n_dot_v, np.float64)) * 2.0 * columns, 0.0, 1.0))


def stretched_fetches(n, v, d, f0, lut_a, lut_b, roughness):
    """The two fetches of ``stretched_prefiltered_radiance`` for points with normals ``n``, views
    ``v``, mean directions ``d`` (P, 3) and the BRDF LUT's A, B (P,): (d_lo, d_hi (P, 3), w_hi
    (P,), fetch roughness (P,))."""
    table = lobe_table()
    n, v, d = (np.asarray(x, np.float64) for x in (n, v, d))
    n_dot_v = np.maximum(np.sum(n * v, -1), 0.0)
    weight_a = float(np.dot(np.asarray(f0, np.float64), (0.2126, 0.7152, 0.0722))) * np.asarray(lut_a)
    b = np.asarray(lut_b)
    fit = (weight_a[:, None] * sample_table(table[0], n_dot_v, roughness)
           + b[:, None] * sample_table(table[1], n_dot_v, roughness)) / np.maximum(weight_a + b, 1e-6)[:, None]
    toward = d * np.sum(n * d, -1, keepdims=True) - n
    length = np.linalg.norm(toward, axis=-1, keepdims=True)
    toward = np.where(length * length > 1e-10, toward / np.maximum(length, 1e-300), 0.0)
    offsets = fit[:, :2] * pole_fade(n_dot_v, table.shape[2])[:, None]
    d_lo = np.cos(offsets[:, :1]) * d + np.sin(offsets[:, :1]) * toward
    d_hi = np.cos(offsets[:, 1:2]) * d + np.sin(offsets[:, 1:2]) * toward
    return d_lo, d_hi, fit[:, 2], float(roughness) * np.sqrt(fit[:, 3])
