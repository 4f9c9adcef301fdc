"""Error measures between a test image and a reference.

    relative_mae: sum |test - ref| / sum |ref| over the covered pixels (alpha > 0) and RGB, in
                  linear radiance (the figure the accuracy tables quote)
    flip:         NVIDIA's FLIP (Andersson et al. 2020, the ``flip-evaluator`` package) on the
                  tone-mapped sRGB images (ACES fitted, exposure 0: what a person looks at)
    heat maps:    per-pixel relative error and the FLIP map as PNGs with a labelled colour bar

Pure numpy (plus flip-evaluator, and matplotlib for the colour bar's labels); no GL.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from alight.errors import AlightError

# Per-pixel relative error shown at full colour in a heat map (anything above is clipped).
HEATMAP_REL_MAX = 0.25
# Height in pixels of the colour bar strip under a heat map, and the smallest width drawn
# (small images are enlarged by an integer factor so the bar's labels fit).
COLORBAR_HEIGHT = 44
HEATMAP_MIN_WIDTH = 320


def covered_mask(ref: np.ndarray, test: np.ndarray | None = None) -> np.ndarray:
    """Pixels with alpha > 0 in the reference (and in the test, when both have alpha); every
    pixel when neither has an alpha channel."""
    mask = np.ones(ref.shape[:2], bool)
    for img in (ref, test):
        if img is not None and img.ndim == 3 and img.shape[2] >= 4:
            mask &= img[:, :, 3] > 0.0
    return mask


def _rgb(img: np.ndarray) -> np.ndarray:
    img = np.asarray(img, dtype=np.float64)
    if img.ndim == 2:
        img = img[:, :, None]
    return np.repeat(img, 3, axis=2) if img.shape[2] == 1 else img[:, :, :3]


def _check_shapes(test: np.ndarray, ref: np.ndarray) -> None:
    if test.shape[:2] != ref.shape[:2]:
        raise ValueError(f"image sizes differ: {test.shape[1]}x{test.shape[0]} against "
                         f"{ref.shape[1]}x{ref.shape[0]}")


def relative_mae(test: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> float:
    """sum |test - ref| / sum |ref| over the mask's pixels (default: ``covered_mask``) and RGB.
    0 for identical images; inf when the reference is 0 there and the test is not."""
    _check_shapes(test, ref)
    if mask is None:
        mask = covered_mask(ref, test)
    t, r = _rgb(test)[mask], _rgb(ref)[mask]
    num = float(np.abs(t - r).sum())
    den = float(np.abs(r).sum())
    if den == 0.0:
        return 0.0 if num == 0.0 else math.inf
    return num / den


def relative_error_map(test: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
    """Per pixel sum_c |test - ref| / sum_c |ref| (H, W); 0 outside the mask. A pixel whose
    reference is 0 gets 0 when the test is 0 too, else inf."""
    _check_shapes(test, ref)
    if mask is None:
        mask = covered_mask(ref, test)
    num = np.abs(_rgb(test) - _rgb(ref)).sum(axis=2)
    den = np.abs(_rgb(ref)).sum(axis=2)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), np.where(num > 0.0, np.inf, 0.0))
    return np.where(mask, out, 0.0)


def tonemapped_srgb(linear: np.ndarray, exposure: float = 0.0) -> np.ndarray:
    """Linear radiance -> display sRGB in [0, 1] (H, W, 3) float32: exposure, ACES fitted, the
    sRGB curve (what ``alight render --out x.png`` shows, before 8-bit quantisation)."""
    from alight.core.shading import linear_to_srgb, tonemap_aces_fitted

    rgb = np.nan_to_num(_rgb(linear), nan=0.0, posinf=1e4, neginf=0.0) * (2.0 ** exposure)
    return linear_to_srgb(tonemap_aces_fitted(np.maximum(rgb, 0.0))).astype(np.float32)


def flip(test_srgb: np.ndarray, ref_srgb: np.ndarray, mask: np.ndarray | None = None) -> tuple[float, np.ndarray]:
    """LDR FLIP between two sRGB images in [0, 1] (or uint8): (mean over the mask, or over the
    whole image when mask is None; the per-pixel FLIP map (H, W) in [0, 1]).

    FLIP assumes a viewing distance (67 pixels per degree by default); a tiny image's value is
    still comparable between runs at the same size."""
    try:
        import flip_evaluator
    except ImportError as exc:   # a main dependency; only a broken install lacks it
        raise AlightError(f"FLIP needs the flip-evaluator package ({exc})") from None

    def as_float(img):
        img = np.asarray(img)
        img = img.astype(np.float32) / 255.0 if img.dtype.kind in "ui" else img.astype(np.float32)
        return np.ascontiguousarray(np.clip(_rgb(img), 0.0, 1.0), dtype=np.float32)

    _check_shapes(np.asarray(test_srgb), np.asarray(ref_srgb))
    error_map, mean, _ = flip_evaluator.evaluate(as_float(ref_srgb), as_float(test_srgb), "LDR",
                                                applyMagma=False)
    error_map = np.asarray(error_map, np.float32).reshape(np.asarray(test_srgb).shape[:2])
    if mask is not None:
        mean = float(error_map[mask].mean()) if mask.any() else 0.0
    return float(mean), error_map


@dataclass
class Comparison:
    """What ``compare_linear`` measured."""

    relative_mae: float
    flip: float
    covered: int                  # pixels compared
    relative_map: np.ndarray      # (H, W)
    flip_map: np.ndarray          # (H, W)


def compare_linear(test: np.ndarray, ref: np.ndarray, exposure: float = 0.0) -> Comparison:
    """relMAE in linear radiance and FLIP on the tone-mapped images, over the covered pixels."""
    test, ref = np.asarray(test), np.asarray(ref)
    _check_shapes(test, ref)
    mask = covered_mask(ref, test)
    rel = relative_mae(test, ref, mask)
    mean_flip, flip_map = flip(tonemapped_srgb(test, exposure), tonemapped_srgb(ref, exposure), mask)
    return Comparison(rel, mean_flip, int(mask.sum()), relative_error_map(test, ref, mask), flip_map * mask)


# --- heat maps ---------------------------------------------------------------------------

def heatmap_scale(width: int) -> int:
    """The integer enlargement a heat map of this width is drawn at (>= 1)."""
    return max(1, math.ceil(HEATMAP_MIN_WIDTH / max(1, int(width))))


def heatmap_size(width: int, height: int) -> tuple[int, int]:
    """(width, height) in pixels of the PNG ``write_heatmap`` writes for a W x H error map."""
    s = heatmap_scale(width)
    return width * s, height * s + COLORBAR_HEIGHT


def colorize(values: np.ndarray, vmax: float, cmap: str = "magma") -> np.ndarray:
    """Values in [0, vmax] (clipped) through a matplotlib colour map -> uint8 (H, W, 3)."""
    from matplotlib import colormaps

    v = np.clip(np.nan_to_num(np.asarray(values, np.float64), nan=vmax, posinf=vmax) / vmax, 0.0, 1.0)
    return (colormaps[cmap](v)[..., :3] * 255.0 + 0.5).astype(np.uint8)


def write_heatmap(path: str | os.PathLike, values: np.ndarray, vmax: float, label: str,
                  cmap: str = "magma", percent: bool = False) -> Path:
    """Write ``values`` (H, W) as a PNG heat map, atomically: the map pixel for pixel (enlarged
    by ``heatmap_scale``, nearest neighbour) above a colour bar from 0 to ``vmax`` with ``label``.
    Values above vmax are drawn at vmax's colour. Returns the path."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    from alight.exchange.output import atomic_path

    values = np.asarray(values, np.float64)
    h, w = values.shape
    s = heatmap_scale(w)
    W, H = heatmap_size(w, h)
    rgb = colorize(np.kron(values, np.ones((s, s))), vmax, cmap)
    dpi = 100.0
    fig = Figure(figsize=(W / dpi, H / dpi), dpi=dpi, facecolor="white")
    fig.figimage(rgb, xo=0, yo=COLORBAR_HEIGHT, origin="upper")
    # The strip under the map, bottom up: tick labels (0-18 px), the bar (20-28), the label (31-43).
    ax = fig.add_axes((0.04, 20.0 / H, 0.92, 8.0 / H))
    gradient = np.linspace(0.0, 1.0, 256)[None, :]
    ax.imshow(gradient, aspect="auto", cmap=cmap, extent=(0.0, vmax, 0.0, 1.0))
    ax.set_yticks([])
    ticks = np.linspace(0.0, vmax, 6)
    ax.set_xticks(ticks)
    ax.set_xticklabels([f"{t * 100:g}%" if percent else f"{t:g}" for t in ticks], fontsize=6)
    ax.tick_params(axis="x", length=2, pad=1)
    fig.text(0.5, 31.0 / H, label + (f" (clipped at {vmax * 100:g}%)" if percent else ""),
             ha="center", va="bottom", fontsize=6)
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format="png")
    return path


def write_relative_heatmap(path, rel_map: np.ndarray, vmax: float = HEATMAP_REL_MAX) -> Path:
    return write_heatmap(path, rel_map, vmax, "per-pixel relative error sum|test-ref|/sum|ref|", percent=True)


def write_flip_heatmap(path, flip_map: np.ndarray) -> Path:
    return write_heatmap(path, flip_map, 1.0, "FLIP (0 = no visible difference, 1 = most)")


# --- reading images for `alight compare` --------------------------------------------------

def read_linear(path: str | os.PathLike) -> np.ndarray:
    """A linear float image (.exr or .hdr) as float32 (H, W, C); AlightError naming the file
    for anything else."""
    import OpenImageIO as oiio

    p = str(path)
    if not os.path.exists(p):
        raise AlightError(f"{p}: no such file")
    if os.path.isdir(p):
        raise AlightError(f"{p}: is a directory, not an image")
    if Path(p).suffix.lower() not in (".exr", ".hdr"):
        raise AlightError(f"{p}: not a linear image (use .exr, e.g. from 'alight render --out x.exr' "
                          f"or 'alight reference')")
    inp = oiio.ImageInput.open(p)
    if inp is None:
        raise AlightError(f"{p}: cannot read the image ({' '.join(oiio.geterror().split())})")
    try:
        pixels = inp.read_image(format=oiio.FLOAT)
    finally:
        inp.close()
    if pixels is None:
        raise AlightError(f"{p}: cannot read the pixels ({' '.join(oiio.geterror().split())})")
    pixels = np.asarray(pixels, np.float32)
    if pixels.ndim == 2:
        pixels = pixels[:, :, None]
    if pixels.size == 0:
        raise AlightError(f"{p}: empty image")
    if not np.isfinite(pixels).all():
        raise AlightError(f"{p}: holds NaN or infinite values")
    return pixels
