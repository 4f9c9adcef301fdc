"""KHR_materials_anisotropy's numpy twins (shaders/common/anisotropy.glsl, same names;
docs/layer_anisotropy.md defines the BRDF exactly).

The terms broadcast over any leading shape; ``anisotropic_specular`` works per (point,
direction) pair as in ``alight.core.layers.stack.Pairs``.
"""

from __future__ import annotations

import numpy as np

from alight.core.shading import MIN_PUNCTUAL_ROUGHNESS, PI, G1_SchlickGGX, k_direct, k_ibl


def anisotropic_alpha(roughness, strength):
    """(alpha_t, alpha_b) = (mix(r^2, 1, strength^2), r^2) (KHR_materials_anisotropy)."""
    alpha = np.asarray(roughness, dtype=np.float64) ** 2
    s2 = np.asarray(strength, dtype=np.float64) ** 2
    return alpha + (1.0 - alpha) * s2, alpha


def D_GGX_anisotropic(t_dot_h, b_dot_h, n_dot_h, alpha_t, alpha_b):
    """GGX with alpha_t along t and alpha_b along b (Burley 2012, eq. 13):
    1 / (pi at ab ((t.h/at)^2 + (b.h/ab)^2 + (n.h)^2)^2)."""
    at = np.asarray(alpha_t, dtype=np.float64)
    ab = np.asarray(alpha_b, dtype=np.float64)
    q = (np.asarray(t_dot_h) / at) ** 2 + (np.asarray(b_dot_h) / ab) ** 2 + np.asarray(n_dot_h, dtype=np.float64) ** 2
    return 1.0 / (PI * at * ab * q * q)


def projected_alpha(t_dot_x, b_dot_x, alpha_t, alpha_b):
    """The alpha direction x sees: sqrt((t.x^2 at^2 + b.x^2 ab^2) / (t.x^2 + b.x^2)) (Heitz 2014,
    sec. 5.3); alpha_b where x is along n (G1 is 1 there whatever alpha)."""
    tx = np.asarray(t_dot_x, dtype=np.float64)
    bx = np.asarray(b_dot_x, dtype=np.float64)
    at, ab = np.asarray(alpha_t, dtype=np.float64), np.asarray(alpha_b, dtype=np.float64)
    sin2 = tx * tx + bx * bx
    ok = sin2 >= 1e-12
    value = np.sqrt((tx * tx * at * at + bx * bx * ab * ab) / np.where(ok, sin2, 1.0))
    return np.where(ok, value, ab)


def G1_anisotropic(n_dot_x, projected, punctual: bool):
    """Schlick-GGX masking at the projected alpha: k_direct(sqrt(alpha)) or k_ibl(sqrt(alpha))."""
    r = np.sqrt(np.asarray(projected, dtype=np.float64))
    return G1_SchlickGGX(n_dot_x, k_direct(r) if punctual else k_ibl(r))


def anisotropy_direction(m, n, t, b):
    """The world-space direction of the stretch (..., 3): the tangent frame's t rotated by
    ``anisotropy_rotation`` toward b (counter-clockwise, KHR_materials_anisotropy), and its
    bitangent cross(n, direction) (common/material_layers.glsl: apply_material_layers)."""
    c, s = np.cos(m.anisotropy_rotation), np.sin(m.anisotropy_rotation)
    direction = c * np.asarray(t, np.float64) + s * np.asarray(b, np.float64)
    return direction, np.cross(np.asarray(n, np.float64), direction)


def anisotropic_specular(m, p, F, punctual: bool = False, spread: float = 0.0) -> np.ndarray:
    """The stretched lobe D G F / (4 n.l n.v) (P, T, 3) for the pairs ``p`` (their t, b: the
    tangent frame before the rotation); F (P, T, 3). The defaults are docs/conventions.md's exact
    choices (k_ibl, no floor), what the ground truth sums."""
    direction, bitangent = anisotropy_direction(m, p.n, p.t, p.b)
    nl = np.maximum(p.n_dot_l, 1e-8)
    nv = p.n_dot_v
    r = max(m.roughness, MIN_PUNCTUAL_ROUGHNESS) if punctual else m.roughness
    at, ab = anisotropic_alpha(r, m.anisotropy_strength)
    if not punctual:
        floor = MIN_PUNCTUAL_ROUGHNESS ** 2
        wt, wb = max(np.sqrt(at * at + spread * spread), floor), max(np.sqrt(ab * ab + spread * spread), floor)
        at, ab = anisotropic_alpha(max(m.roughness, MIN_PUNCTUAL_ROUGHNESS), m.anisotropy_strength)
    else:
        wt, wb = at, ab
    D = D_GGX_anisotropic(p.dot_h(direction, "aniso_t"), p.dot_h(bitangent, "aniso_b"), p.n_dot_h, wt, wb)
    t_dot_v = np.sum(direction * p.v, -1)[:, None]
    b_dot_v = np.sum(bitangent * p.v, -1)[:, None]
    g1v = G1_anisotropic(nv, projected_alpha(t_dot_v, b_dot_v, at, ab), punctual)
    g1l = G1_anisotropic(nl, projected_alpha(p.dot_l(direction, "aniso_t"), p.dot_l(bitangent, "aniso_b"), at, ab),
                         punctual)
    return (D * g1v * g1l / (4.0 * nl * nv))[..., None] * F


def importance_sample_ggx_anisotropic(xi, alpha_t, alpha_b):
    """Half vectors (..., 3) in tangent space (x along the direction, z = n) with pdf D(h) (n.h):
    the unit GGX slope distribution scaled by (alpha_t, alpha_b) (Walter et al. 2007, sec. 5.2)."""
    xi = np.asarray(xi, dtype=np.float64)
    phi = 2.0 * PI * xi[..., 0]
    radius = np.sqrt(xi[..., 1] / np.maximum(1.0 - xi[..., 1], 1e-12))
    h = np.stack([radius * alpha_t * np.cos(phi), radius * alpha_b * np.sin(phi), np.ones_like(phi)], axis=-1)
    return h / np.linalg.norm(h, axis=-1, keepdims=True)


def fetch_normals(n, t, roughness, strength, fetches: int = 8):
    """The stretched lookup's microfacet normals (P, K, 3) for normals n and directions t (P, 3):
    h_k = normalize(n - x_k t), x_k = sqrt(alpha_t^2 - alpha_b^2) q / sqrt(1 - q^2) at the
    quantiles q = (2k + 1)/K - 1 of GGX's slope marginal (anisotropy.glsl's
    anisotropic_prefiltered_radiance)."""
    at, ab = anisotropic_alpha(roughness, strength)
    spread = np.sqrt(max(float(at * at - ab * ab), 0.0))
    q = (2.0 * np.arange(fetches) + 1.0) / fetches - 1.0
    x = spread * q / np.sqrt(1.0 - q * q)
    h = np.asarray(n, np.float64)[:, None, :] - x[None, :, None] * np.asarray(t, np.float64)[:, None, :]
    return h / np.linalg.norm(h, axis=-1, keepdims=True)


def fetch_weights(n, dk, h, v, t, b, roughness, strength):
    """Each fetch's weight (P, K): G1(n.d_k) at d_k's projected alpha times v.h_k / n.h_k."""
    at, ab = anisotropic_alpha(roughness, strength)
    n, v, t, b = (np.asarray(x, np.float64)[:, None, :] for x in (n, v, t, b))
    projected = projected_alpha(np.sum(t * dk, -1), np.sum(b * dk, -1), at, ab)
    masking = G1_anisotropic(np.maximum(np.sum(n * dk, -1), 0.0), projected, False)
    return masking * np.maximum(np.sum(v * h, -1), 0.0) / np.maximum(np.sum(n * h, -1), 1e-4)
