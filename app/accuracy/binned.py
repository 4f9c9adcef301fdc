"""Binned relative error: the measure a noisy reference (a path tracer's) can be held to.

Per-pixel relMAE against a Monte Carlo image counts its noise as error; summing both images over
``factor`` x ``factor`` blocks first divides that noise by ``factor`` while leaving a shading
error (smooth over a block) as it is. Only blocks every pixel of which is covered in both images
(alpha 1) count, so silhouettes, where anti-aliasing filters differ, stay out.
"""

from __future__ import annotations

import numpy as np


def binned_sums(image: np.ndarray, factor: int) -> np.ndarray:
    """(H, W, C) summed over factor x factor blocks: (H // factor, W // factor, C); the last
    rows and columns that do not fill a block are dropped."""
    h, w = image.shape[0] // factor * factor, image.shape[1] // factor * factor
    c = image.shape[2]
    return image[:h, :w].reshape(h // factor, factor, w // factor, factor, c).sum(axis=(1, 3))


def _alpha(image: np.ndarray) -> np.ndarray:
    """The alpha channel, or 1 everywhere for an image without one (an .hdr)."""
    return image[..., 3] if image.shape[2] >= 4 else np.ones(image.shape[:2])


def covered_blocks(test: np.ndarray, ref: np.ndarray, factor: int) -> np.ndarray:
    """(H // factor, W // factor) bool: blocks whose every pixel has alpha 1 in both images."""
    full = ((_alpha(test) >= 1.0) & (_alpha(ref) >= 1.0)).astype(np.float64)[..., None]
    return binned_sums(full, factor)[..., 0] >= factor * factor - 0.5


def binned_relative_mae(test: np.ndarray, ref: np.ndarray, factor: int = 4, mask: np.ndarray | None = None) -> float:
    """sum |T_b - R_b| / sum R_b over the RGB of the covered blocks b (``covered_blocks``; and
    ``mask``, (H // factor, W // factor) bool, where given). test, ref: (H, W, 3 or 4) linear. NaN
    where no block is covered."""
    t = binned_sums(np.asarray(test, np.float64)[..., :3], factor)
    r = binned_sums(np.asarray(ref, np.float64)[..., :3], factor)
    keep = covered_blocks(test, ref, factor)
    if mask is not None:
        keep &= mask
    if not keep.any():
        return float("nan")
    return float(np.abs(t[keep] - r[keep]).sum() / max(r[keep].sum(), 1e-30))
