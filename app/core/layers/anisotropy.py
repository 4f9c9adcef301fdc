"""KHR_materials_anisotropy's numpy twins (shaders/common/anisotropy.glsl; docs/layers.md).

Arrays are per (point, direction) pair as in ``alight.core.layers.stack.Pairs``. Until the
anisotropic lobe is written, ``anisotropic_specular`` is the isotropic lobe (what strength 0
must give).
"""

from __future__ import annotations

import numpy as np

from alight.core.shading import D_GGX, G1_SchlickGGX, k_ibl


def anisotropic_specular(m, p, F) -> np.ndarray:
    """The base's specular lobe D G F / (4 n.l n.v) (P, T, 3), with the IBL k; F (P, T, 3)."""
    nl = np.maximum(p.n_dot_l, 1e-8)
    k = k_ibl(m.roughness)
    dg = D_GGX(p.n_dot_h, m.roughness) * G1_SchlickGGX(nl, k) * G1_SchlickGGX(p.n_dot_v, k)
    return (dg / (4.0 * nl * p.n_dot_v))[..., None] * F
