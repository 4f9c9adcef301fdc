"""Compact, very bright sources (the sun, the moon, lamps, a spot) taken out of an environment
so the bake can add them back in closed form.

Sampling converges on such a source very slowly: quarry_01's sun holds half the map's power in
a few texels, and the prefilter's filtered importance sampling was still 5% off at r = 1 with
10,240 samples per texel (63% without filtering). As a delta light its contributions are exact:
irradiance P max(n.l, 0) / pi, the prefilter's integral P (n.l) D(h), SH coefficients P Y(l).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from alight.core.shading import equirect_uv_to_direction

# The choices, in one place: a source is what lies within SUN_RADIUS_DEG of the brightest texel
# above the surrounding sky; up to MAX_SUNS of them (shaders' MAX_SUNS) are taken out, brightest
# first, while each holds at least SUN_MIN_POWER_FRACTION of the map's power. Broader or weaker
# light is left to the sampling, which handles it well. (moonless_golf's lamps hold 14, 12, 7
# and 5.5% of its power; quarry_01's sun 48%.)
SUN_RADIUS_DEG = 3.0
SUN_RING_DEG = (3.0, 4.5)        # where the sky that fills the hole is measured
# A source is only compact if the map resolves its cone: texels at most SUN_RADIUS_DEG tall. A
# coarser map has none (a 2x1 map's two texels are hemispheres; taken as suns they turned a
# constant map into two point lights, irradiance 0.07-3.1 instead of 1).
_MIN_HEIGHT = int(np.ceil(180.0 / SUN_RADIUS_DEG))
SUN_MIN_POWER_FRACTION = 0.05
MAX_SUNS = 4


@dataclass(frozen=True)
class Sun:
    direction: np.ndarray   # (3,) unit, in the map's own frame
    power: np.ndarray       # (3,) RGB: the integral of the removed radiance over solid angle
    fraction: float         # of the map's total power (mean over RGB)
    texels: int
    spread: float = 0.0     # power-weighted RMS angle (radians) of the removed radiance from direction


@functools.lru_cache(maxsize=4)
def _omega(height: int, width: int) -> np.ndarray:
    """(H,) float32: one texel's solid angle on each row (as alight.core.shading.texel_directions)."""
    theta = (np.arange(height) + 0.5) / height * np.pi
    return ((2.0 * np.pi / width) * (np.pi / height) * np.sin(theta)).astype(np.float32)


def _band_directions(r0: int, r1: int, height: int, width: int) -> np.ndarray:
    """(r1 - r0, W, 3) float32 texel-centre directions of rows r0..r1 only: the search looks at a
    band a few degrees tall, so it never builds the whole map's (H, W, 3) directions."""
    rows = (np.arange(r0, r1) + 0.5) / height
    cols = (np.arange(width) + 0.5) / width
    return equirect_uv_to_direction(np.stack(np.meshgrid(cols, rows), axis=-1)).astype(np.float32)


def extract_suns(radiance: np.ndarray, max_count: int = MAX_SUNS) -> tuple[np.ndarray, list[Sun]]:
    """The radiance without its compact bright sources, and those sources (brightest first).
    Power is conserved: the returned map's power plus the sources' equals the map's.

    One copy of the map, one luminance image, updated in the few rows each source covers: the
    cost is a couple of passes over the map whatever the number of sources."""
    lum = radiance.mean(axis=2)
    h, w, _ = radiance.shape
    total = float((lum.sum(axis=1, dtype=np.float64) * _omega(h, w)).sum())
    suns: list[Sun] = []
    while len(suns) < max_count and total > 0.0:
        found = _find_sun(radiance, lum, total)
        if found is None:
            break
        if not suns:
            radiance = np.array(radiance, copy=True)   # the caller's map is never changed
        suns.append(_remove(radiance, lum, *found))
    return radiance, suns


def extract_sun(radiance: np.ndarray, total: float | None = None) -> tuple[np.ndarray, Sun | None]:
    """The brightest compact source, if it holds SUN_MIN_POWER_FRACTION of ``total`` (default:
    this map's power): the radiance without it, and it; else the radiance unchanged and None."""
    h, w, _ = radiance.shape
    lum = radiance.mean(axis=2)
    if total is None:
        total = float((lum.sum(axis=1, dtype=np.float64) * _omega(h, w)).sum())
    found = _find_sun(radiance, lum, total)
    if found is None:
        return radiance, None
    without = np.array(radiance, copy=True)
    return without, _remove(without, lum, *found)


def _remove(radiance: np.ndarray, lum: np.ndarray, sun: "Sun", r0: int, cone: np.ndarray,
            excess: np.ndarray) -> "Sun":
    """Take a found source's excess out of ``radiance`` rows r0.. in place, and out of ``lum``."""
    band = radiance[r0:r0 + cone.shape[0]]     # a view: the map changes in place
    band[cone] = band[cone] - excess
    lum[r0:r0 + cone.shape[0]] = band.mean(axis=2)
    return sun


_FLAT_TOP = 1.0 - 1e-3   # texels this close to the brightest are its equals
_EDGE_TEXELS = 1.5


def _cone_at(band: np.ndarray, band_dirs: np.ndarray, band_omega: np.ndarray, direction: np.ndarray,
             edge_texels: float, height: int):
    """The cone of SUN_RADIUS_DEG around ``direction`` within a band of rows of a map ``height``
    texels tall: (its mask, the excess radiance over the ring's sky inside it, that excess's power
    (3,), the excess-weighted centroid direction (3,)); None where no ring texel lies in the band
    to measure the sky.

    The cone and the ring reach ``edge_texels`` further: for a flat-topped source (a hard-edged
    disc) of radius SUN_RADIUS_DEG, _EDGE_TEXELS, so that it is taken whole at any resolution,
    with the texels its edge touches (with a cone of
    exactly its radius, the ring counted the edge texels of awkward_8198x4099.exr's 3-degree disc
    as sky and 12% of the disc stayed in the sampled map, a different share at each resolution)."""
    edge = edge_texels * 180.0 / height
    cos_to = band_dirs @ direction.astype(np.float32)
    cone = cos_to > np.cos(np.radians(SUN_RADIUS_DEG + edge))
    ring = ((cos_to <= np.cos(np.radians(SUN_RING_DEG[0] + edge)))
            & (cos_to > np.cos(np.radians(SUN_RING_DEG[1] + edge))))
    if not ring.any() or not cone.any():
        return None
    fill = (band[ring] * band_omega[ring, None]).sum(axis=0) / max(float(band_omega[ring].sum()), 1e-30)
    excess = np.maximum(band[cone] - fill, 0.0)
    power = (excess * band_omega[cone, None]).sum(axis=0)
    weights = excess.mean(axis=1) * band_omega[cone]
    centroid = (band_dirs[cone] * weights[:, None]).sum(axis=0, dtype=np.float64)
    norm = float(np.linalg.norm(centroid))
    centroid = centroid / norm if norm > 0.0 else direction
    return cone, excess, power, centroid


def _find_sun(radiance: np.ndarray, lum: np.ndarray, total: float):
    """The brightest compact source of ``radiance`` (``lum``: its mean over RGB) as (Sun, its
    first row, its cone mask over the rows from there, the excess radiance inside the cone);
    None if there is none worth taking. Changes nothing."""
    h, w, _ = radiance.shape
    if h < _MIN_HEIGHT or total <= 0.0:
        return None
    omega_rows = _omega(h, w)
    peak = np.unravel_index(np.argmax(lum), lum.shape)
    # The cone is centred on the brightest texels: on the one brightest texel of a real sun, but on
    # the middle of a flat top (equal texels, as a rendered disc or a clipped photo has), whose
    # first brightest texel lies on its edge. A cone centred there cut awkward_8198x4099.exr's
    # disc into four sources that changed with the map's resolution.
    reach = int(np.ceil(np.radians(SUN_RING_DEG[1] + 2.0 * SUN_RADIUS_DEG) / np.pi * h + 2 * _EDGE_TEXELS)) + 1
    r0, r1 = max(0, peak[0] - reach), min(h, peak[0] + reach + 1)
    band, band_dirs = radiance[r0:r1], _band_directions(r0, r1, h, w)
    band_omega = np.broadcast_to(omega_rows[r0:r1, None], band.shape[:2])
    to_peak = band_dirs[peak[0] - r0, peak[1]]
    # a source that fits the cone fits within its diameter of any of its texels
    near_peak = band_dirs @ to_peak > np.cos(np.radians(2.0 * SUN_RADIUS_DEG))
    top = near_peak & (lum[r0:r1] >= lum[peak] * _FLAT_TOP)
    direction = (band_dirs[top] * band_omega[top, None]).sum(axis=0, dtype=np.float64)
    direction = direction / np.linalg.norm(direction)
    # A flat top has a hard edge, whose texels are the same disc's partial cover: the cone takes
    # them too. A real sun's one brightest texel and soft falloff keep the cone as it was.
    edge_texels = _EDGE_TEXELS if int(top.sum()) > 1 else 0.0
    found = _cone_at(band, band_dirs, band_omega, direction, edge_texels, h)
    if found is None:
        return None
    cone, excess, power, direction = found
    fraction = float(power.mean()) / total
    if fraction < SUN_MIN_POWER_FRACTION:
        return None
    weights = excess.mean(axis=1) * band_omega[cone]
    angle = np.arccos(np.clip(np.einsum("ij,j->i", band_dirs[cone], direction), -1.0, 1.0))
    spread = float(np.sqrt((weights * angle * angle).sum() / max(float(weights.sum()), 1e-30)))
    sun = Sun(direction.astype(np.float64), power.astype(np.float64), fraction, int(cone.sum()), spread)
    return sun, r0, cone, excess
