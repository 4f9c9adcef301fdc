"""KHR_materials_sheen's numpy twins (shaders/common/sheen.glsl and ibl/sheen_lut.comp, same
names; exact definition: docs/layer_sheen.md).

    f_sheen = sheen_color D_Charlie(h) V_Charlie(n.v, n.l)            (F = 1)
    D_Charlie = (2 + 1/a) sin(theta_h)^(1/a) / (2 pi),  a = sheen_roughness^2
    V_Charlie = 1 / ((1 + Lambda(n.v) + Lambda(n.l)) 4 n.v n.l)
    layered   = f_sheen + base min(1 - max(sheen_color) E(n.v), 1 - max(sheen_color) E(n.l))

(Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF"; the Lambda fit and the
albedo scaling as KHR_materials_sheen gives them.) E(mu, r) is the directional albedo of
D_Charlie V_Charlie: the integral over the hemisphere of D V (n.l) dl at n.v = mu, tabulated by
``sheen_lut_table`` with a midpoint rule (the LUT ibl/sheen_lut.comp bakes the same table on
the GPU) and read with the texture's bilinear rule (``sheen_albedo``).

One guard beyond the extension: with the fitted Lambda, E exceeds 1 at grazing view for low
sheen roughness (E(0.05, 0.1) = 1.03, E(0.02, 0.07) = 2.0), where the albedo scaling would turn
negative and the sheen alone would reflect more than it receives. The lobe is divided by
max(E(n.v), 1) and the scaling uses min(E, 1), which changes nothing where E <= 1 (every n.v
above 0.1, every roughness above 0.3) and keeps the white furnace at or below 1.

The sheen roughness is floored at MIN_SHEEN_ROUGHNESS: at 0 the distribution degenerates
(1/a = inf); every implementation clamps it, and this floor is part of the definition.
"""

from __future__ import annotations

import functools
import os

import numpy as np

from alight.core.shading import MIN_N_DOT_V, PI

MIN_SHEEN_ROUGHNESS = 0.07
SHEEN_LUT_SIZE = 64      # the table's texels per axis: n.v (x) and sheen roughness (y) at texel centres
_QUADRATURE = 160        # midpoint steps per angle of l (theta in [0, pi/2), phi in [0, pi)): ibl/sheen_lut.comp's


def sheen_alpha(roughness):
    r = np.maximum(np.asarray(roughness, np.float64), MIN_SHEEN_ROUGHNESS)
    return r * r


def D_Charlie(n_dot_h, alpha):
    """The Charlie sheen distribution (Estevez and Kulla 2017): (2 + 1/a) sin^(1/a)(theta_h) / (2 pi)."""
    inv = 1.0 / np.asarray(alpha, np.float64)
    sin2 = np.maximum(1.0 - np.asarray(n_dot_h, np.float64) ** 2, 0.0)
    return (2.0 + inv) * sin2 ** (0.5 * inv) / (2.0 * PI)


def _sheen_l(x, alpha):
    """Estevez and Kulla's fit l(x) of the Charlie masking exponent (KHR_materials_sheen)."""
    t = (1.0 - alpha) ** 2
    a = 21.5473 + (25.3245 - 21.5473) * t
    b = 3.82987 + (3.32435 - 3.82987) * t
    c = 0.19823 + (0.16801 - 0.19823) * t
    d = -1.97760 + (-1.27393 + 1.97760) * t
    e = -4.32054 + (-4.85967 + 4.32054) * t
    return a / (1.0 + b * np.asarray(x, np.float64) ** c) + d * x + e


def sheen_lambda(cos_theta, alpha):
    """Lambda(cos theta) of the Charlie masking: exp(l(x)) below x = 0.5, mirrored above."""
    x = np.abs(np.asarray(cos_theta, np.float64))
    low = np.exp(_sheen_l(np.minimum(x, 0.5), alpha))
    high = np.exp(2.0 * _sheen_l(0.5, alpha) - _sheen_l(np.maximum(1.0 - x, 0.0), alpha))
    return np.where(x < 0.5, low, high)


def V_Charlie(n_dot_v, n_dot_l, alpha):
    """The Charlie visibility 1 / ((1 + Lambda(n.v) + Lambda(n.l)) 4 n.v n.l)."""
    nv = np.asarray(n_dot_v, np.float64)
    nl = np.asarray(n_dot_l, np.float64)
    return 1.0 / ((1.0 + sheen_lambda(nv, alpha) + sheen_lambda(nl, alpha)) * (4.0 * nv * nl))


def sheen_lobe(n_dot_l, n_dot_v, n_dot_h, roughness):
    """D V (n.l) of the sheen for unit sheen colour; 0 where n.l <= 0. n.v clamped to MIN_N_DOT_V."""
    nl = np.asarray(n_dot_l, np.float64)
    nv = np.maximum(np.asarray(n_dot_v, np.float64), MIN_N_DOT_V)
    alpha = sheen_alpha(roughness)
    lit = nl > 0.0
    nl_s = np.where(lit, nl, 1.0)
    out = D_Charlie(np.clip(n_dot_h, 0.0, 1.0), alpha) * V_Charlie(nv, nl_s, alpha) * nl_s
    return np.where(lit, out, 0.0)


def _cbar_prefilter(rho, steps: int = 256):
    """The mean cosine about its centre d of the prefilter's kernel at roughness rho (the lecture's
    prefilter with n = v = d: weight D(h) max(d.l, 0) over l, D's n.h^2 = (1 + d.l)/2), by a
    midpoint rule in c = d.l. ``rho`` broadcasts."""
    rho = np.asarray(rho, np.float64)[..., None]
    c = (np.arange(steps) + 0.5) / steps
    w = c / (0.5 * (1.0 + c) * (rho ** 4 - 1.0) + 1.0) ** 2
    return np.sum(c * w, axis=-1) / np.sum(w, axis=-1)


def prefilter_roughness_for(cbar, iterations: int = 24):
    """The prefilter roughness whose kernel has mean cosine ``cbar`` (bisection in [0.05, 1]);
    1 where the lobe is broader than the broadest kernel (cbar <= 2/3). Broadcasts."""
    cbar = np.asarray(cbar, np.float64)
    lo, hi = np.full(cbar.shape, 0.05), np.ones(cbar.shape)
    for _ in range(iterations):   # the mean cosine falls as the roughness grows
        mid = 0.5 * (lo + hi)
        above = _cbar_prefilter(mid) > cbar
        lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
    return 0.5 * (lo + hi)


def lobe_moments(n_dot_v, roughness, steps: int = _QUADRATURE):
    """E and the mean direction of the sheen lobe D V (n.l) for n = +z, v = (sqrt(1 - mu^2), 0, mu),
    by a midpoint rule in (theta_l, phi_l) over the hemisphere (phi in [0, pi), doubled by the
    lobe's symmetry about the xz plane). ``n_dot_v`` (M,) or a scalar; returns (E, m_x, m_z),
    m the integral of l times the lobe (its y part is 0), each of n_dot_v's shape."""
    mu = np.maximum(np.asarray(n_dot_v, np.float64), MIN_N_DOT_V)
    shape = mu.shape
    mu = mu.reshape(-1, 1, 1)
    th = (np.arange(steps) + 0.5) * (0.5 * PI / steps)
    ph = (np.arange(steps) + 0.5) * (PI / steps)
    st, ct = np.sin(th)[:, None], np.cos(th)[:, None]
    lx, ly = st * np.cos(ph)[None, :], st * np.sin(ph)[None, :]
    lz = np.broadcast_to(ct, (steps, steps))
    vx, vz = np.sqrt(1.0 - mu * mu), mu
    hx, hz = lx + vx, lz + vz
    nh = hz / np.sqrt(hx * hx + ly * ly + hz * hz)
    w = st * (0.5 * PI / steps) * (PI / steps) * 2.0
    f = sheen_lobe(lz, mu, nh, roughness) * w
    return (np.sum(f, axis=(1, 2)).reshape(shape), np.sum(f * lx, axis=(1, 2)).reshape(shape),
            np.sum(f * lz, axis=(1, 2)).reshape(shape))


def directional_albedo(n_dot_v, roughness, steps: int = _QUADRATURE):
    """E(mu, r): the integral over the hemisphere of D V (n.l) dl (``lobe_moments``)."""
    return lobe_moments(n_dot_v, roughness, steps)[0]


def lut_row(n_dot_v, roughness) -> np.ndarray:
    """Texels of the sheen LUT (ibl/sheen_lut.comp) at n.v values (M,) and one roughness:
    (M, 4) = (E, sin phi, rho, 0), E the directional albedo, phi the angle of the lobe's mean
    direction from n toward v's side (negative: toward the mirror direction), rho the prefilter
    roughness whose kernel has the lobe's mean cosine about that direction (image-based light)."""
    e, mx, mz = lobe_moments(n_dot_v, roughness)
    length = np.hypot(mx, mz)
    ok = (e > 0.0) & (length > 0.0)
    sin_phi = np.where(ok, mx / np.where(ok, length, 1.0), 0.0)
    rho = np.where(ok, prefilter_roughness_for(np.where(ok, length / np.where(ok, e, 1.0), 1.0)), 1.0)
    return np.stack([np.maximum(e, 0.0), sin_phi, rho, np.zeros_like(e)], axis=-1)


# Changes whenever the table's definition does, so a cached table is never stale.
_TABLE_VERSION = f"1-{_QUADRATURE}-{MIN_SHEEN_ROUGHNESS}"


@functools.lru_cache(maxsize=2)
def sheen_lut_table(size: int = SHEEN_LUT_SIZE) -> np.ndarray:
    """The sheen LUT at its texel centres: (size, size, 4) float64, [row = sheen roughness j,
    column = n.v i] at ((i + 0.5)/size, (j + 0.5)/size), as ibl/sheen_lut.comp stores it.

    About a minute of numpy on 2 cores, so it is kept in alight's cache folder
    (``alight.paths.cache_dir``) once computed."""
    from alight.paths import cache_dir

    path = cache_dir() / f"sheen_lut_numpy-{size}-{_TABLE_VERSION}.npy"
    try:
        table = np.load(path, allow_pickle=False)
        if table.shape == (size, size, 4) and np.isfinite(table).all():
            return table
    except (OSError, ValueError):
        pass
    c = (np.arange(size) + 0.5) / size
    table = np.stack([lut_row(c, r) for r in c])
    try:   # written to a temporary name and renamed: a reader never sees half a table
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        with open(tmp, "wb") as f:
            np.save(f, table)
        os.replace(tmp, path)
    except OSError:
        pass   # an unwritable cache only costs the minute again
    return table


def sheen_albedo_table(size: int = SHEEN_LUT_SIZE) -> np.ndarray:
    """E alone (the LUT's first channel): (size, size)."""
    return sheen_lut_table(size)[..., 0]


def lut_bilinear(table: np.ndarray, n_dot_v, roughness) -> np.ndarray:
    """A (size, size, C) table read as a texture's bilinear filter reads it at (n.v, r), clamped
    to the edge texel centres: (..., C)."""
    size = table.shape[0]
    x = np.clip(np.asarray(n_dot_v, np.float64) * size - 0.5, 0.0, size - 1.0)
    y = np.clip(np.asarray(roughness, np.float64) * size - 0.5, 0.0, size - 1.0)
    x0 = np.minimum(np.floor(x).astype(int), size - 2)
    y0 = np.minimum(np.floor(y).astype(int), size - 2)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    top = table[y0, x0] * (1 - fx) + table[y0, x0 + 1] * fx
    bottom = table[y0 + 1, x0] * (1 - fx) + table[y0 + 1, x0 + 1] * fx
    return top * (1 - fy) + bottom * fy


def sheen_albedo(n_dot_v, roughness, table: np.ndarray | None = None):
    """E(n.v, r) read from the LUT (``lut_bilinear``), so the ground truth and the shaders see the
    same numbers."""
    t = sheen_lut_table() if table is None else table
    return lut_bilinear(t[..., :1] if t.ndim == 3 else t[..., None], n_dot_v, roughness)[..., 0]


def sheen_scaling(sheen_color, e):
    """1 - max(sheen_color) min(E, 1): the albedo scaling of the layers below (E is capped at 1,
    see the module docstring)."""
    return 1.0 - max(float(c) for c in sheen_color) * np.minimum(np.asarray(e, np.float64), 1.0)


def sheen_base_weight(m, p) -> np.ndarray:
    """min(1 - max(sheen_color) E(n.v), 1 - max(sheen_color) E(|n.l|)) for each pair: (P, T)."""
    ev = sheen_albedo(np.clip(p.n_dot_v, 0.0, 1.0), m.sheen_roughness)
    el = sheen_albedo(np.clip(np.abs(p.n_dot_l), 0.0, 1.0), m.sheen_roughness)
    return np.minimum(sheen_scaling(m.sheen_color, ev), sheen_scaling(m.sheen_color, el))


def sheen_light(m, p) -> np.ndarray:
    """The sheen BRDF times n.l: (P, T, 3), the lobe divided by max(E(n.v), 1)."""
    lobe = sheen_lobe(p.n_dot_l, p.n_dot_v, p.n_dot_h, m.sheen_roughness)
    norm = np.maximum(sheen_albedo(np.clip(p.n_dot_v, 0.0, 1.0), m.sheen_roughness), 1.0)
    return (lobe / norm)[..., None] * np.asarray(m.sheen_color, np.float64)
