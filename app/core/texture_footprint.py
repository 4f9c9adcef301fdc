"""How much anisotropic filtering a view of a textured mesh gains: the texel footprint of its
pixels, from the triangles' screen-space uv derivatives (no GL here).

A pixel's footprint in a texture is the parallelogram spanned by the uv derivatives along x
and y, in texels; its axes are the singular values ``p_max >= p_min`` of that 2x2 Jacobian.
Isotropic trilinear filtering picks the mip level of ``p_max`` and so blurs the image along
the minor axis by ``p_max / p_min``; anisotropic filtering with N probes (EXT_texture_filter_
anisotropic, OpenGL 4.6 section 8.14.1) takes the level of ``p_max / N`` instead. It changes the
picture only where the texture is minified (``p_max > 1``) and seen at a slant (``p_max / p_min
> 1``). ``anisotropy_for_view`` returns the largest power of two N (1 to 8) such that over half
the minified area isotropic filtering blurs at least N-fold along the minor axis, i.e. picks a
mip level at least log2(N) too coarse: 1 for a mesh seen face-on, magnified or mostly at mild
slants (under one mip level of blur, where the pictures differ by a fraction of a level), 8 for
a textured floor seen at a grazing angle. Before, every texture had 8, which on llvmpipe costs
a frame of DamagedHelmet 2-5x (docs/speed_notes.md; llvmpipe draws any level above 1 alike).
"""

from __future__ import annotations

import numpy as np

MAX_ANISOTROPY = 8.0
# At most this many triangles (evenly strided) are measured per part: the statistic is an
# area-weighted percentile, which a sample of this size pins down well, and the cost stays
# a few milliseconds on a multi-million-triangle part.
SAMPLE_TRIANGLES = 20000
# The share of the minified screen area whose ratio the chosen level must not exceed (the median).
COVERED_SHARE = 0.5
# Where less than this share of a part's screen area is minified, no level is worth its cost.
MIN_MINIFIED_SHARE = 0.02


def footprints(positions: np.ndarray, uvs: np.ndarray, indices: np.ndarray, view_projection: np.ndarray,
               image_size: tuple[int, int], texture_size: tuple[int, int],
               sample: int = SAMPLE_TRIANGLES) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per measured triangle facing the camera in front of it: (screen area in pixels,
    ``p_max``, ``p_min`` in texels per pixel), each (K,) float64.

    ``positions`` (N, 3) world space, ``uvs`` (N, 2), ``indices`` (M, 3); ``view_projection``
    (4, 4) as alight's cameras give it (row vectors: clip = [p, 1] @ VP); ``image_size`` (W, H)
    pixels; ``texture_size`` (W, H) texels of the finest texture the part reads."""
    faces = np.asarray(indices).reshape(-1, 3)
    if len(faces) > sample:
        faces = faces[:: int(np.ceil(len(faces) / sample))]
    faces = faces.astype(np.int64)
    p = np.asarray(positions, np.float64)[faces]                       # (K, 3, 3)
    clip = np.concatenate([p, np.ones(p.shape[:2] + (1,))], axis=2) @ np.asarray(view_projection, np.float64)
    w = clip[..., 3]
    front = (w > 1e-9).all(axis=1)
    clip, faces = clip[front], faces[front]
    screen = clip[..., :2] / clip[..., 3:4] * 0.5 * np.asarray(image_size, np.float64)   # pixels, centred
    uv = np.asarray(uvs, np.float64)[faces] * np.asarray(texture_size, np.float64)      # texels
    ds = np.stack([screen[:, 1] - screen[:, 0], screen[:, 2] - screen[:, 0]], axis=2)   # (K, 2, 2) columns
    du = np.stack([uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]], axis=2)
    det = ds[:, 0, 0] * ds[:, 1, 1] - ds[:, 0, 1] * ds[:, 1, 0]
    area = 0.5 * np.abs(det)
    ok = area > 1e-12
    ds, du, det, area = ds[ok], du[ok], det[ok], area[ok]
    inverse = np.stack([np.stack([ds[:, 1, 1], -ds[:, 0, 1]], 1), np.stack([-ds[:, 1, 0], ds[:, 0, 0]], 1)], 1)
    jacobian = du @ (inverse / det[:, None, None])                      # texels per pixel
    sv = np.linalg.svd(jacobian, compute_uv=False)
    return area, sv[:, 0], sv[:, 1]


def anisotropy_for_view(area: np.ndarray, p_max: np.ndarray, p_min: np.ndarray,
                        max_anisotropy: float = MAX_ANISOTROPY) -> float:
    """The anisotropy level (1, 2, 4 or 8) a view's footprints (``footprints``) gain from: the
    area-weighted COVERED_SHARE quantile of ``p_max / p_min`` over the minified triangles,
    rounded down to a power of two; 1 where under MIN_MINIFIED_SHARE of the area is minified."""
    total = float(area.sum())
    minified = p_max > 1.0
    if total <= 0.0 or float(area[minified].sum()) < MIN_MINIFIED_SHARE * total:
        return 1.0
    ratio = p_max[minified] / np.maximum(p_min[minified], 1e-12)
    weights = area[minified]
    order = np.argsort(ratio)
    cumulative = np.cumsum(weights[order])
    at = min(int(np.searchsorted(cumulative, COVERED_SHARE * cumulative[-1])), len(order) - 1)
    quantile = float(ratio[order][at])
    level = 1.0
    while level * 2.0 <= quantile and level * 2.0 <= max_anisotropy:
        level *= 2.0
    return level
