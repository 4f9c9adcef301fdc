"""KHR_materials_dispersion's numpy twin (shaders/common/dispersion_terms.glsl; the definition
is docs/layer_dispersion.md).

The extension gives ``dispersion = 20 / V_d``, V_d the Abbe number ``(n_d - 1) / (n_F - n_C)``,
so the spread between the blue (F line) and the red (C line) index is
``n_F - n_C = (n_d - 1) dispersion / 20``. Each colour channel refracts at its own index about
the material's ior (taken as n_d): red ``ior - h``, green ``ior``, blue ``ior + h`` with the
half spread ``h = (ior - 1) dispersion / 40``, the spread the Khronos glTF Sample Viewer uses.
Only a volume's refraction disperses (KHR_materials_volume; a thin wall bends nothing); the
Fresnel keeps the material's F0.
"""

from __future__ import annotations

import numpy as np

# h / ((ior - 1) dispersion): half of n_F - n_C = (n_d - 1) / V_d, with dispersion = 20 / V_d.
HALF_SPREAD_PER_DISPERSION = 1.0 / 40.0


def abbe_number(dispersion: float) -> float:
    """V_d = 20 / dispersion (inf for 0: no dispersion)."""
    return float("inf") if dispersion <= 0.0 else 20.0 / float(dispersion)


def dispersion_iors(ior: float, dispersion: float) -> np.ndarray:
    """The red, green and blue channels' indices of refraction (3,): ior -/+ (ior - 1)
    dispersion / 40 (dispersion_terms.glsl: dispersion_iors). Dispersion 0 gives ior three times."""
    half_spread = (float(ior) - 1.0) * HALF_SPREAD_PER_DISPERSION * float(dispersion)
    return np.array([ior - half_spread, ior, ior + half_spread], np.float64)


def channel_iors(m) -> np.ndarray:
    """The per-channel indices of a material (3,): ``dispersion_iors`` where its dispersion layer
    is on, else its ior in every channel."""
    if "dispersion" in m.layers():
        return dispersion_iors(m.ior, m.dispersion)
    return np.full(3, float(m.ior))
