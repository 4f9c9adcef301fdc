"""Area-weighted box reduction of equirectangular maps (CONVENTIONS.md's mapping).

Shared by the environment-file reader (``alight.exchange.environment_files``, strip by strip),
the converged twins and the GPU reference's ``--env-level``.
"""

from __future__ import annotations

import math

import numpy as np


def _row_weights(y0: int, y1: int, height: int) -> np.ndarray:
    """Solid-angle weights sin(theta) of rows y0..y1-1 of a map `height` rows tall."""
    return np.sin((np.arange(y0, y1, dtype=np.float64) + 0.5) * (math.pi / height))


def _reduce_columns(strip: np.ndarray, factor: int) -> np.ndarray:
    """Box-average groups of `factor` columns: (h, W, 3) -> (h, W // factor, 3), float64."""
    h, w, c = strip.shape
    return strip.reshape(h, w // factor, factor, c).mean(axis=2, dtype=np.float64)


def _reduce_rows(strip: np.ndarray, factor: int, y0: int, height: int) -> np.ndarray:
    """Solid-angle weighted average of groups of `factor` rows (y0 a multiple of factor)."""
    h, w, c = strip.shape
    wts = _row_weights(y0, y0 + h, height).reshape(h // factor, factor)
    s = (strip.reshape(h // factor, factor, w, c) * wts[:, :, None, None]).sum(axis=1)
    return s / wts.sum(axis=1)[:, None, None]


def box_reduce(radiance: np.ndarray, factor: int) -> np.ndarray:
    """Area-weighted integer box reduction of an equirect map by `factor` in both axes.

    Columns are plain means (equal solid angle within a row); rows are averaged with their
    solid-angle weights sin(theta), so the integral of radiance times solid angle is kept to
    second order in the row spacing. H must be divisible by `factor`.
    """
    rad = np.asarray(radiance)
    h = rad.shape[0]
    if factor < 1 or h % factor or rad.shape[1] % factor:
        raise ValueError(f"box factor {factor} does not divide the map size {rad.shape[1]}x{h}")
    if factor == 1:
        return np.ascontiguousarray(rad, dtype=np.float32)
    out = _reduce_rows(_reduce_columns(rad, factor), factor, 0, h)
    return np.ascontiguousarray(out, dtype=np.float32)


def _box_factor(width: int, height: int, max_width: int) -> int:
    """The smallest integer factor >= width / max_width that divides the height (and so the width)."""
    f = max(1, -(-width // max_width))
    while height % f:
        f += 1
    return f
