"""Numpy twins of the GLSL shading functions in ``shaders/common``.

Each function here has a GLSL function of the same name; the tests evaluate both on the same
inputs and compare. Everything broadcasts over leading array dimensions; vectors live in the
last axis. Conventions (coordinates, the equirectangular mapping, the probe view, the BRDF) are
those of ``docs/conventions.md``.
"""

from __future__ import annotations

import numpy as np

PI = np.pi


def _dot(a, b):
    return np.sum(np.asarray(a) * np.asarray(b), axis=-1)


def _normalize(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


# --- BRDF terms (brdf.glsl) -------------------------------------------------------------

def D_GGX(n_dot_h, roughness):
    """Trowbridge-Reitz GGX normal distribution, alpha = roughness^2 (Walter et al. 2007)."""
    a2 = np.asarray(roughness, dtype=np.float64) ** 4
    d = np.asarray(n_dot_h, dtype=np.float64) ** 2 * (a2 - 1.0) + 1.0
    return a2 / (PI * d * d)


def normal_map_roughness(roughness, widening):
    """A normal map's lost spread added to GGX's alpha^2 (Toksvig 2005): sigma^2 = widening^4
    (alight.render.normal_spread's A), roughness' = (roughness^4 + widening^4)^(1/4)."""
    r = np.asarray(roughness, dtype=np.float64)
    w = np.asarray(widening, dtype=np.float64)
    return (r ** 4 + w ** 4) ** 0.25


def k_direct(roughness):
    """Schlick-GGX k for punctual lights (Karis 2013)."""
    return (np.asarray(roughness, dtype=np.float64) + 1.0) ** 2 / 8.0


def k_ibl(roughness):
    """Schlick-GGX k for image-based lighting (Karis 2013)."""
    return np.asarray(roughness, dtype=np.float64) ** 2 / 2.0


def G1_SchlickGGX(n_dot_x, k):
    """Schlick's approximation of the Smith masking term for one direction (Schlick 1994)."""
    n_dot_x = np.asarray(n_dot_x, dtype=np.float64)
    return n_dot_x / (n_dot_x * (1.0 - k) + k)


def G_Smith(n_dot_v, n_dot_l, k):
    """Separable Smith geometry term: masking times shadowing (Smith 1967)."""
    return G1_SchlickGGX(n_dot_v, k) * G1_SchlickGGX(n_dot_l, k)


def F_Schlick(v_dot_h, f0, f90=1.0):
    """Schlick's Fresnel approximation (Schlick 1994): f0 + (f90 - f0)(1 - v.h)^5. f0 broadcasts
    against v_dot_h[..., None]; f90 (scalar or v_dot_h's shape) is 1 but for KHR_materials_specular,
    whose specularFactor is the dielectric's F90 (brdf.glsl's three-argument F_Schlick)."""
    x = np.clip(1.0 - np.asarray(v_dot_h, dtype=np.float64), 0.0, 1.0) ** 5
    f0 = np.asarray(f0, dtype=np.float64)
    f90 = np.asarray(f90, dtype=np.float64)
    f90 = f90[..., None] if f90.ndim else f90
    return f0 + (f90 - f0) * x[..., None]


def F_SchlickRoughness(n_dot_v, f0, roughness):
    """The lecture's roughness-aware Fresnel for the ambient term (Lagarde, sebastien lagarde blog 2011)."""
    x = np.clip(1.0 - np.asarray(n_dot_v, dtype=np.float64), 0.0, 1.0) ** 5
    f0 = np.asarray(f0, dtype=np.float64)
    r = np.asarray(roughness, dtype=np.float64)[..., None]
    return f0 + (np.maximum(1.0 - r, f0) - f0) * x[..., None]


def f0_of(base_color, metallic, specular_f0):
    """F0 = mix(specular_f0, base_color, metallic) (docs/conventions.md, material model)."""
    m = np.asarray(metallic, dtype=np.float64)[..., None]
    return np.asarray(specular_f0) * (1.0 - m) + np.asarray(base_color) * m


# --- sampling (sampling.glsl) -----------------------------------------------------------

def radical_inverse_vdc(i):
    """Van der Corput radical inverse in base 2 (bit reversal of a 32-bit integer)."""
    b = np.asarray(i, dtype=np.uint64) & np.uint64(0xFFFFFFFF)
    b = ((b << np.uint64(16)) | (b >> np.uint64(16))) & np.uint64(0xFFFFFFFF)
    b = ((b & np.uint64(0x55555555)) << np.uint64(1)) | ((b & np.uint64(0xAAAAAAAA)) >> np.uint64(1))
    b = ((b & np.uint64(0x33333333)) << np.uint64(2)) | ((b & np.uint64(0xCCCCCCCC)) >> np.uint64(2))
    b = ((b & np.uint64(0x0F0F0F0F)) << np.uint64(4)) | ((b & np.uint64(0xF0F0F0F0)) >> np.uint64(4))
    b = ((b & np.uint64(0x00FF00FF)) << np.uint64(8)) | ((b & np.uint64(0xFF00FF00)) >> np.uint64(8))
    return b.astype(np.float64) * 2.3283064365386963e-10


def hammersley(i, n):
    """The i-th of n Hammersley points in [0,1)^2."""
    i = np.asarray(i)
    return np.stack([i / float(n), radical_inverse_vdc(i)], axis=-1)


def importance_sample_ggx_tangent(xi, roughness):
    """Half vector in tangent space (z = normal), distributed with pdf D(h) (n.h) (Karis 2013)."""
    a = np.asarray(roughness, dtype=np.float64) ** 2
    phi = 2.0 * PI * xi[..., 0]
    denominator = 1.0 + (a * a - 1.0) * xi[..., 1]
    cos_t = np.sqrt((1.0 - xi[..., 1]) / denominator)
    sin_t = np.sqrt(a * a * xi[..., 1] / denominator)   # 1 - cos^2 without cancellation
    return np.stack([np.cos(phi) * sin_t, np.sin(phi) * sin_t, cos_t], axis=-1)


# --- environment mapping (equirect.glsl) ------------------------------------------------

def direction_to_equirect_uv(d):
    """docs/conventions.md: u = 0.5 + atan2(d.x, -d.z)/(2 pi), v = acos(d.y)/pi (v = 0 at the top row)."""
    d = np.asarray(d, dtype=np.float64)
    u = 0.5 + np.arctan2(d[..., 0], -d[..., 2]) / (2.0 * PI)
    v = np.arccos(np.clip(d[..., 1], -1.0, 1.0)) / PI
    return np.stack([u, v], axis=-1)


def equirect_uv_to_direction(uv):
    """Inverse of direction_to_equirect_uv."""
    uv = np.asarray(uv, dtype=np.float64)
    phi = (uv[..., 0] - 0.5) * 2.0 * PI
    theta = uv[..., 1] * PI
    s = np.sin(theta)
    return np.stack([s * np.sin(phi), np.cos(theta), -s * np.cos(phi)], axis=-1)


def rotate_world_to_map(d, rotation_deg):
    """Radiance arriving from world direction d is the map's radiance in R_y(-deg) d."""
    t = np.radians(-np.asarray(rotation_deg, dtype=np.float64))
    c, s = np.cos(t), np.sin(t)
    d = np.asarray(d, dtype=np.float64)
    return np.stack([c * d[..., 0] + s * d[..., 2], d[..., 1], -s * d[..., 0] + c * d[..., 2]], axis=-1)


def texel_directions(height, width):
    """Unit directions (H, W, 3) of equirectangular texel centres and their solid angles (H, W)."""
    rows = (np.arange(height) + 0.5) / height
    cols = (np.arange(width) + 0.5) / width
    uv = np.stack(np.meshgrid(cols, rows), axis=-1)
    dirs = equirect_uv_to_direction(uv)
    theta = rows * PI
    omega = (2.0 * PI / width) * (PI / height) * np.sin(theta)
    return dirs, np.broadcast_to(omega[:, None], (height, width))


# --- the probe view ---------------------------------------------------------------------

def probe_normals(width):
    """Per-pixel normals (W, W, 3) and the inside mask (W, W) of docs/conventions.md's probe view."""
    c = (np.arange(width) + 0.5) / width
    x = 2.0 * c[None, :] - 1.0
    y = 1.0 - 2.0 * c[:, None]
    x, y = np.broadcast_arrays(x, y)
    r2 = x * x + y * y
    inside = r2 < 1.0
    z = np.sqrt(np.maximum(0.0, 1.0 - r2))
    return np.stack([x, y, z], axis=-1), inside


def reflect(i, n):
    """GLSL reflect(): i - 2 (n.i) n."""
    return i - 2.0 * _dot(n, i)[..., None] * n


# --- tone mapping and output (tonemapping.glsl) -----------------------------------------

TONEMAP_INPUT_MAX = 1.0e6   # tonemapping.glsl: exposed radiance is limited to this first


def tonemap_aces_fitted(c):
    """Stephen Hill's fit of the ACES RRT+ODT (BakingLab, 2016), sRGB primaries in and out."""
    c = np.minimum(np.asarray(c, dtype=np.float64), TONEMAP_INPUT_MAX)
    m_in = np.array([[0.59719, 0.35458, 0.04823],
                     [0.07600, 0.90834, 0.01566],
                     [0.02840, 0.13383, 0.83777]])
    m_out = np.array([[1.60475, -0.53108, -0.07367],
                      [-0.10208, 1.10813, -0.00605],
                      [-0.00327, -0.07276, 1.07602]])
    v = c @ m_in.T
    a = v * (v + 0.0245786) - 0.000090537
    b = v * (0.983729 * v + 0.4329510) + 0.238081
    return np.clip((a / b) @ m_out.T, 0.0, 1.0)


def tonemap_pbr_neutral(c):
    """Khronos PBR Neutral tone mapper (Khronos 3D Commerce, 2024)."""
    c = np.minimum(np.asarray(c, dtype=np.float64), TONEMAP_INPUT_MAX)
    start, desat = 0.8 - 0.04, 0.15
    x = np.min(c, axis=-1, keepdims=True)
    offset = np.where(x < 0.08, x - 6.25 * x * x, 0.04)
    c = c - offset
    peak = np.max(c, axis=-1, keepdims=True)
    d = 1.0 - start
    new_peak = 1.0 - d * d / (peak + d - start)
    compressed = c * (new_peak / np.maximum(peak, 1e-20))
    g = 1.0 - 1.0 / (desat * (peak - new_peak) + 1.0)
    mixed = compressed * (1.0 - g) + new_peak * g
    return np.where(peak < start, c, mixed)


def tonemap_aces_narkowicz(c):
    """Narkowicz's ACES fit (2016), per channel, as the glTF Sample Viewer applies it."""
    c = np.minimum(np.asarray(c, dtype=np.float64), TONEMAP_INPUT_MAX)
    return np.clip((c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14), 0.0, 1.0)


def tonemap_aces_hill_exposure_boost(c):
    """Hill's fit of c / 0.6: three.js's, model-viewer's and the Sample Viewer's default ACES."""
    return tonemap_aces_fitted(np.minimum(np.asarray(c, dtype=np.float64), TONEMAP_INPUT_MAX) / 0.6)


_SRGB_TO_REC2020 = np.array([[0.6274, 0.3293, 0.0433], [0.0691, 0.9195, 0.0113], [0.0164, 0.0880, 0.8956]])
_REC2020_TO_SRGB = np.array([[1.6605, -0.5876, -0.0728], [-0.1246, 1.1329, -0.0083], [-0.0182, -0.1006, 1.1187]])
_AGX_INSET = np.array([[0.856627153315983, 0.0951212405381588, 0.0482516061458583],
                       [0.137318972929847, 0.761241990602591, 0.101439036467562],
                       [0.11189821299995, 0.0767994186031903, 0.811302368396859]])
_AGX_OUTSET = np.array([[1.1271005818144368, -0.11060664309660323, -0.016493938717834573],
                        [-0.1413297634984383, 1.157823702216272, -0.016493938717834257],
                        [-0.14132976349843826, -0.11060664309660294, 1.2519364065950405]])


def tonemap_agx(c):
    """AgX as Filament and three.js implement it (tonemapping.glsl's tonemap_agx); sRGB in and out.
    The matrices are the GLSL's transposed (GLSL's mat3 takes columns)."""
    c = np.minimum(np.asarray(c, dtype=np.float64), TONEMAP_INPUT_MAX)
    min_ev, max_ev = -12.47393, 4.026069
    c = c @ _SRGB_TO_REC2020.T @ _AGX_INSET.T
    x = np.clip((np.log2(np.maximum(c, 1e-10)) - min_ev) / (max_ev - min_ev), 0.0, 1.0)
    x2 = x * x
    x4 = x2 * x2
    s = 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x - 0.00232
    c = np.maximum(s @ _AGX_OUTSET.T, 0.0) ** 2.2
    return np.clip(c @ _REC2020_TO_SRGB.T, 0.0, 1.0)


def linear_to_srgb(c):
    """The sRGB transfer function (IEC 61966-2-1)."""
    c = np.clip(np.asarray(c, dtype=np.float64), 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def srgb_to_linear(c):
    """Inverse of linear_to_srgb."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


# --- punctual lights (punctual.glsl) ----------------------------------------------------

MIN_PUNCTUAL_ROUGHNESS = 0.045   # brdf.glsl
MIN_N_DOT_V = 1e-4               # brdf.glsl


def spot_attenuation(cos_angle, scale, offset):
    """A spot's angular falloff (KHR_lights_punctual's recommended implementation): the square
    of clamp(cos(angle off the axis) * scale + offset, 0, 1), scale = 1 / max(0.001, cos inner -
    cos outer), offset = -cos outer * scale."""
    t = np.clip(np.asarray(cos_angle, np.float64) * scale + offset, 0.0, 1.0)
    return t * t


def range_attenuation(distance_squared, range_):
    """KHR_lights_punctual's range window: clamp(1 - (d / range)^4, 0, 1)^2 (1 without a range)."""
    if range_ is None or range_ <= 0:
        return np.ones_like(np.asarray(distance_squared, np.float64))
    x = np.asarray(distance_squared, np.float64) / (range_ * range_)
    return np.clip(1.0 - x * x, 0.0, 1.0) ** 2


def punctual_light(n, v, l, base_color, metallic, roughness, specular_f0, radiance_in):
    """f(l, v) L_in (n.l) for one delta light, with k = (r+1)^2/8 (the lecture's punctual k)."""
    n, v, l = (np.asarray(x, dtype=np.float64) for x in (n, v, l))
    n_dot_l = _dot(n, l)
    n_dot_v = np.maximum(_dot(n, v), MIN_N_DOT_V)
    h = _normalize(l + v)
    n_dot_h = np.maximum(_dot(n, h), 0.0)
    v_dot_h = np.maximum(_dot(v, h), 0.0)
    r = np.maximum(roughness, MIN_PUNCTUAL_ROUGHNESS)
    f0 = f0_of(base_color, metallic, specular_f0)
    F = F_Schlick(v_dot_h, f0)
    kd = (1.0 - F) * (1.0 - np.asarray(metallic, dtype=np.float64)[..., None])
    D = D_GGX(n_dot_h, r)
    G = G_Smith(n_dot_v, np.maximum(n_dot_l, 1e-8), k_direct(r))
    specular = (D * G)[..., None] * F / (4.0 * np.maximum(n_dot_l, 1e-8) * n_dot_v)[..., None]
    out = (kd * np.asarray(base_color) / PI + specular) * np.asarray(radiance_in) * n_dot_l[..., None]
    return np.where((n_dot_l > 0.0)[..., None], out, 0.0)
