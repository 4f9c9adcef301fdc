"""Lights that turn with the environment: when the artist turns the environment (Shift + right
drag, the rotation slider), each punctual light turns about +Y by the same angle, so a key light
placed at the sun of an HDR stays on it.

The environment's rotation is right-handed about +Y (docs/conventions.md: +90 degrees carries
the map's +X to world -Z), so its features move by R_y(+deg); a light moves by the same R_y.
Pure functions on alight.core.scene.Light.
"""

from __future__ import annotations

import dataclasses
import math

from alight.core.scene import Light


def rotate_y(v: tuple[float, float, float], deg: float) -> tuple[float, float, float]:
    """``v`` turned right-handedly about +Y by ``deg`` degrees: +90 takes +X to -Z."""
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    x, y, z = v
    return (x * c + z * s, y, -x * s + z * c)


def turn_lights(lights: list[Light], deg: float) -> list[Light]:
    """Each light turned about +Y through the origin by ``deg``: a directional light's direction,
    a point or spot light's position and a spot's aim. New Light objects (lights are replaced,
    never mutated: the view's redraw check compares them)."""
    return [dataclasses.replace(light, vector=rotate_y(light.vector, deg),
                                direction=rotate_y(light.direction, deg)) for light in lights]


def wrapped_delta(old_deg: float, new_deg: float) -> float:
    """The turn from ``old_deg`` to ``new_deg`` the shorter way round, in (-180, 180]: the
    rotation wraps at +-180 while the artist drags on."""
    d = (new_deg - old_deg) % 360.0
    return d - 360.0 if d > 180.0 else d
