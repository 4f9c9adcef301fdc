"""KHR_materials_sheen's numpy twins (shaders/common/sheen.glsl; docs/layers.md).

Arrays are per (point, direction) pair as in ``alight.core.layers.stack.Pairs``.
"""

from __future__ import annotations

import numpy as np


def sheen_base_weight(m, p) -> np.ndarray:
    """The albedo scaling of the layers below the sheen for each pair: (P, T)."""
    return np.ones(p.n_dot_l.shape)


def sheen_light(m, p) -> np.ndarray:
    """The sheen BRDF times n.l: (P, T, 3)."""
    return np.zeros(p.n_dot_l.shape + (3,))
