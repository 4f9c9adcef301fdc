"""Plain scene state: camera, lights, display settings. Nothing here touches the GPU or the UI."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pyrr

from alight.core.ibl_models import DEFAULT_IBL_MODEL
from alight.core.material import Material
from alight.errors import AlightError

if TYPE_CHECKING:
    from alight.core.mesh import Mesh
    from alight.core.texture_maps import TextureMaps

VIEWS = ("camera", "probe")
TONEMAPS = ("none", "aces", "neutral")
BACKGROUNDS = ("env", "blur", "color", "transparent")
LIGHT_KINDS = ("point", "directional")


@dataclass
class Camera:
    position: tuple[float, float, float] = (0.0, 0.0, 4.0)
    target: tuple[float, float, float] = (0.0, 0.0, 0.0)
    up: tuple[float, float, float] = (0.0, 1.0, 0.0)
    fov_y_deg: float = 35.0
    near: float = 0.05
    far: float = 100.0

    def view_matrix(self) -> np.ndarray:
        """pyrr's row-vector layout: upload as is for GLSL's column-vector ``M * v``."""
        return pyrr.matrix44.create_look_at(np.array(self.position), np.array(self.target),
                                            np.array(self.up), dtype=np.float32)

    def projection_matrix(self, aspect: float) -> np.ndarray:
        return pyrr.matrix44.create_perspective_projection(self.fov_y_deg, aspect, self.near, self.far,
                                                           dtype=np.float32)

    def view_projection(self, aspect: float) -> np.ndarray:
        return pyrr.matrix44.multiply(self.view_matrix(), self.projection_matrix(aspect))


def frame_camera(center, radius: float, fov_y_deg: float = 35.0, aspect: float = 1.0,
                 direction=(0.0, 0.0, 1.0), margin: float = 1.3) -> Camera:
    """A camera on ``direction`` from ``center`` (default +Z, CONVENTIONS.md) that fits a sphere
    of ``radius`` in the narrower of the two fields of view."""
    half = math.radians(fov_y_deg) / 2.0
    half_narrow = min(half, math.atan(math.tan(half) * aspect))
    distance = margin * radius / math.sin(half_narrow)
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    c = np.asarray(center, dtype=np.float64)
    position = c + d * distance
    return Camera(tuple(position), tuple(c), (0.0, 1.0, 0.0), fov_y_deg,
                  near=max(distance - radius * 1.5, distance * 1e-3), far=distance + radius * 4.0)


@dataclass
class Light:
    kind: str = "point"                                   # 'point' or 'directional'
    vector: tuple[float, float, float] = (2.0, 3.0, 4.0)  # position, or the direction light travels
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    intensity: float = 10.0                               # point: radiant intensity; directional: irradiance


def _floats(text: str, n: int, what: str) -> tuple[float, ...]:
    try:
        values = tuple(float(x) for x in text.split(","))
    except ValueError:
        raise AlightError(f"--light: {what} '{text}' is not {n} comma-separated numbers") from None
    if len(values) != n or not all(math.isfinite(v) for v in values):
        raise AlightError(f"--light: {what} '{text}' is not {n} finite comma-separated numbers")
    return values


def parse_light(spec: str) -> Light:
    """``point:pos=X,Y,Z[:color=R,G,B][:intensity=I]`` or ``directional:dir=X,Y,Z[:...]``."""
    fields = spec.split(":")
    kind = {"point": "point", "dir": "directional", "directional": "directional", "sun": "directional"}.get(fields[0])
    if kind is None:
        raise AlightError(f"--light: '{spec}': the kind must be point or directional")
    light = Light(kind=kind, vector=(0.0, 0.0, 0.0) if kind == "point" else (0.0, -1.0, 0.0),
                  intensity=10.0 if kind == "point" else 3.0)
    for item in fields[1:]:
        key, _, value = item.partition("=")
        if key in ("pos", "position") and kind == "point":
            light.vector = _floats(value, 3, key)
        elif key in ("dir", "direction") and kind == "directional":
            light.vector = _floats(value, 3, key)
            if np.linalg.norm(light.vector) == 0.0:
                raise AlightError(f"--light: '{spec}': the direction is zero")
        elif key in ("color", "colour"):
            light.color = _floats(value, 3, key)
            if min(light.color) < 0:
                raise AlightError(f"--light: '{spec}': colour components must be >= 0")
        elif key == "intensity":
            (light.intensity,) = _floats(value, 1, key)
            if light.intensity < 0:
                raise AlightError(f"--light: '{spec}': intensity must be >= 0")
        else:
            raise AlightError(f"--light: '{spec}': unknown field '{key}' "
                              f"(point takes pos=, directional takes dir=; both take color= and intensity=)")
    return light


@dataclass
class Display:
    tonemap: str = "aces"
    exposure: float = 0.0                                    # EV: radiance times 2^EV before tone mapping
    background: str = "env"
    background_color: tuple[float, float, float] = (0.05, 0.05, 0.05)  # linear
    blur_roughness: float = 0.6


@dataclass
class Scene:
    """What to draw. ``material`` shades parts that have no material of their own; with
    ``use_file_materials`` false it shades every part, ignoring the file's materials."""

    mesh: "Mesh | None" = None
    material: Material = field(default_factory=Material)
    use_file_materials: bool = True
    material_overrides: dict = field(default_factory=dict)   # fields set on top of file materials
    lights: list[Light] = field(default_factory=list)
    camera: Camera | None = None                              # None: frame the mesh
    view: str = "camera"
    env_rotation_deg: float = 0.0
    env_intensity: float = 1.0
    ibl_enabled: bool = True
    ibl_model: str = DEFAULT_IBL_MODEL                        # a key of app/core/ibl_models.py's IBL_MODELS
    multiple_scattering: bool = False                         # Fdez-Aguera 2019 energy compensation
    display: Display = field(default_factory=Display)
    debug_view: int = 0        # 0: shaded; else an index of app/frontends/editor/state.py's DEBUG_VIEWS
    debug_mip: float = 0.0     # the prefiltered mip shown by that debug view
    # User-loaded maps for ``material`` (app/core/texture_maps.py: paths and UV tiling) and their
    # decoded images by path; parts shaded with a file's own material ignore them.
    texture_maps: "TextureMaps | None" = None
    texture_images: dict = field(default_factory=dict)
