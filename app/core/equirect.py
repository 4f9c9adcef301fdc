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


# Output cells that overlap at most this many input cells are summed from their overlaps
# directly (a few multiply-adds per texel in the input's precision); larger reductions go through
# float64 prefix sums, whose cost does not grow with the ratio. On awkward_8198x4099.exr (2.0x)
# the direct sums took read_equirect's resampling from 6.2 s to 2.2 s (profiled, one loaded run)
# and agree with the prefix sums to 1.5e-7.
_GATHER_SPAN = 4


def area_resample(block: np.ndarray, start: int, n_in: int, n_out: int, axis: int,
                  solid_angle: bool) -> tuple[int, np.ndarray]:
    """Exact area-weighted resampling of equirect cells along one axis, for any sizes.

    ``block`` holds input cells ``start .. start + m - 1`` (of ``n_in``) along ``axis`` (0 rows,
    1 columns); the map is piecewise constant over its cells. Returns ``(o0, sums)``: for the
    output cells ``o0 .. o0 + k - 1`` (of ``n_out``) that these input cells overlap, the integral
    of the block over the overlap divided by the output cell's whole measure (``solid_angle``:
    rows weighted by sin(theta), exactly, as 1 - cos; else uniform). Summed over blocks that tile
    the axis, that is each output cell's area-weighted mean, so the map's power (radiance times
    solid angle) is kept exactly and a constant map stays constant. O(m) per line: the overlaps'
    weighted sums where an output cell meets at most _GATHER_SPAN input cells, else prefix sums
    in float64."""
    span = -(-n_in // n_out) + 1
    if span <= _GATHER_SPAN:
        return _area_resample_direct(np.asarray(block), start, n_in, n_out, axis, solid_angle, span)
    return _area_resample_prefix(block, start, n_in, n_out, axis, solid_angle)


def _area_resample_direct(b: np.ndarray, start: int, n_in: int, n_out: int, axis: int, solid_angle: bool,
                          span: int) -> tuple[int, np.ndarray]:
    """area_resample as each output cell's sum over the ``span`` input cells it can overlap, with
    weights computed in float64 (the overlap's measure over the output cell's)."""
    m = b.shape[axis]
    o0 = (start * n_out) // n_in
    o1 = min(n_out, -(-(start + m) * n_out // n_in))
    o = np.arange(o0, o1, dtype=np.int64)
    idx = (o * n_in // n_out)[:, None] + np.arange(span, dtype=np.int64)[None, :]
    lo = np.maximum(idx / n_in, (o / n_out)[:, None])
    hi = np.minimum((idx + 1) / n_in, ((o + 1) / n_out)[:, None])
    inside = (idx >= start) & (idx < start + m) & (hi > lo)
    whole = _cumulative_measure((o + 1) / n_out, solid_angle) - _cumulative_measure(o / n_out, solid_angle)
    weights = np.where(inside, _cumulative_measure(hi, solid_angle) - _cumulative_measure(lo, solid_angle), 0.0)
    weights = weights / whole[:, None]
    local = np.clip(idx - start, 0, m - 1)
    dtype = np.float32 if b.dtype == np.float32 else np.float64
    shape = [1] * b.ndim
    shape[axis] = -1
    out = np.zeros(b.shape[:axis] + (len(o),) + b.shape[axis + 1:], dtype)
    for k in range(span):
        used = weights[:, k] != 0.0
        if not used.any():
            continue
        out += np.take(b, local[:, k], axis=axis) * weights[:, k].astype(dtype).reshape(shape)
    return o0, out


def _area_resample_prefix(block: np.ndarray, start: int, n_in: int, n_out: int, axis: int,
                          solid_angle: bool) -> tuple[int, np.ndarray]:
    """area_resample through prefix sums in float64 (any ratio)."""
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
