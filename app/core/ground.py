"""Where the ground under a model lies (``--ground``): pure geometry.

The ground is a square on the plane through the bottom of the model's bounding box, centred
under it, as wide as the model's shadow may fall near it: its shadow fades out between 0.6 and
1 times ``FADE_RADII`` bounding radii from the centre (model-viewer fades its ground shadow too),
so the square's edge never shows."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

FADE_RADII = 3.0      # where the ground's shadow has faded out, in bounding-sphere radii (a 45-degree light
                      # casts a unit sphere's shadow out to 2.4 radii)


@dataclass(frozen=True)
class Ground:
    """``centre``: (3,) the square's centre on the plane y = centre[1]; ``half_size``: half its
    side; ``fade``: the distance from the centre where its shadow has faded out; ``bounds``:
    (centre (3,), radius) of a sphere holding the model and the shadowed part of the ground (what
    the shadow maps must cover)."""

    centre: np.ndarray
    half_size: float
    fade: float
    bounds: tuple[np.ndarray, float]


def ground_under(lo, hi, centre, radius: float) -> Ground:
    """The ground under a model with bounding box (``lo``, ``hi``) and bounding sphere
    (``centre``, ``radius``), all in world units."""
    lo = np.asarray(lo, np.float64)
    centre = np.asarray(centre, np.float64)
    radius = max(float(radius), 1e-6)
    fade = FADE_RADII * radius
    base = np.array([centre[0], lo[1], centre[2]])
    reach = max(radius, math.hypot(fade, centre[1] - lo[1]))
    return Ground(base, fade, fade, (centre, reach))
