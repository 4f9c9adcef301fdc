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
a frame of DamagedHelmet 2-5x (docs/performance-assets.md; llvmpipe draws any level above 1 alike).
"""

from __future__ import annotations

import numpy as np

MAX_ANISOTROPY = 8.0
# At most this many triangles (evenly strided) are measured per part: the statistic is an
# area-weighted median, which a sample of this size pins down well, and the cost stays a few
# milliseconds per view at any triangle count (the editor asks again at every orbit step).
SAMPLE_TRIANGLES = 4096
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
    p = np.asarray(positions, np.float64)[faces].reshape(-1, 3)        # (3K, 3): corners
    m = np.asarray(view_projection, np.float64)
    # clip = [p, 1] @ VP written out per column: a batched matmul goes to a threaded BLAS,
    # which was the slow part on a loaded 2-core machine (alight.core.mesh.rows_times).
    clip = (p[:, 0:1] * m[0] + p[:, 1:2] * m[1] + p[:, 2:3] * m[2] + m[3]).reshape(-1, 3, 4)
    w = clip[..., 3]
    front = (w > 1e-9).all(axis=1)
    clip, faces = clip[front], faces[front]
    screen = clip[..., :2] / clip[..., 3:4] * 0.5 * np.asarray(image_size, np.float64)   # pixels, centred
    uv = np.asarray(uvs, np.float64)[faces] * np.asarray(texture_size, np.float64)      # texels
    # Edge vectors in pixels (x1, y1), (x2, y2) and in texels (u1, v1), (u2, v2).
    x1, y1 = screen[:, 1, 0] - screen[:, 0, 0], screen[:, 1, 1] - screen[:, 0, 1]
    x2, y2 = screen[:, 2, 0] - screen[:, 0, 0], screen[:, 2, 1] - screen[:, 0, 1]
    u1, v1 = uv[:, 1, 0] - uv[:, 0, 0], uv[:, 1, 1] - uv[:, 0, 1]
    u2, v2 = uv[:, 2, 0] - uv[:, 0, 0], uv[:, 2, 1] - uv[:, 0, 1]
    det = x1 * y2 - x2 * y1
    area = 0.5 * np.abs(det)
    ok = area > 1e-12
    det = np.where(ok, det, 1.0)
    # The Jacobian d(u, v) / d(x, y) = [[u1 u2], [v1 v2]] [[x1 x2], [y1 y2]]^-1.
    a, b = (u1 * y2 - u2 * y1) / det, (u2 * x1 - u1 * x2) / det
    c, d = (v1 * y2 - v2 * y1) / det, (v2 * x1 - v1 * x2) / det
    # A 2x2 matrix's singular values in closed form: s^2 = (S +- sqrt(S^2 - 4 D^2)) / 2 with
    # S the sum of squared entries and D the determinant.
    squares = a * a + b * b + c * c + d * d
    root = np.sqrt(np.maximum(squares * squares - 4.0 * (a * d - b * c) ** 2, 0.0))
    p_max = np.sqrt((squares + root) / 2.0)
    p_min = np.abs(a * d - b * c) / np.maximum(p_max, 1e-300)   # |D| / s_max: no cancellation
    return area[ok], p_max[ok], p_min[ok]


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
