"""KHR_materials_diffuse_transmission's numpy twins (shaders/common/diffuse_transmission.glsl and
diffuse_transmission_terms.glsl; the definition is docs/layer_diffuse_transmission.md).

A share ``dt`` of the base's diffuse lobe leaves through the back side as a Lambertian BTDF of
colour ``c``: for l behind the surface (n.l < 0)

    f_dt |n.l| = (1 - m)(1 - t) dt c T (1 - F(v.h')) / pi |n.l|,  h' = normalize(v + l - 2 (n.l) n)

(the Fresnel at the half vector of l mirrored to the front, as the Khronos glTF Sample Viewer
takes it), T Beer-Lambert over the thickness where the volume layer is on, and the front
diffuse lobe keeps 1 - dt. Arrays are per (point, direction) pair as in
``alight.core.layers.stack.Pairs``.
"""

from __future__ import annotations

import numpy as np

from alight.core.btdf import beer_lambert
from alight.core.shading import PI, F_Schlick


def diffuse_btdf_cos(color, n_dot_l) -> np.ndarray:
    """diffuse_transmission_terms.glsl's diffuse_btdf_cos: c / pi |n.l| behind (n.l < 0), else 0;
    (..., 3) for colours (3,) and n.l (...)."""
    nl = np.asarray(n_dot_l, np.float64)
    return np.asarray(color, np.float64) * (np.maximum(-nl, 0.0) / PI)[..., None]


def front_weight(m) -> float:
    """What the front diffuse lobe keeps: 1 - diffuse_transmission."""
    return 1.0 - float(m.diffuse_transmission)


def diffuse_transmission_weight(m) -> np.ndarray:
    """dt c T (1 - metallic)(1 - transmission) (3,): the back lobe's weight before the Fresnel."""
    weight = m.diffuse_transmission * np.asarray(m.diffuse_transmission_color, np.float64) * (1.0 - m.metallic)
    if "transmission" in m.layers():
        weight = weight * (1.0 - m.transmission)
    if "volume" in m.layers():
        weight = weight * beer_lambert(m.attenuation_color, m.attenuation_distance, m.thickness)
    return weight


def diffuse_transmission_light(m, p) -> np.ndarray:
    """The back lobe times |n.l| for every pair (P, T, 3), 0 for l in front."""
    nl = p.n_dot_l                      # (P, T)
    nv_raw = p.n_dot_v_raw              # (P, 1)
    # v.h' with h' = normalize(v + l'), l' = l - 2 (n.l) n: v.(v + l') = 1 + v.l - 2 (n.l)(n.v)
    vlm = p.l_dot_v - 2.0 * nl * nv_raw
    length = np.maximum(np.sqrt(np.maximum(2.0 + 2.0 * vlm, 0.0)), 1e-7)
    vh = np.clip((1.0 + vlm) / length, 0.0, 1.0)
    F = F_Schlick(vh, np.asarray(m.f0(), np.float64))   # (P, T, 3)
    return diffuse_transmission_weight(m) * (1.0 - F) * diffuse_btdf_cos(np.ones(3), nl)
