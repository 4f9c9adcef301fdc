"""Environment maps: loading, validation and repair of equirectangular files, and the built-in studio.

Every environment is an (H, W, 3) float32, C-contiguous array of linear scene-referred RGB
radiance with W == 2*H, in [0, RADIANCE_MAX] (1e10), row 0 at the top (+Y); the mapping between
texels and directions is docs/conventions.md's (see ``alight.core.shading.direction_to_equirect_uv``).

Files are read by ``alight.exchange.environment_files`` (oriented as the file says, the display
window as the picture, the first part with R, G, B; in strips, repaired, box-reduced when wider
than ``max_width``); every problem with a file becomes one ``AlightError`` line
naming the file first, every repair one warning line.
"""

from __future__ import annotations

import hashlib
import math
import os
from dataclasses import dataclass, field

import numpy as np

from alight.core.shading import texel_directions
from alight.errors import AlightError
from alight.exchange.environment_files import RADIANCE_MAX, Repairs, read_equirect, repair_radiance

MAX_WIDTH = 4096


@dataclass(eq=False)
class Environment:
    """An equirectangular environment ready to bake (see the module docstring for the invariants)."""

    radiance: np.ndarray  # (H, W, 3) float32, linear RGB, W == 2*H, in [0, RADIANCE_MAX], C-contiguous
    name: str  # 'studio', 'constant', or the file path
    warnings: list[str] = field(default_factory=list)  # repairs made, one line each
    _hash: str | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        # The loader repairs files; an array handed in directly (the Python API takes one) gets
        # the same repair here, on a copy, so NaN or 1e30 never reaches the bake's mips.
        rad = np.asarray(self.radiance)
        if rad.size and not (np.isfinite(rad).all() and 0.0 <= rad.min() and rad.max() <= RADIANCE_MAX):
            repairs = Repairs()
            self.radiance = repair_radiance(np.array(rad, dtype=np.float32, order="C"), repairs)
            self.warnings = [*self.warnings, *repairs.lines(self.name)]

    @property
    def content_hash(self) -> str:
        """sha256 hex digest of the radiance's shape and bytes (the bake cache key); computed once."""
        if self._hash is None:
            h = hashlib.sha256()
            h.update(repr(tuple(self.radiance.shape)).encode())
            h.update(np.ascontiguousarray(self.radiance, dtype=np.float32).tobytes())
            self._hash = h.hexdigest()
        return self._hash

    @property
    def width(self) -> int:
        return int(self.radiance.shape[1])

    @property
    def height(self) -> int:
        return int(self.radiance.shape[0])


# --------------------------------------------------------------------------------------------
# Loading files
# --------------------------------------------------------------------------------------------

def load_environment(spec: str, max_width: int = MAX_WIDTH) -> Environment:
    """'studio' (the built-in studio) or the path of an equirect file OpenImageIO can read.

    Raises AlightError (one line: file then problem) for a missing, unreadable, corrupt,
    truncated or empty file, a picture that is not 2:1, or one without R, G, B or Y channels.
    Y (grey) is replicated to RGB; alpha and other channels are dropped; the file's orientation
    and display window are applied. NaN/Inf/negative texels are set to 0, texels above
    RADIANCE_MAX clamped to it, maps wider than ``max_width`` box-reduced, and the part taken
    from a multi-part file named: each a warning line.
    """
    if str(spec) == "studio":
        return studio_environment()
    if not str(spec).strip():
        raise AlightError("environment: the path is empty ('studio', or an equirectangular .hdr/.exr file)")
    path = os.fspath(spec)
    if max_width < 2:
        raise ValueError("max_width must be >= 2")
    try:
        radiance, warnings = read_equirect(path, max_width)
        return Environment(radiance, path, warnings)
    except AlightError as e:
        raise AlightError(str(e)) from None
    except MemoryError:
        raise AlightError(f"{path}: not enough memory to read the environment map") from None
    except Exception as e:  # anything OIIO or numpy throws: one line, no traceback
        raise AlightError(f"{path}: cannot read environment map ({' '.join(str(e).split()) or type(e).__name__})") from None


# --------------------------------------------------------------------------------------------
# Procedural environments
# --------------------------------------------------------------------------------------------

def constant_environment(value=1.0, width: int = 64) -> Environment:
    """A uniform environment of radiance `value` (scalar or RGB), width x width/2 (the white furnace)."""
    if width < 2 or width % 2:
        raise ValueError("width must be an even number >= 2")
    v = np.broadcast_to(np.asarray(value, dtype=np.float32), (3,))
    if not np.all(np.isfinite(v)) or np.any(v < 0):
        raise ValueError(f"constant radiance must be finite and >= 0, got {value!r}")
    rad = np.empty((width // 2, width, 3), dtype=np.float32)
    rad[...] = v
    return Environment(rad, "constant", [])


# The studio, one table. Directions are world directions (docs/conventions.md: +Y up, the camera on
# +Z looking toward -Z at the subject at the origin). Angles in degrees; radiance linear RGB.
# Each soft box is a rectangle centred on `dir`, `half` = (half-width, half-height) measured as
# angles in the plane of its own frame (right = up_hint x dir, up = dir x right), with
# smoothstep edges `soft` degrees wide on each side of the edge, and a mild hotspot (the centre
# is `hotspot` times brighter than the edge of the plateau, falling off quadratically).
# Levels chosen so that the default 0.8-grey ball sits in ACES's mid-range with visible
# highlights at exposure 0, rather than clipping to white.
STUDIO = {
    # background: a vertical profile over elevation e (degrees, +90 = up)
    "ceiling_zenith": (0.06, 0.06, 0.065),   # straight up (a dark studio ceiling)
    "backdrop_horizon": (0.22, 0.22, 0.22),  # the grey backdrop at eye level
    "backdrop_falloff_deg": 40.0,            # backdrop -> ceiling, smoothstep over 0..this
    "horizon_soft_deg": 2.0,                 # backdrop/floor seam half-width
    "floor_horizon": (0.11, 0.107, 0.104),    # floor seen at grazing angles
    "floor_nadir": (0.025, 0.025, 0.025),    # floor straight down (under the subject, shadowed)
    "softboxes": [
        # name, centre direction, up hint, (half w, half h), soft edge, radiance, hotspot
        {"name": "key", "dir": (-1.0, 0.75, 1.0), "up_hint": (0.0, 1.0, 0.0),
         "half": (20.0, 14.0), "soft": 4.0, "radiance": (6.0, 5.8, 5.5), "hotspot": 1.12},
        {"name": "strip", "dir": (1.0, 0.12, -0.35), "up_hint": (0.0, 1.0, 0.0),
         "half": (5.0, 32.0), "soft": 2.5, "radiance": (3.2, 3.3, 3.45), "hotspot": 1.06},
        {"name": "top", "dir": (0.0, 1.0, -0.15), "up_hint": (0.0, 0.0, -1.0),
         "half": (18.0, 18.0), "soft": 6.0, "radiance": (1.6, 1.6, 1.6), "hotspot": 1.10},
    ],
}


def mean_irradiance(radiance: np.ndarray) -> float:
    """The irradiance an equirect map (H, W, 3) gives a surface, averaged over every facing:
    pi times its solid-angle weighted mean radiance (the mean of cos+ over the sphere is 1/4),
    the mean of the three channels. W/m^2 for radiance in W/(m^2 sr)."""
    h = radiance.shape[0]
    weight = np.sin((np.arange(h) + 0.5) / h * np.pi)
    rows = radiance.mean(axis=(1, 2), dtype=np.float64)
    return float(np.pi * (rows * weight).sum() / weight.sum())


def _smoothstep(e0, e1, x):
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def studio_environment(width: int = 1024) -> Environment:
    """The built-in photo studio (the default environment): deterministic, vectorised numpy.

    Layout (world directions; the camera is on +Z looking toward -Z, the subject at the origin):
    - background: a grey backdrop at the horizon (radiance ~0.42) that fades to a dark ceiling
      (~0.06) toward the zenith; below a soft seam at the horizon, a floor ~0.2 at grazing
      angles that darkens toward the nadir (~0.025);
    - ``key``: the big soft box (40 x 28 degrees, radiance ~16) in front of the subject, up and
      to the camera's left, centred on normalize(-1, 0.75, 1) (azimuth 45 degrees left of the
      camera, 28 degrees up). A mirror ball shows it in its upper-left quadrant;
    - ``strip``: a tall thin strip light (10 x 64 degrees, ~9, slightly cool) on the right side
      (+X), a little behind the subject (toward -Z): a rim light on the ball's right edge;
    - ``top``: a square overhead box (36 x 36 degrees, ~5.5) straight above, tilted slightly
      back (toward -Z).
    Parameters are in the ``STUDIO`` table at the top of this section.
    """
    if width < 4 or width % 2:
        raise ValueError("width must be an even number >= 4")
    height = width // 2
    dirs, _ = texel_directions(height, width)
    dirs = dirs.astype(np.float32)
    p = STUDIO

    # Background profile by row (elevation only).
    elev = 90.0 - (np.arange(height) + 0.5) * (180.0 / height)  # degrees, per row
    ceil_c = np.asarray(p["ceiling_zenith"], np.float64)
    back_c = np.asarray(p["backdrop_horizon"], np.float64)
    floor_h = np.asarray(p["floor_horizon"], np.float64)
    floor_n = np.asarray(p["floor_nadir"], np.float64)
    t_up = _smoothstep(0.0, p["backdrop_falloff_deg"], np.maximum(elev, 0.0))[:, None]
    upper = back_c * (1.0 - t_up) + ceil_c * t_up
    t_dn = (np.clip(-elev, 0.0, 90.0) / 90.0) ** 0.6
    lower = floor_h * (1.0 - t_dn[:, None]) + floor_n * t_dn[:, None]
    s = p["horizon_soft_deg"]
    seam = _smoothstep(-s, s, elev)[:, None]
    profile = (lower * (1.0 - seam) + upper * seam).astype(np.float32)  # (H, 3)
    rad = np.empty((height, width, 3), dtype=np.float32)
    rad[...] = profile[:, None, :]

    for box in p["softboxes"]:
        c = np.asarray(box["dir"], np.float64)
        c /= np.linalg.norm(c)
        right = np.cross(np.asarray(box["up_hint"], np.float64), c)
        right /= np.linalg.norm(right)
        up = np.cross(c, right)
        hw, hh = box["half"]
        soft = box["soft"]
        # Only texels within the box's bounding cone (corner + soft edge) need the work below.
        reach = math.radians(min(89.0, math.hypot(hw + soft, hh + soft)))
        flat = rad.reshape(-1, 3)
        fdirs = dirs.reshape(-1, 3)
        idx = np.flatnonzero(fdirs @ c.astype(np.float32) > math.cos(reach))
        local = fdirs[idx] @ np.stack([right, up, c], axis=1).astype(np.float32)  # right, up, centre
        z = local[:, 2]
        ax = np.degrees(np.arctan2(np.abs(local[:, 0]), z))
        ay = np.degrees(np.arctan2(np.abs(local[:, 1]), z))
        mask = _smoothstep(hw + soft, hw - soft, ax) * _smoothstep(hh + soft, hh - soft, ay)
        r2 = np.minimum((ax / hw) ** 2 + (ay / hh) ** 2, 2.0) / 2.0
        gain = box["hotspot"] - (box["hotspot"] - 1.0) * r2
        # A soft box hangs in front of the backdrop: blend over it rather than add.
        cover = mask.astype(np.float32)[:, None]
        lum = (mask * gain).astype(np.float32)[:, None] * np.asarray(box["radiance"], np.float32)
        flat[idx] = flat[idx] * (1.0 - cover) + lum

    rad = np.ascontiguousarray(np.maximum(rad, 0.0), dtype=np.float32)
    return Environment(rad, "studio", [])
