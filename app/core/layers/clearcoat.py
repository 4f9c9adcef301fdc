"""KHR_materials_clearcoat's numpy twins (shaders/common/clearcoat.glsl, same names; exact
definition: docs/layer_clearcoat.md).

    coated = base (1 - clearcoat F_c(n_c.v)) + clearcoat F_c(n_c.v) D G / (4 n_c.l n_c.v) n_c.l
    F_c(x) = 0.04 + 0.96 (1 - x)^5                 (the coat's ior 1.5; Schlick 1994)

The scalar functions take dot products (any broadcasting shapes); ``clearcoat_base_weight`` and
``clearcoat_light`` take a material and ``alight.core.layers.stack.Pairs`` and give docs/conventions.md's
exact choices (k = r^2/2, no floor beyond MIN_PUNCTUAL_ROUGHNESS), which the ground truth sums.
"""

from __future__ import annotations

import numpy as np

from alight.core.shading import D_GGX, MIN_N_DOT_V, MIN_PUNCTUAL_ROUGHNESS, G1_SchlickGGX, k_direct, k_ibl

CLEARCOAT_F0 = 0.04


def clearcoat_fresnel(n_dot_v):
    """The coat's Fresnel weight at n_c.v (n_c.v clamped to [0, 1])."""
    x = 1.0 - np.clip(np.asarray(n_dot_v, np.float64), 0.0, 1.0)
    return CLEARCOAT_F0 + (1.0 - CLEARCOAT_F0) * x ** 5


def clearcoat_lobe(n_dot_l, n_dot_v, n_dot_h, roughness, punctual=False, spread=0.0):
    """D G / (4 n.l n.v) n.l of the coat, without Fresnel; 0 where n_c.l <= 0. ``n_dot_v`` is
    clamped to MIN_N_DOT_V, ``n_dot_h`` to >= 0, the roughness floored at MIN_PUNCTUAL_ROUGHNESS."""
    nl = np.asarray(n_dot_l, np.float64)
    nv = np.maximum(np.asarray(n_dot_v, np.float64), MIN_N_DOT_V)
    nh = np.maximum(np.asarray(n_dot_h, np.float64), 0.0)
    r = max(float(roughness), MIN_PUNCTUAL_ROUGHNESS)
    alpha = float(roughness) ** 2
    lobe = r if punctual else max(float(np.sqrt(np.sqrt(alpha * alpha + spread * spread))), MIN_PUNCTUAL_ROUGHNESS)
    k = k_direct(r) if punctual else k_ibl(r)
    lit = nl > 0.0
    nl_s = np.where(lit, nl, 1.0)
    out = D_GGX(nh, lobe) * G1_SchlickGGX(nv, k) * G1_SchlickGGX(nl_s, k) / (4.0 * nv)
    return np.where(lit, out, 0.0)


def _coat_dots(p):
    n_c = p.coat_normal
    return p.dot_l(n_c, "n_c"), np.sum(n_c * p.v, axis=-1)[:, None], p.dot_h(n_c, "n_c")


def clearcoat_base_weight(m, p) -> np.ndarray:
    """What the coat lets through, 1 - clearcoat F_c(n_c.v): (P, 1), broadcasting over T."""
    _, nv, _ = _coat_dots(p)
    return 1.0 - m.clearcoat * clearcoat_fresnel(nv)


def clearcoat_light(m, p) -> np.ndarray:
    """The coat's BRDF times n_c.l, weighted by clearcoat: (P, T, 3), the exact choices."""
    nl, nv, nh = _coat_dots(p)
    f = m.clearcoat * clearcoat_fresnel(nv) * clearcoat_lobe(nl, nv, nh, m.clearcoat_roughness, spread=p.spread)
    return np.repeat(f[..., None], 3, axis=-1)
