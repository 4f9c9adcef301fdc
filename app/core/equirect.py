"""Area-weighted box reduction of equirectangular maps (docs/conventions.md's mapping).

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


def _cumulative_measure(t: np.ndarray, solid_angle: bool) -> np.ndarray:
    """The measure of [0, t] along an axis normalised to [0, 1]: t itself for columns (every
    column of a row spans the same solid angle), 1 - cos(pi t) for rows (the solid angle of the
    band from the pole down to theta = pi t, over 2 pi)."""
    return 1.0 - np.cos(math.pi * t) if solid_angle else t


def area_resample(block: np.ndarray, start: int, n_in: int, n_out: int, axis: int,
                  solid_angle: bool) -> tuple[int, np.ndarray]:
    """Exact area-weighted resampling of equirect cells along one axis, for any sizes.

    ``block`` holds input cells ``start .. start + m - 1`` (of ``n_in``) along ``axis`` (0 rows,
    1 columns); the map is piecewise constant over its cells. Returns ``(o0, sums)``: for the
    output cells ``o0 .. o0 + k - 1`` (of ``n_out``) that these input cells overlap, the integral
    of the block over the overlap divided by the output cell's whole measure (``solid_angle``:
    rows weighted by sin(theta), exactly, as 1 - cos; else uniform). Summed over blocks that tile
    the axis, that is each output cell's area-weighted mean, so the map's power (radiance times
    solid angle) is kept exactly and a constant map stays constant. Works through prefix sums:
    O(m) per line, float64."""
    b = np.moveaxis(np.asarray(block), axis, 0).astype(np.float64)
    m = b.shape[0]
    edges_in = (start + np.arange(m + 1, dtype=np.float64)) / n_in
    meas_in = _cumulative_measure(edges_in, solid_angle)
    shape = (-1,) + (1,) * (b.ndim - 1)
    prefix = np.concatenate([np.zeros((1,) + b.shape[1:]),
                             np.cumsum(b * np.diff(meas_in).reshape(shape), axis=0)], axis=0)
    o0 = int(math.floor(start * n_out / n_in))
    o1 = min(n_out, int(math.ceil((start + m) * n_out / n_in)))
    edges_out = np.arange(o0, o1 + 1, dtype=np.float64) / n_out
    clipped = np.clip(edges_out, edges_in[0], edges_in[-1])
    k = np.clip(np.floor(clipped * n_in - start).astype(np.int64), 0, m - 1)
    at = prefix[k] + b[k] * (_cumulative_measure(clipped, solid_angle) - meas_in[k]).reshape(shape)
    whole = np.diff(_cumulative_measure(edges_out, solid_angle)).reshape(shape)
    return o0, np.moveaxis(np.diff(at, axis=0) / whole, 0, axis)


def resample_equirect(radiance: np.ndarray, width: int) -> np.ndarray:
    """An equirect map (H, W, C) area-resampled to (width // 2, width), for any sizes (an odd or
    prime height included): columns by overlap length, rows by solid angle (area_resample)."""
    rad = np.asarray(radiance)
    h, w = rad.shape[:2]
    _, cols = area_resample(rad, 0, w, width, 1, False)
    _, rows = area_resample(cols, 0, h, width // 2, 0, True)
    return np.ascontiguousarray(rows, dtype=np.float32)
