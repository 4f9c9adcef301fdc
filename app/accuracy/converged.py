"""The converged split sum: what the GPU bake's sampling loops tend to with infinite samples.

These numpy references sum exactly over the texels of an equirect map (docs/conventions.md's
mapping and solid angles, via ``alight.core.shading.texel_directions``) instead of sampling, and they
integrate the BRDF LUT by a deterministic quadrature instead of Hammersley points. Tests and
the accuracy tools compare the GPU's baked irradiance map, prefiltered mip chain and BRDF LUT
with them, and ``split_sum_converged`` assembles the lecture's ambient term from them.

Cost: the texel sums are chunked over the query directions (P x T matmuls in float32, T the
number of texels), so memory stays near ``_CHUNK_ELEMS`` * 4 bytes * 2 whatever P is.
Measured for P = 4000 at 1024x512 on 2 cores: irradiance_converged 2.9 s,
prefiltered_converged 4.7 s, split_sum_converged 11.6 s (its BRDF LUT quadrature is ~0.6 ms
per (n.v, r) pair), peak RSS 0.5 GB. Tests use ``downsample_equirect`` to shrink maps first.
"""

from __future__ import annotations

import numpy as np

from alight.core.equirect import box_reduce
from alight.core.shading import (
    PI,
    F_Schlick,
    F_SchlickRoughness,
    G_Smith,
    direction_to_equirect_uv,
    f0_of,
    k_ibl,
    reflect,
    texel_directions,
)

# Directions x texels per chunk (float32): 2**25 elements = 128 MiB per temporary.
_CHUNK_ELEMS = 1 << 25

# Below this roughness prefiltered_converged is the bilinear lookup of L(d) (see its docstring).
MIN_PREFILTER_ROUGHNESS = 0.05


def _texels(radiance):
    """Flattened texel directions (T, 3) float32, radiance (T, 3) float64 and solid angles (T,)."""
    rad = np.asarray(radiance)
    if rad.ndim != 3 or rad.shape[2] != 3 or rad.shape[1] != 2 * rad.shape[0]:
        raise ValueError(f"expected an (H, 2H, 3) equirect radiance array, got {rad.shape}")
    h, w = rad.shape[:2]
    dirs, omega = texel_directions(h, w)
    return (np.ascontiguousarray(dirs.reshape(-1, 3), dtype=np.float32),
            rad.reshape(-1, 3).astype(np.float64),
            np.ascontiguousarray(omega).reshape(-1).astype(np.float64))


def _unit_rows(d):
    d = np.asarray(d, dtype=np.float64)
    if d.ndim == 1:
        d = d[None, :]
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _chunks(p, t):
    step = max(1, _CHUNK_ELEMS // max(t, 1))
    for i in range(0, p, step):
        yield slice(i, min(p, i + step))


def irradiance_converged(radiance, normals) -> np.ndarray:
    """E(n)/pi = (1/pi) sum_t L_t max(n.l_t, 0) dOmega_t for each normal: (P, 3) float64.

    The white furnace (L == 1) gives 1.0 up to the discretisation of the texel sum (~1e-5 at
    256x128).
    """
    dirs, rad, omega = _texels(radiance)
    n = _unit_rows(normals).astype(np.float32)
    lw = (rad * omega[:, None] / PI).astype(np.float32)  # (T, 3)
    out = np.empty((n.shape[0], 3), dtype=np.float64)
    for sl in _chunks(n.shape[0], dirs.shape[0]):
        c = n[sl] @ dirs.T  # (p, T) cosines
        np.maximum(c, 0.0, out=c)
        out[sl] = c @ lw
    return out


def prefiltered_converged(radiance, directions, roughness) -> np.ndarray:
    """The converged value of the lecture's prefilter loop (N = V = R = d) for each d: (P, 3).

    The loop draws half vectors h with pdf D(h)(n.h), reflects l = 2(v.h)h - v and averages
    L(l) with weight n.l over the samples with n.l > 0. With v = n, dh = dl / (4 v.h) and
    v.h = n.h, so the pdf over l is D(h)/4 and the loop converges to the ratio

        sum_t L_t max(d.l_t, 0) D(h_t) dOmega_t  /  sum_t max(d.l_t, 0) D(h_t) dOmega_t,

    h_t = normalize(l_t + d); since n.h = sqrt((1 + d.l)/2), D depends only on c = d.l
    (computed by matmul), and D's constant a^2/pi cancels.

    ``roughness`` is one scalar. Below ``MIN_PREFILTER_ROUGHNESS`` (0.05) the kernel (width
    about alpha = r^2 radians) is far narrower than a texel and the texel sum degenerates, so
    the function FALLS BACK to the bilinear lookup of L(d) (the r -> 0 limit, what mip 0
    holds). Just above 0.05 the kernel still spans only a few texels of a 1k map; trust the
    texel sum from about r = 0.15 up at 1024x512 (r = 0.25 at 512x256).
    """
    r = float(roughness)
    if not np.isfinite(r) or r < 0.0 or r > 1.0:
        raise ValueError(f"roughness must be in [0, 1], got {roughness!r}")
    d = _unit_rows(directions)
    if r < MIN_PREFILTER_ROUGHNESS:
        return sample_equirect_bilinear(radiance, d)
    dirs, rad, omega = _texels(radiance)
    a2m1 = r ** 4 - 1.0
    # 1 / ((n.h)^2 (a^2 - 1) + 1)^2 with (n.h)^2 = (1 + c)/2:  denominator = c*s + o
    s_ = np.float32(0.5 * a2m1)
    o_ = np.float32(0.5 * a2m1 + 1.0)
    lw = np.concatenate([rad * omega[:, None], omega[:, None]], axis=1).astype(np.float32)  # (T, 4)
    d32 = d.astype(np.float32)
    out = np.empty((d.shape[0], 3), dtype=np.float64)
    for sl in _chunks(d.shape[0], dirs.shape[0]):
        c = d32[sl] @ dirs.T  # (p, T)
        den = c * s_
        den += o_
        np.square(den, out=den)
        np.maximum(c, 0.0, out=c)
        np.divide(c, den, out=c)  # weight max(c,0) * D / (a^2/pi)
        acc = (c @ lw).astype(np.float64)  # (p, 4): weighted radiance, weight sum
        out[sl] = acc[:, :3] / acc[:, 3:4]
    return out


def prefiltered_converged_each(radiance, directions, roughness) -> np.ndarray:
    """``prefiltered_converged`` with a roughness per direction (P,): the directions grouped by
    roughness rounded to 1e-4 (the kernel changes by < 1e-4 relative within a group)."""
    d = _unit_rows(directions)
    rough = np.round(np.broadcast_to(np.asarray(roughness, np.float64), d.shape[:1]), 4)
    out = np.empty((d.shape[0], 3))
    for value in np.unique(rough):
        sel = rough == value
        out[sel] = prefiltered_converged(radiance, d[sel], float(min(value, 1.0)))
    return out


def sample_equirect_bilinear(radiance, directions) -> np.ndarray:
    """Bilinear lookup of an equirect map in unit directions (P, 3) -> (P, 3) float64.

    Texel centres at ((i + 0.5)/W, (j + 0.5)/H); u wraps around, v is clamped at the poles.
    """
    rad = np.asarray(radiance)
    h, w = rad.shape[:2]
    uv = direction_to_equirect_uv(_unit_rows(directions))
    x = uv[:, 0] * w - 0.5
    y = np.clip(uv[:, 1] * h - 0.5, 0.0, h - 1.0)
    x0 = np.floor(x)
    y0 = np.minimum(np.floor(y), h - 2) if h > 1 else np.zeros_like(y)
    fx = (x - x0)[:, None]
    fy = (y - y0)[:, None]
    x0 = x0.astype(np.int64) % w
    x1 = (x0 + 1) % w
    y0 = y0.astype(np.int64)
    y1 = np.minimum(y0 + 1, h - 1)
    r = rad.astype(np.float64, copy=False)
    top = r[y0, x0] * (1 - fx) + r[y0, x1] * fx
    bot = r[y1, x0] * (1 - fx) + r[y1, x1] * fx
    return top * (1 - fy) + bot * fy


def _lut_quadrature(n_dot_v, roughness, n_u: int, n_phi: int):
    """The LUT twins' shared set-up: the broadcast shape, flat n.v (>= 1e-4) and roughness, and
    the midpoint grid over the GGX inverse CDF's u (weights wu summing to 1) and phi in [0, pi)."""
    nv, r = np.broadcast_arrays(np.asarray(n_dot_v, dtype=np.float64), np.asarray(roughness, dtype=np.float64))
    shape = nv.shape
    nv = np.clip(nv.reshape(-1), 1e-4, 1.0)
    r = np.clip(r.reshape(-1), 0.0, 1.0)
    # u = 1 - (1 - s)^2 with a midpoint grid in s: near u = 1 (grazing h, where
    # 1 - u ~ cos^2(theta_h)) cos(theta_h) becomes linear in s instead of a square root.
    sg = (np.arange(n_u) + 0.5) / n_u
    u = 1.0 - (1.0 - sg) ** 2
    wu = 2.0 * (1.0 - sg) / n_u  # du, sums to 1
    phi = (np.arange(n_phi) + 0.5) * (PI / n_phi)
    return shape, nv, r, u, wu, phi


def brdf_lut_converged(n_dot_v, roughness, n_u: int = 512, n_phi: int = 128):
    """The lecture's integrate_brdf (k = r^2/2), integrated by a deterministic midpoint rule.

    A = E[(1 - Fc) G_vis], B = E[Fc G_vis] over h with pdf D(h)(n.h), N = z,
    V = (sqrt(1 - nv^2), 0, nv), L = reflect(-V, H), only n.l > 0 (else 0),
    G_vis = G_Smith(n.v, n.l, k_ibl(r)) (v.h) / ((n.h)(n.v)), Fc = (1 - v.h)^5.

    The expectation is a midpoint grid over (u, phi): u in [0, 1) maps to cos(theta_h) by the
    GGX inverse CDF cos = sqrt((1 - u)/(1 + (a^2 - 1) u)), and phi covers [0, pi) only (the
    integrand is even in phi because V lies in the xz plane). Accurate to ~1e-5 with the
    default grid (the tests double it). ``n_dot_v`` and ``roughness`` broadcast; returns
    (A, B) of their broadcast shape, float64. n.v is clamped to >= 1e-4; at r = 0 (a = 0, all
    h = n) the integral is A = 1 - Fc(nv), B = Fc(nv) and the code gives exactly that.
    """
    shape, nv, r, u, wu, phi = _lut_quadrature(n_dot_v, roughness, n_u, n_phi)
    cphi = np.cos(phi)
    A = np.empty(nv.shape[0])
    B = np.empty(nv.shape[0])
    for i in range(nv.shape[0]):  # one (nv, r) pair at a time: a (n_u, n_phi) grid each
        a2 = r[i] ** 4
        cos_t = np.sqrt((1.0 - u) / (1.0 + (a2 - 1.0) * u))  # (n_u,)
        sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
        vx, vz = np.sqrt(1.0 - nv[i] * nv[i]), nv[i]
        # h = (cos phi sin t, sin phi sin t, cos t); v.h = vx hx + vz hz
        vh = vx * sin_t[:, None] * cphi[None, :] + vz * cos_t[:, None]  # (n_u, n_phi)
        nh = cos_t[:, None]
        nl = 2.0 * vh * nh - vz  # L = 2 (v.h) h - v
        ok = nl > 0.0
        nl_s = np.where(ok, nl, 1.0)
        vh_c = np.clip(vh, 0.0, 1.0)
        g = G_Smith(vz, nl_s, k_ibl(r[i]))
        g_vis = np.where(ok, g * vh_c / (nh * vz), 0.0)
        fc = (1.0 - vh_c) ** 5
        A[i] = wu @ np.mean((1.0 - fc) * g_vis, axis=1)
        B[i] = wu @ np.mean(fc * g_vis, axis=1)
    return A.reshape(shape), B.reshape(shape)


def lobe_directions_converged(n_dot_v, roughness, n_u: int = 512, n_phi: int = 128):
    """Numpy twin of brdf_lut.comp's t_A and t_B: where the specular lobe points.

    The lobe f (n.l) over l, split like A and B into its (1 - Fc) and Fc parts, has a mean
    vector m (the integral of the lobe times l); t is the lerp factor with
    normalize(mix(n, R, t)) on m's angle from n toward R: tan(phi) = t sin / (1 - t + t cos),
    clamped to [0, 1], and 1 at n.v = 1 (R = n). Same midpoint grid and guards as
    ``brdf_lut_converged``. Returns (t_A, t_B) of the broadcast shape.
    """
    shape, nv, r, u, wu, phi = _lut_quadrature(n_dot_v, roughness, n_u, n_phi)
    cphi = np.cos(phi)
    out = np.empty((2, nv.shape[0]))
    for i in range(nv.shape[0]):
        a2 = r[i] ** 4
        cos_t = np.sqrt((1.0 - u) / (1.0 + (a2 - 1.0) * u))
        sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
        vx, vz = np.sqrt(1.0 - nv[i] * nv[i]), nv[i]
        hx = sin_t[:, None] * cphi[None, :]
        hz = np.broadcast_to(cos_t[:, None], hx.shape)
        vh = vx * hx + vz * hz
        lx = 2.0 * vh * hx - vx   # l = 2 (v.h) h - v; its y part averages out over phi
        nl = 2.0 * vh * hz - vz
        ok = nl > 0.0
        nl_s = np.where(ok, nl, 1.0)
        vh_c = np.clip(vh, 0.0, 1.0)
        g = G_Smith(vz, nl_s, k_ibl(r[i]))
        g_vis = np.where(ok, g * vh_c / (hz * vz), 0.0) * wu[:, None]
        fc = (1.0 - vh_c) ** 5
        sin_v = np.sqrt(max(1.0 - vz * vz, 0.0))
        for j, w in enumerate(((1.0 - fc) * g_vis, fc * g_vis)):
            toward_r = float(np.sum(w * -lx))
            along_n = float(np.sum(w * np.where(ok, nl, 0.0)))
            if sin_v < 1e-4 or along_n <= 0.0:
                out[j, i] = 1.0
                continue
            tan_phi = max(toward_r, 0.0) / along_n
            out[j, i] = np.clip(tan_phi / (sin_v + tan_phi * (1.0 - vz)), 0.0, 1.0)
    return out[0].reshape(shape), out[1].reshape(shape)


def anisotropy_lut_converged(n_dot_v, roughness, strength, azimuth, n_u: int = 256, n_phi: int = 256):
    """Numpy twin of ibl/anisotropy_lut.comp at one view: the stretched lobe's (A, B) over the
    round lobe's, (ratio_A, ratio_B), by a midpoint rule over the slope distribution's inverse
    CDF (u, phi) instead of Hammersley points. ``azimuth``: the view's angle (radians) from the
    stretch direction in the tangent plane. Scalars in, floats out.
    """
    from alight.core.layers.anisotropy import anisotropic_alpha, projected_alpha

    nv = float(np.clip(n_dot_v, 1e-4, 1.0))
    sg = (np.arange(n_u) + 0.5) / n_u
    u = 1.0 - (1.0 - sg) ** 2          # dense near u = 1 (grazing h), as _lut_quadrature
    wu = 2.0 * (1.0 - sg) / n_u
    phi = (np.arange(n_phi) + 0.5) * (2.0 * PI / n_phi)
    sin_v = np.sqrt(1.0 - nv * nv)
    v = np.array([sin_v * np.cos(azimuth), sin_v * np.sin(azimuth), nv])

    def energy(alpha_t, alpha_b):
        radius = np.sqrt(u / (1.0 - u))[:, None]
        h = np.stack(np.broadcast_arrays(radius * alpha_t * np.cos(phi)[None, :],
                                         radius * alpha_b * np.sin(phi)[None, :], np.ones((n_u, n_phi))), -1)
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        vh = h @ v
        l = 2.0 * vh[..., None] * h - v
        ok = (l[..., 2] > 0.0) & (vh > 0.0)
        kv = projected_alpha(v[0], v[1], alpha_t, alpha_b) / 2.0
        kl = projected_alpha(l[..., 0], l[..., 1], alpha_t, alpha_b) / 2.0
        nl = np.where(ok, l[..., 2], 1.0)
        g = (nv / (nv * (1.0 - kv) + kv)) * (nl / (nl * (1.0 - kl) + kl))
        g_vis = np.where(ok, g * np.clip(vh, 0.0, 1.0) / (h[..., 2] * nv), 0.0)
        fc = (1.0 - np.clip(vh, 0.0, 1.0)) ** 5
        return wu @ np.mean((1.0 - fc) * g_vis, axis=1), wu @ np.mean(fc * g_vis, axis=1)

    at, ab = anisotropic_alpha(float(roughness), float(strength))
    sa, sb = energy(float(at), float(ab))
    ra, rb = energy(float(ab), float(ab))
    return (sa / ra if ra > 0.0 else 1.0), (sb / rb if rb > 0.0 else 1.0)


def anisotropic_prefiltered_converged(radiance, normals, view, tangents, f0, roughness, strength,
                                      fetches: int = 8) -> np.ndarray:
    """Numpy twin of anisotropy.glsl's anisotropic_prefiltered_radiance with converged parts: the
    ``fetches`` round lookups (``prefiltered_converged`` at the material's roughness) along the
    stretch, each drawn toward its lobe's mean (the LUT's t_A, t_B by quadrature) and weighted
    by G1(n.l) v.h / n.h. ``tangents``: the stretch direction at each point (P, 3), already
    rotated; (P, 3) float64.
    """
    from alight.core.layers.anisotropy import fetch_normals, fetch_weights

    n = _unit_rows(normals)
    v = np.broadcast_to(_unit_rows(view), n.shape)
    t = _unit_rows(tangents)
    b = np.cross(n, t)
    r = float(roughness)
    h = fetch_normals(n, t, r, strength, fetches)                                # (P, K, 3)
    vh = np.clip(np.sum(v[:, None, :] * h, -1), 0.0, 1.0)
    l = 2.0 * np.sum(v[:, None, :] * h, -1)[..., None] * h - v[:, None, :]
    # The LUT's (A, B, t_A, t_B) at (v.h, r), from quadratures on a fine n.v grid.
    grid = np.linspace(0.0, 1.0, 129)
    A, B = brdf_lut_converged(grid, np.full_like(grid, r), 256, 64)
    ta, tb = lobe_directions_converged(grid, np.full_like(grid, r), 256, 64)
    a_k, b_k, ta_k, tb_k = (np.interp(vh, grid, x) for x in (A, B, ta, tb))
    weight_a = float(np.dot(np.asarray(f0, np.float64), (0.2126, 0.7152, 0.0722))) * a_k
    mix_t = (weight_a * ta_k + b_k * tb_k) / np.maximum(weight_a + b_k, 1e-6)
    dk = h + mix_t[..., None] * (l - h)
    dk /= np.linalg.norm(dk, axis=-1, keepdims=True)
    w = fetch_weights(n, dk, h, v, t, b, r, strength)                           # (P, K)
    values = prefiltered_converged(radiance, dk.reshape(-1, 3), r).reshape(dk.shape)
    total = np.sum(w, axis=1, keepdims=True)
    return np.sum(w[..., None] * values, axis=1) / np.maximum(total, 1e-30)


# ibl.glsl's diffuse_fresnel: a quartic in 1 - n.v fitted to diffuse_fresnel_converged.
DIFFUSE_FRESNEL_COEFFS = (8.233601e-05, 0.002021979, 0.009310647, 0.007795988, 0.0089526)


def diffuse_fresnel(n_dot_v):
    """Numpy twin of ibl.glsl's diffuse_fresnel (the fit)."""
    x = 1.0 - np.asarray(n_dot_v, dtype=np.float64)
    return np.polynomial.polynomial.polyval(x, DIFFUSE_FRESNEL_COEFFS)


def diffuse_fresnel_converged(n_dot_v, n_theta: int = 600, n_phi: int = 600):
    """(1/pi) * integral over the hemisphere of (1 - v.h)^5 (n.l) dl, by a midpoint rule in
    (theta_l, phi_l): the Fresnel part of the Lambert lobe under uniform light. Independent of
    the roughness, since h = normalize(l + v)."""
    nv = np.atleast_1d(np.asarray(n_dot_v, dtype=np.float64))
    th = (np.arange(n_theta) + 0.5) * (0.5 * PI / n_theta)
    ph = (np.arange(n_phi) + 0.5) * (2.0 * PI / n_phi)
    st, ct = np.sin(th)[:, None], np.cos(th)[:, None]
    lx, ly, lz = st * np.cos(ph)[None, :], st * np.sin(ph)[None, :], np.broadcast_to(ct, (n_theta, n_phi))
    w = st * (0.5 * PI / n_theta) * (2.0 * PI / n_phi)
    out = np.empty(nv.shape[0])
    for i, c in enumerate(np.clip(nv, 1e-4, 1.0)):
        vx, vz = np.sqrt(1.0 - c * c), c
        # v.h = (1 + l.v) / |l + v| = sqrt((1 + l.v) / 2)
        vh = np.sqrt(np.maximum(0.5 * (1.0 + lx * vx + lz * vz), 0.0))
        out[i] = float(np.sum((1.0 - vh) ** 5 * lz * w)) / PI
    del ly
    return out.reshape(np.shape(n_dot_v))


def split_sum_converged(radiance, normals, view, base_color, metallic, roughness, specular_f0) -> np.ndarray:
    """The lecture's ``cook_torrance_IBL`` ambient term with converged parts, (P, 3) float64.

    n.v = max(n.v, 0); F = F_SchlickRoughness(n.v, F0, r); kd = (1 - F)(1 - metallic);
    diffuse = kd base_color E(n)/pi (irradiance_converged); R = reflect(-v, n);
    specular = prefiltered_converged(R, r) (F A + B), (A, B) = brdf_lut_converged(n.v, r);
    F0 = f0_of(base_color, metallic, specular_f0). The material (base_color, metallic,
    roughness, specular_f0) is one material; ``view`` is one direction (3,) or one per normal.
    """
    return ibl_converged("lecture", radiance, normals, view, base_color, metallic, roughness, specular_f0)


def ibl_converged(model: str, radiance, normals, view, base_color, metallic, roughness, specular_f0,
                  multiple_scattering: bool = False, material=None, tangents=None,
                  diffuse_scale: float = 1.0, specular_f90: float = 1.0) -> np.ndarray:
    """What the forward pass's IBL model ``model`` (app/core/ibl_models.py) tends to with a converged
    bake: (P, 3) float64, the numpy twin of ibl.glsl's ibl_<model> (occlusion 1, no emission).

    The compact sources are taken out of ``radiance`` as the bake does (``alight.ibl.sun.extract_suns``);
    the models in SUNS_AS_BAKED see them as if filtered into the maps (the converged texel sums of
    the whole map), ``alight`` shades them as delta lights through the exact BRDF. ``lecture`` is
    ``split_sum_converged``. Roughness must be >= MIN_PREFILTER_ROUGHNESS for the non-lecture
    models (the sun's mirror image below the grid is the source cube's business, not this twin's).

    With KHR_materials_anisotropy on ``material`` (anisotropy.glsl): the LUT's A and B times the
    stretched lobe's ratios (``anisotropy_lut_converged``), the stretched lookup
    (``anisotropic_prefiltered_converged``) and the compact sources through the stretched lobe;
    ``tangents`` (P, 3) the tangent frame's t (default: the probe's).

    ``material`` (an alight.core.material.Material): its layers over the result, as
    common/layers.glsl's layered_ibl (``layered_ibl_converged``: the transmitted environment, the
    sheen, the coat; the diffuse lobe scaled by 1 - transmission), and the compact sources through
    the whole layered BRDF. Without it, ``diffuse_scale`` scales the diffuse lobe alone (the
    reflected part of a transmissive material, without what it transmits).

    ``specular_f90``: the dielectric's Fresnel at grazing incidence (KHR_materials_specular's
    specularFactor; F90 = mix(specular_f90, 1, metallic)), which scales the split sum's B and
    enters the diffuse weight as 1 - F0 - (F90 - F0) Fc (surface.glsl's surface_f90).
    """
    from alight.core.ibl_models import IBL_MODELS, SUNS_AS_BAKED
    from alight.ibl.sun import extract_suns

    if model not in IBL_MODELS:
        raise ValueError(f"unknown IBL model '{model}'")
    n = _unit_rows(normals)
    v = np.broadcast_to(_unit_rows(view), n.shape)
    r = float(roughness)
    m = float(metallic)
    base = np.asarray(base_color, dtype=np.float64)
    f0 = f0_of(base, m, np.asarray(specular_f0, dtype=np.float64))
    f90 = float(specular_f90) * (1.0 - m) + m
    nv = np.maximum(np.sum(n * v, axis=-1), 0.0)
    A, B = brdf_lut_converged(nv, r)
    A, B = A[:, None], B[:, None]
    R = reflect(-v, n)
    rad = np.asarray(radiance, dtype=np.float32)
    suns = []
    if model in SUNS_AS_BAKED:
        lighting = rad
    else:
        lighting, suns = extract_suns(rad)
    if model in ("lecture", "lecture-schlick"):
        F = F_SchlickRoughness(nv, f0, r) if model == "lecture" else f0 + (f90 - f0) * ((1.0 - nv) ** 5)[:, None]
        diffuse_weight, spec_weight, direction = 1.0 - F, F * A + f90 * B, R
    else:
        diffuse_weight = 1.0 - f0 - (f90 - f0) * diffuse_fresnel(nv)[:, None]
        spec_weight = f0 * A + f90 * B
        direction = R
        if model in ("dominant", "alight", "stretched"):
            t_a, t_b = lobe_directions_converged(nv, r)
            weight_a = float(np.dot(f0, (0.2126, 0.7152, 0.0722))) * A[:, 0]
            t = (weight_a * t_a + B[:, 0] * t_b) / np.maximum(weight_a + B[:, 0], 1e-6)
            direction = _unit_rows(n + t[:, None] * (R - n))
    irradiance = irradiance_converged(lighting, n)
    from alight.core.layers.stack import probe_tangents

    t0 = probe_tangents(n) if tangents is None else _unit_rows(tangents)
    t0 = _unit_rows(t0 - n * np.sum(n * t0, -1, keepdims=True))
    anisotropic = material is not None and "anisotropy" in material.layers()
    strength = float(material.anisotropy_strength) if anisotropic else 0.0
    if strength > 0.0:
        from alight.core.layers.anisotropy import anisotropy_direction

        t_dir, b_dir = anisotropy_direction(material, n, t0, np.cross(n, t0))
        azimuth = np.arctan2(np.abs(np.sum(b_dir * v, -1)), np.abs(np.sum(t_dir * v, -1)))
        ratios = np.array([anisotropy_lut_converged(x, r, strength, a, 128, 128) for x, a in zip(nv, azimuth)])
        A, B = A * ratios[:, :1], B * ratios[:, 1:]
        spec_weight = f0 * A + f90 * B if model not in ("lecture", "lecture-schlick") else F * A + f90 * B
        prefiltered = anisotropic_prefiltered_converged(lighting, n, v, t_dir, f0, r, strength)
    elif model == "stretched":
        from alight.core.stretched_lobe import stretched_fetches

        from alight.core.stretched_lobe import blend_weight

        d_lo, d_hi, w_hi, fetch_r = stretched_fetches(n, v, direction, f0, A[:, 0], B[:, 0], r)
        two = ((1.0 - w_hi)[:, None] * prefiltered_converged_each(lighting, d_lo, fetch_r)
               + w_hi[:, None] * prefiltered_converged_each(lighting, d_hi, fetch_r))
        share = float(blend_weight(r))
        prefiltered = two if share >= 1.0 else (1.0 - share) * prefiltered_converged(lighting, direction, r) + share * two
    else:
        prefiltered = prefiltered_converged(lighting, direction, r)
    if material is not None and "transmission" in material.layers():
        diffuse_scale = 1.0 - material.transmission
    if material is not None and "iridescence" in material.layers():   # ibl.glsl: iridescence_ibl_weights
        from alight.core.layers import iridescence as ir

        diffuse_weight, spec_weight = ir.iridescence_ibl_weights(
            ir.iridescence_fresnel_at_view(material, np.sum(n * v, axis=-1)), ir.iridescence_weight(material),
            A[:, 0], B[:, 0], diffuse_weight, spec_weight)
    albedo = base * (1.0 - m) * float(diffuse_scale)
    if multiple_scattering:
        e_ss = A + B
        e_ms = 1.0 - e_ss
        f_avg = f0 + (f90 - f0) / 21.0
        f_ms = spec_weight * f_avg / (1.0 - e_ms * f_avg)
        out = spec_weight * prefiltered + (f_ms * e_ms + albedo * (1.0 - (spec_weight + f_ms * e_ms))) * irradiance
    else:
        out = diffuse_weight * albedo * irradiance + spec_weight * prefiltered
    layered = material is not None and bool(material.layers())
    if layered:
        out = layered_ibl_converged(material, lighting, n, v, out)
    for sun in suns:
        if layered:
            from alight.core.layers.stack import Pairs, layered_brdf_cos

            l = _unit_rows(sun.direction)
            pairs = Pairs(n=n, v=v, l=l, t=t0, b=np.cross(n, t0), spread=sun.spread)
            out = out + layered_brdf_cos(material, pairs)[:, 0, :] * np.asarray(sun.power)[None, :]
        else:
            out = out + _sun_exact(n, v, sun.direction, sun.power, base, m, f0, r, sun.spread, diffuse_scale, f90)
    return out


def layered_ibl_converged(material, radiance, normals, view, base) -> np.ndarray:
    """Numpy twin of common/layers.glsl's layered_ibl with converged maps: (P, 3). ``base`` is the
    IBL model's result (P, 3); ``radiance`` the map the maps are baked from (without the compact
    sources for the alight model). The sheen reads the numpy twin of its LUT
    (alight.core.layers.sheen.sheen_lut_table), the clearcoat brdf_lut_converged."""
    from alight.core.layers import clearcoat as cc
    from alight.core.layers import sheen as sh

    n = _unit_rows(normals)
    v = np.broadcast_to(_unit_rows(view), n.shape)
    out = np.asarray(base, np.float64)
    used = material.layers()
    if "transmission" in used:
        out = out + transmission_environment_converged(material, radiance, n, v)
    if "sheen" in used:
        nv = np.clip(np.sum(n * v, axis=-1), 0.0, 1.0)
        lut = sh.lut_bilinear(sh.sheen_lut_table(), nv, material.sheen_roughness)   # (P, 4)
        toward_v = v - n * np.sum(n * v, axis=-1, keepdims=True)
        length = np.linalg.norm(toward_v, axis=-1, keepdims=True)
        t = np.where(length > 1e-6, toward_v / np.maximum(length, 1e-300), 0.0)
        d = _unit_rows(n * np.sqrt(np.maximum(1.0 - lut[:, 1:2] ** 2, 0.0)) + t * lut[:, 1:2])
        sheen = np.minimum(lut[:, :1], 1.0) * prefiltered_converged_each(radiance, d, lut[:, 2])
        out = out * sh.sheen_scaling(material.sheen_color, lut[:, :1]) + sheen * np.asarray(material.sheen_color)
    if "clearcoat" in used:
        rc = float(material.clearcoat_roughness)
        nv = np.maximum(np.sum(n * v, axis=-1), 0.0)
        A, B = brdf_lut_converged(nv, rc)
        t_a, t_b = lobe_directions_converged(nv, rc)
        t = (A * t_a + B * t_b) / np.maximum(A + B, 1e-6)   # ibl.glsl's mix with F0 = 1
        R = reflect(-v, n)
        d = _unit_rows(n + t[:, None] * (R - n))
        weight = material.clearcoat * cc.clearcoat_fresnel(nv)[:, None]
        out = out * (1.0 - weight) + weight * (A + B)[:, None] * prefiltered_converged(radiance, d, rc)
    return out


def _sun_exact(n, v, l, power, base, metallic, f0, roughness, spread=0.0, diffuse_scale=1.0, f90=1.0):
    """ibl.glsl's sun_light: the exact BRDF (IBL k, F at v.h) times the power P, D widened to
    alpha' = sqrt(alpha^2 + spread^2) for the source's size."""
    l = np.asarray(l, dtype=np.float64)
    nl = n @ l
    nv = np.maximum(np.sum(n * v, axis=-1), 1e-4)
    h = _unit_rows(l[None, :] + v)
    nh = np.clip(np.sum(n * h, axis=-1), 0.0, 1.0)
    vh = np.clip(np.sum(v * h, axis=-1), 0.0, 1.0)
    widened = max(float(np.sqrt(np.sqrt(roughness ** 4 + spread ** 2))), 0.045)
    a2 = widened ** 4
    D = a2 / (PI * (nh * nh * (a2 - 1.0) + 1.0) ** 2)
    nlc = np.maximum(nl, 0.0)
    k = k_ibl(max(roughness, 0.045))
    G = G_Smith(nv, np.where(nl > 0, nl, 1.0), k)
    F = F_Schlick(vh, f0, f90)
    spec = (D * G / (4.0 * np.where(nl > 0, nl, 1.0) * nv))[:, None] * F
    diffuse = (1.0 - F) * (1.0 - metallic) * base / PI * diffuse_scale
    return np.where((nl > 0)[:, None], (diffuse + spec) * nlc[:, None] * np.asarray(power)[None, :], 0.0)


def downsample_equirect(radiance, factor: int) -> np.ndarray:
    """Area-weighted integer box reduction (columns averaged, rows weighted by solid angle).

    For speed in tests (the texel sums cost O(texels)). Error it adds, measured on
    royal_esplanade_1k.hdr at factor 2 (1024x512 -> 512x256) against the full-resolution
    converged values at 2000 random directions (relative, per channel, max / mean):
    irradiance_converged 1.1e-4 / 9e-6; prefiltered_converged r = 0.25: 5.6e-4 / 7e-5,
    r = 0.5: 7e-5 / 1.6e-5, r = 1.0: 1.0e-4 / 8e-6 (r = 0.15: 2.1e-3 / 1.3e-4, so keep
    r >= 0.25 when downsampling). At factor 4: irradiance 5.8e-4 / 4e-5, r = 0.5: 3.3e-4 / 8e-5.
    """
    return box_reduce(radiance, int(factor))


# --- transmission (docs/layer_transmission.md) --------------------------------------------------

def prefilter_kernel_mean_cosine(roughness, n_u: int = 4096):
    """The mean cosine between l and the lookup direction d of the prefiltered map's kernel at a
    roughness, D(h) max(d.l, 0) over l with h = normalize(l + d) (the lecture's prefilter, N = V =
    R = d): E[(n.l)^2] / E[n.l] over h drawn with pdf D(h)(n.h), n.l = 2 (n.h)^2 - 1, only
    n.l > 0. 1 at roughness 0, falling with roughness; a midpoint rule over the GGX inverse CDF
    (twin of transmission_lut.comp's prefilter_kernel_mean_cosine)."""
    r = np.atleast_1d(np.asarray(roughness, dtype=np.float64))
    u = (np.arange(n_u) + 0.5) / n_u
    out = np.empty(r.shape)
    for i, rr in enumerate(r.reshape(-1)):
        a2 = rr ** 4
        nh2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u)
        nl = np.maximum(2.0 * nh2 - 1.0, 0.0)
        out.reshape(-1)[i] = float(np.sum(nl * nl) / max(np.sum(nl), 1e-30)) if a2 > 0 else 1.0
    return out.reshape(np.shape(roughness))


def roughness_for_mean_cosine(mean_cosine, steps: int = 40):
    """The prefiltered roughness whose kernel has this mean cosine (bisection on
    ``prefilter_kernel_mean_cosine``), clamped to [0, 1]."""
    c = np.atleast_1d(np.asarray(mean_cosine, dtype=np.float64)).reshape(-1)
    lo = np.zeros_like(c)
    hi = np.ones_like(c)
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        wider = prefilter_kernel_mean_cosine(mid, 1024) < c   # mid's kernel is wider than wanted
        hi = np.where(wider, mid, hi)
        lo = np.where(wider, lo, mid)
    return (0.5 * (lo + hi)).reshape(np.shape(mean_cosine))


def transmission_lut_converged(n_dot_v, roughness, ior, n_u: int = 256, n_phi: int = 64):
    """Numpy twin of ``ibl/transmission_lut.comp``: the refracted lobe of KHR_materials_volume's
    BTDF (v outside, index 1; l inside, index ``ior``) at one (n.v, roughness, ior) each, as
    three numbers the forward pass reads (docs/layer_transmission.md, "Real-time"):

    - E: the integral of btdf (1 - Fc(v.h)) |n.l| over l (transmitted = (1 - m) t c T (1 - F0) E L
      under a constant environment L). Drawing h with pdf D(h)(n.h) and l = refract(-v, h, 1/ior),
      the weight is (1 - Fc) G(n.v, |n.l|) (v.h) / ((n.h)(n.v)): the same as the BRDF LUT's;
    - bend: the sine of the lobe's mean direction's angle from -n (leaning toward -v's
      tangential part) over the sine of v's angle from n: 1/ior for a smooth surface (Snell),
      more where roughness leans the lobe toward grazing. A ratio rather than the sine itself,
      so that it goes to 0 with the view's sine at n.v = 1, where the tangential direction is
      undefined (the table's last texel centre is n.v = 0.984, not 1);
    - roughness: the prefiltered roughness whose kernel has the same mean cosine about its axis
      (``roughness_for_mean_cosine``), so one prefiltered fetch along the mean direction stands
      for the lobe.

    Midpoint grid over (u, phi in [0, 2 pi)) as ``brdf_lut_converged``; n.v >= 1e-4, ior >= 1.
    Returns (E, bend, roughness), each of the broadcast shape.
    """
    from alight.core.btdf import refract

    nv, r, eta = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in (n_dot_v, roughness, ior)))
    shape = nv.shape
    nv = np.clip(nv.reshape(-1), 1e-4, 1.0)
    r = np.clip(r.reshape(-1), 0.0, 1.0)
    eta = np.maximum(eta.reshape(-1), 1.0)
    sg = (np.arange(n_u) + 0.5) / n_u
    u = 1.0 - (1.0 - sg) ** 2
    wu = 2.0 * (1.0 - sg) / n_u
    phi = (np.arange(n_phi) + 0.5) * (2.0 * PI / n_phi)
    energy = np.empty(nv.shape[0])
    bend = np.empty(nv.shape[0])
    cosines = np.empty(nv.shape[0])
    for i in range(nv.shape[0]):
        a2 = r[i] ** 4
        cos_t = np.sqrt((1.0 - u) / (1.0 + (a2 - 1.0) * u))
        sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
        h = np.stack([sin_t[:, None] * np.cos(phi)[None, :], sin_t[:, None] * np.sin(phi)[None, :],
                      np.broadcast_to(cos_t[:, None], (n_u, n_phi))], axis=-1)
        v = np.array([np.sqrt(1.0 - nv[i] ** 2), 0.0, nv[i]])
        vh = h @ v
        l = refract(np.broadcast_to(-v, h.shape), h, np.full(h.shape[:2], 1.0 / eta[i]))
        nl = l[..., 2]
        ok = (nl < 0.0) & (vh > 0.0)
        g = G_Smith(nv[i], np.where(ok, -nl, 1.0), k_ibl(r[i]))
        w = np.where(ok, (1.0 - (1.0 - np.clip(vh, 0.0, 1.0)) ** 5) * g * vh / (h[..., 2] * nv[i]), 0.0)
        w = w * wu[:, None] / n_phi
        energy[i] = float(w.sum())
        mx, mz = float(np.sum(w * l[..., 0])), float(np.sum(w * l[..., 2]))
        length = np.hypot(mx, mz)
        sin_v = np.sqrt(max(1.0 - nv[i] ** 2, 0.0))
        bend[i] = -mx / length / sin_v if length > 0 and sin_v > 0 else 1.0 / eta[i]
        cosines[i] = length / energy[i] if energy[i] > 0 else 1.0
    rough = roughness_for_mean_cosine(cosines)
    return energy.reshape(shape), bend.reshape(shape), rough.reshape(shape)


def transmitted_lobe_converged(material, normals, view, n_table: int = 129):
    """Where the forward pass's transmitted lobe points, its prefiltered roughness and its energy
    (common/transmission.glsl: thin_walled_lobe, refracted_lobe) with converged tables: (P, 3)
    directions, (P,) roughness, (P,) energy. Thin-walled: the BRDF LUT's A and t_A (mirrored
    through the surface), roughness the material's. Refracting: ``transmission_lut_converged``
    on ``n_table`` values of n.v, interpolated linearly (the lobe changes slowly in n.v)."""
    from alight.core.btdf import mirror_through_surface

    n = _unit_rows(normals)
    v = np.broadcast_to(_unit_rows(view), n.shape)
    r = float(material.roughness)
    nv = np.clip(np.sum(n * v, axis=-1), 0.0, 1.0)
    if "volume" not in material.layers():
        A, _ = brdf_lut_converged(nv, r)
        t_a, _ = lobe_directions_converged(nv, r)
        R = reflect(-v, n)
        mean = _unit_rows(n + t_a[:, None] * (R - n))
        return mirror_through_surface(mean, n), np.full(nv.shape, r), A
    grid = np.linspace(1e-4, 1.0, n_table)
    energy, bend, rough = transmission_lut_converged(grid, r, float(material.ior))
    e = np.interp(nv, grid, energy)
    s = np.clip(np.interp(nv, grid, bend) * np.sqrt(1.0 - np.minimum(nv, 1.0) ** 2), 0.0, 1.0)
    rr = np.interp(nv, grid, rough)
    nvc = np.maximum(nv, 1e-4)
    tangential = v - nvc[:, None] * n
    length = np.linalg.norm(tangential, axis=-1, keepdims=True)
    side = np.where(length > 1e-6, -tangential / np.maximum(length, 1e-300), 0.0)
    direction = -n * np.sqrt(1.0 - s * s)[:, None] + side * s[:, None]
    return direction, rr, e


def prefiltered_converged_varying(radiance, directions, roughness, steps: int = 12) -> np.ndarray:
    """``prefiltered_converged`` where each direction has its own roughness: evaluated at
    ``steps`` roughness values spanning theirs and interpolated linearly in alpha = r^2 between
    the two nearest (the forward pass blends its grid steps the same way)."""
    d = _unit_rows(directions)
    r = np.clip(np.asarray(roughness, dtype=np.float64), MIN_PREFILTER_ROUGHNESS, 1.0)
    lo, hi = float(r.min()), float(r.max())
    if hi - lo < 1e-6:
        return prefiltered_converged(radiance, d, lo)
    knots = np.sqrt(np.linspace(lo * lo, hi * hi, steps))
    out = np.zeros((d.shape[0], 3))
    a = r * r
    ka = knots * knots
    idx = np.clip(np.searchsorted(ka, a) - 1, 0, steps - 2)
    t = ((a - ka[idx]) / (ka[idx + 1] - ka[idx]))[:, None]
    for j in range(steps - 1):
        sel = idx == j
        if sel.any():
            out[sel] = (1.0 - t[sel]) * prefiltered_converged(radiance, d[sel], knots[j]) \
                + t[sel] * prefiltered_converged(radiance, d[sel], knots[j + 1])
    return out


def transmission_environment_converged(material, radiance, normals, view) -> np.ndarray:
    """The transmitted environment with converged parts (P, 3): the twin of transmission.glsl's
    transmission_ibl, weight base (1 - F0) E L_prefiltered along the lobe (``radiance``: the map
    the maps are baked from, without the compact sources for the alight model; those go through
    the BTDF with the rest of the layered BRDF, ``ibl_converged``)."""
    from alight.core.btdf import beer_lambert

    import dataclasses

    from alight.core.layers.dispersion import channel_iors

    m = material
    n = _unit_rows(normals)
    v = np.broadcast_to(_unit_rows(view), n.shape)
    weight = (1.0 - m.metallic) * m.transmission * np.asarray(m.base_color) * (1.0 - np.asarray(m.f0()))
    if "volume" in m.layers():
        weight = weight * beer_lambert(m.attenuation_color, m.attenuation_distance, m.thickness)
    env = np.asarray(radiance, np.float32)

    def gathered(mc):
        direction, rough, energy = transmitted_lobe_converged(mc, n, v)
        return energy[:, None] * prefiltered_converged_varying(env, direction, rough)

    iors = channel_iors(m)
    if iors[0] == iors[2]:
        return weight * gathered(m)
    # KHR_materials_dispersion (transmission.glsl: dispersed_radiance): a lobe per channel.
    channels = [gathered(dataclasses.replace(m, ior=float(iors[c])))[:, c] for c in range(3)]
    return weight * np.stack(channels, -1)
