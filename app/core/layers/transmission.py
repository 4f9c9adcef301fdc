"""KHR_materials_transmission and KHR_materials_volume's numpy twins
(shaders/common/transmission.glsl; the definition is docs/layer_transmission.md).

Arrays are per (point, direction) pair as in ``alight.core.layers.stack.Pairs``. The BTDF terms
themselves are ``alight.core.btdf`` (twins of common/btdf.glsl).
"""

from __future__ import annotations

import numpy as np

from alight.core.btdf import beer_lambert, btdf_refraction, btdf_thin
from alight.core.layers import dispersion
from alight.core.shading import MIN_PUNCTUAL_ROUGHNESS, F_Schlick, k_direct, k_ibl


def thin_walled(m) -> bool:
    """KHR_materials_volume absent or thickness 0: the surface is a thin wall."""
    return "volume" not in m.layers()


def transmission_weight(m) -> np.ndarray:
    """(1 - metallic) transmission T (RGB): what transmitted light keeps before the base colour
    and the Fresnel; T is Beer-Lambert over the thickness (1 for a thin wall)."""
    weight = (1.0 - m.metallic) * m.transmission * np.ones(3)
    if not thin_walled(m):
        weight = weight * beer_lambert(m.attenuation_color, m.attenuation_distance, m.thickness)
    return weight


def widened_transmission_roughness(m, spread: float) -> float:
    """transmission.glsl's widened_transmission_roughness: the lobe's alpha widened for a source
    of RMS angular radius ``spread``, 2 / (1 - 1/ior) times more for the narrower refracted lobe."""
    scale = 1.0 if thin_walled(m) else 2.0 / max(1.0 - 1.0 / m.ior, 1e-3)
    alpha = m.roughness ** 2
    return min(float(np.sqrt(np.sqrt(alpha * alpha + (spread * scale) ** 2))), 1.0)


def transmission_light(m, p, punctual: bool = False) -> np.ndarray:
    """The transmitted part of the base times |n.l| for every pair, (P, T, 3): for l behind the
    surface (n.l < 0) (1 - m) t T base (1 - F(v.h)) btdf |n.l|, 0 in front. ``punctual``: the
    punctual lights' k = (r+1)^2/8 and roughness floor; else the exact k = r^2/2. A compact
    source (``p.spread`` > 0) widens D's lobe (``widened_transmission_roughness``); k keeps the
    material's roughness, as ibl.glsl's sun_light does. With KHR_materials_dispersion each
    channel refracts at its own index (``alight.core.layers.dispersion``)."""
    roughness = max(m.roughness, MIN_PUNCTUAL_ROUGHNESS) if punctual else m.roughness
    k = k_direct(roughness) if punctual else k_ibl(roughness)
    spread = float(getattr(p, "spread", 0.0))
    if spread > 0.0:
        roughness = max(widened_transmission_roughness(m, spread), MIN_PUNCTUAL_ROUGHNESS)
    nl = p.n_dot_l                      # (P, T)
    behind = nl < 0.0
    iors = dispersion.channel_iors(m) if not thin_walled(m) else np.full(3, float(m.ior))
    if iors[0] == iors[2]:
        value = transmitted_btdf_at(m, p, float(iors[1]), roughness, k)
    else:   # KHR_materials_dispersion: each channel at its own index
        value = np.stack([transmitted_btdf_at(m, p, float(iors[c]), roughness, k)[..., c] for c in range(3)], -1)
    return (transmission_weight(m) * np.asarray(m.base_color, np.float64)) * value \
        * np.where(behind, -nl, 0.0)[..., None]


def transmitted_btdf_at(m, p, eta: float, roughness: float, k: float) -> np.ndarray:
    """transmission.glsl's transmitted_btdf_at: (1 - F(v.h)) btdf (P, T, 3) at index ``eta``
    (thin-walled materials ignore it), 0 in front of the surface."""
    nl = p.n_dot_l                      # (P, T)
    nv = p.n_dot_v                      # (P, 1), clamped
    nv_raw = p.n_dot_v_raw
    lv = p.l_dot_v                      # (P, T)
    behind = nl < 0.0
    if thin_walled(m):
        # h = normalize(v + l'), l' = l - 2 (n.l) n: n.(v + l') = n.v - n.l, v.(v + l') = 1 + v.l'
        vlm = lv - 2.0 * nl * nv_raw
        length = np.maximum(np.sqrt(np.maximum(2.0 + 2.0 * vlm, 0.0)), 1e-7)
        nh = (nv_raw - nl) / length
        vh = (1.0 + vlm) / length
        btdf = btdf_thin(nv, nl, nh, roughness, k)
    else:
        # h = -(v + ior l)/|v + ior l|
        length = np.maximum(np.sqrt(np.maximum(1.0 + eta * eta + 2.0 * eta * lv, 0.0)), 1e-7)
        nh = -(nv_raw + eta * nl) / length
        vh = -(1.0 + eta * lv) / length
        lh = -(lv + eta) / length
        btdf = btdf_refraction(nv, nl, nh, vh, lh, roughness, eta, k)
    F = F_Schlick(np.clip(vh, 0.0, 1.0), np.asarray(m.f0(), np.float64))      # (P, T, 3)
    return (1.0 - F) * np.where(behind, btdf, 0.0)[..., None]
