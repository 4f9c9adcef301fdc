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
# The display curves, in tonemapping.glsl's TONEMAP_* order: 'aces' is Hill's fit (alight's
# default, as before), 'aces-hill' the same by the Sample Viewer's name; 'neutral' is Khronos PBR
# Neutral. docs/guides/users-files.md says which peer uses which by default.
TONEMAPS = ("none", "aces", "neutral", "aces-narkowicz", "aces-hill", "aces-hill-exposure-boost", "agx")
BACKGROUNDS = ("env", "blur", "color", "transparent")
LIGHT_KINDS = ("point", "directional", "spot")


# The clip planes of a Camera given none, where nothing fits them to a mesh (the renderer's
# own callers; alight.Renderer fits them, Camera.fit_clip).
DEFAULT_NEAR, DEFAULT_FAR = 0.05, 100.0


@dataclass
class Camera:
    """A pinhole (or orthographic) camera in world space: right-handed, +Y up, the default
    camera on +Z looking down -Z (docs/conventions.md). Lengths are in the mesh's units (glTF:
    metres), angles in degrees.

    - ``position``, ``target``: (x, y, z) of the eye and of the point it looks at; they must differ.
    - ``up``: (x, y, z), the direction that is up in the image; not parallel to target - position.
    - ``fov_y_deg``: the vertical field of view in degrees (the horizontal one follows from the
      image's aspect ratio); ignored when ``ortho_half_height`` is set.
    - ``near``, ``far``: the clip planes, distances from the eye along the view direction
      (0 < near < far); what lies outside is not drawn. None (the default): ``alight.Renderer``
      fits them to the mesh's bounding sphere at each render (``fit_clip``), so a 5 mm model
      and a 50 m one both show; a range that misses the whole mesh is said in one warning
      line. Elsewhere None is 0.05 and 100.
    - ``ortho_half_height``: an orthographic camera showing this half height (glTF's
      ``ymag``); None: perspective.

    ``alight.Renderer.set_camera(Camera(...))`` uses it; ``set_camera(orbit_deg=...)`` builds one
    that frames the mesh.
    """

    position: tuple[float, float, float] = (0.0, 0.0, 4.0)
    target: tuple[float, float, float] = (0.0, 0.0, 0.0)
    up: tuple[float, float, float] = (0.0, 1.0, 0.0)
    fov_y_deg: float = 35.0
    near: float | None = None
    far: float | None = None
    # glTF orthographic cameras: the view's half height (ymag); None: perspective (fov_y_deg).
    ortho_half_height: float | None = None

    def fit_clip(self, center, radius: float) -> tuple[float, float]:
        """(near, far) enclosing a sphere of ``radius`` at ``center`` seen from ``position``, with
        frame_camera's margins (room for a ground under the model); near stays above 1/10000 of
        far for the depth buffer's precision, also with the eye inside the sphere."""
        radius = max(float(radius), 1e-9)
        d = float(np.linalg.norm(np.asarray(self.position, np.float64) - np.asarray(center, np.float64)))
        far = d + radius * 4.0
        return max(d - radius * 1.5, far * 1e-4), far

    def view_matrix(self) -> np.ndarray:
        """pyrr's row-vector layout: upload as is for GLSL's column-vector ``M * v``."""
        return pyrr.matrix44.create_look_at(np.array(self.position), np.array(self.target),
                                            np.array(self.up), dtype=np.float32)

    def projection_matrix(self, aspect: float) -> np.ndarray:
        near = DEFAULT_NEAR if self.near is None else self.near
        far = DEFAULT_FAR if self.far is None else self.far
        if self.ortho_half_height is not None:
            h = self.ortho_half_height
            return pyrr.matrix44.create_orthogonal_projection(-h * aspect, h * aspect, -h, h, near, far,
                                                              dtype=np.float32)
        return pyrr.matrix44.create_perspective_projection(self.fov_y_deg, aspect, near, far, dtype=np.float32)

    def view_projection(self, aspect: float) -> np.ndarray:
        return pyrr.matrix44.multiply(self.view_matrix(), self.projection_matrix(aspect))


def fit_distance(center, radius: float, fov_y_deg: float, aspect: float, direction, corners=None,
                 margin: float = 1.3) -> float:
    """How far along ``direction`` from ``center`` a camera (up +Y) must stand to see the object
    with ``margin`` to spare: the sphere of ``radius`` in the narrower field of view, or, nearer
    where that is enough, every corner of its bounding box (``corners`` (8, 3)) in both fields
    of view. A long or flat object (a row of test tiles, a car) then fills a wide image instead of
    the sphere's square."""
    half = math.radians(fov_y_deg) / 2.0
    tan_y = math.tan(half)
    tan_x = tan_y * aspect
    distance = margin * radius / math.sin(min(half, math.atan(tan_x)))
    if corners is None:
        return distance
    d = np.asarray(direction, np.float64)
    d = d / np.linalg.norm(d)
    right = np.cross(-d, (0.0, 1.0, 0.0))
    if np.linalg.norm(right) < 1e-9:      # looking straight up or down: any right will do
        right = np.array([1.0, 0.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, -d)
    o = np.asarray(corners, np.float64) - np.asarray(center, np.float64)
    # corner at depth D - o.d in front of the camera: |o.right| <= (D - o.d) tan_x / margin
    need = o @ d + margin * np.maximum(np.abs(o @ right) / tan_x, np.abs(o @ up) / tan_y)
    return min(distance, float(need.max()))


def frame_camera(center, radius: float, fov_y_deg: float = 35.0, aspect: float = 1.0,
                 direction=(0.0, 0.0, 1.0), margin: float = 1.3, corners=None) -> Camera:
    """A camera on ``direction`` from ``center`` (default +Z, docs/conventions.md) that fits a sphere
    of ``radius`` in the narrower of the two fields of view, or the bounding box's ``corners``
    (8, 3) where they need less distance (``fit_distance``)."""
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    distance = fit_distance(center, radius, fov_y_deg, aspect, d, corners, margin)
    c = np.asarray(center, dtype=np.float64)
    position = c + d * distance
    return Camera(tuple(position), tuple(c), (0.0, 1.0, 0.0), fov_y_deg,
                  near=max(distance - radius * 1.5, distance * 1e-3), far=distance + radius * 4.0)


def default_camera(mesh, aspect: float) -> Camera:
    """The camera a scene without one gets: the mesh framed from +Z (docs/conventions.md), or a
    built-in preview mesh from its own 3/4 view (``Mesh.view``: orbit, elevation in degrees)."""
    center, radius = mesh.bounding_sphere()
    view = getattr(mesh, "view", None)
    if view is not None:
        return orbit_camera(center, max(radius, 1e-6), aspect, view[0], view[1], corners=mesh.corners())
    return frame_camera(center, max(radius, 1e-6), aspect=aspect, corners=mesh.corners())


def orbit_camera(center, radius: float, aspect: float, orbit_deg: float = 0.0, elevation_deg: float = 0.0,
                 distance: float | None = None, fov_y_deg: float = 35.0, target=None, corners=None) -> Camera:
    """A camera looking at ``target`` (default: ``center``) from a direction turned ``orbit_deg``
    about +Y from +Z (right-handed) and raised by ``elevation_deg``, at ``distance`` (default:
    the distance that frames a sphere of ``radius``, frame_camera's), with a vertical field of
    view of ``fov_y_deg`` degrees; ``corners``: the bounding box's (frame_camera). The near and
    far planes enclose the sphere."""
    a, e = math.radians(orbit_deg), math.radians(elevation_deg)
    direction = np.array([math.sin(a) * math.cos(e), math.sin(e), math.cos(a) * math.cos(e)])
    look_at = np.asarray(center if target is None else target, dtype=np.float64)
    framed = frame_camera(look_at, max(radius, 1e-6), fov_y_deg, aspect, direction, corners=corners)
    if distance is None:
        return framed
    position = look_at + direction * distance
    reach = float(np.linalg.norm(position - np.asarray(center, np.float64))) + max(radius, 1e-6)
    near = max(reach - 2.5 * max(radius, 1e-6), reach * 1e-4)
    up = (0.0, 1.0, 0.0) if abs(math.cos(e)) > 1e-6 else (0.0, 0.0, -math.copysign(1.0, math.sin(e)))
    return Camera(tuple(position), tuple(look_at), up, fov_y_deg, near=near, far=reach + max(radius, 1e-6) * 2.0)


@dataclass
class Light:
    """A punctual light (KHR_lights_punctual's three kinds). ``vector`` is the position (point,
    spot) or the direction light travels (directional); ``direction`` the direction a spot
    points. A spot's intensity falls off between ``inner_cone_deg`` and ``outer_cone_deg`` from
    its axis (the extension's recommended falloff); ``range`` (point, spot) windows the inverse
    square law to 0 at that distance, as the extension recommends (None: no cutoff)."""

    kind: str = "point"                                   # LIGHT_KINDS
    vector: tuple[float, float, float] = (2.0, 3.0, 4.0)  # position, or the direction light travels
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    intensity: float = 10.0                               # point, spot: intensity (/d^2); directional: irradiance
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)   # spot only
    inner_cone_deg: float = 0.0                           # spot only
    outer_cone_deg: float = 45.0                          # spot only
    range: float | None = None


# Where an added light sits, in units of the mesh's bounding radius from its centre: a point
# above, right and in front; a spot above and in front, pointing at the centre; a directional
# from the same side. Each gives the centre ``irradiance`` (W/m^2 on a surface facing it).
_ADDED_LIGHT_OFFSETS = {"point": (2.0, 2.0, 2.0), "spot": (0.0, 3.0, 3.0), "directional": (0.0, 1.0, 1.0)}


def added_light(kind: str, centre, radius: float, irradiance: float) -> Light:
    """A new light of ``kind`` that shows on a mesh of bounding sphere (``centre`` (3,),
    ``radius``) under a fill of ``irradiance``: placed at a fixed multiple of the radius (so a
    5 mm part and a 50 m building are lit alike) with the intensity that gives that irradiance
    at the centre (inverse square law). A fixed intensity at a fixed place barely showed under a
    bright environment and missed meshes far from the origin or of another size."""
    offset = np.asarray(_ADDED_LIGHT_OFFSETS[kind], np.float64) * max(float(radius), 1e-6)
    to_centre = -offset / np.linalg.norm(offset) + 0.0   # (+0.0: no '-0.000' in the panel)
    if kind == "directional":
        return Light("directional", tuple(float(x) for x in to_centre), (1.0, 1.0, 1.0), float(irradiance))
    position = tuple(float(x) for x in np.asarray(centre, np.float64) + offset)
    intensity = float(irradiance) * float(offset @ offset)
    if kind == "spot":
        return Light("spot", position, (1.0, 1.0, 1.0), intensity, direction=tuple(float(x) for x in to_centre),
                     inner_cone_deg=15.0, outer_cone_deg=30.0)
    return Light("point", position, (1.0, 1.0, 1.0), intensity)


def _floats(text: str, n: int, what: str, where: str = "--light") -> tuple[float, ...]:
    try:
        values = tuple(float(x) for x in text.split(","))
    except ValueError:
        raise AlightError(f"{where}: {what} '{text}' is not {n} comma-separated numbers") from None
    if len(values) != n or not all(math.isfinite(v) for v in values):
        raise AlightError(f"{where}: {what} '{text}' is not {n} finite comma-separated numbers")
    return values


# The fields that place each kind of light: parse_light refuses a spec without them.
_LIGHT_NEEDS = {"point": ("pos",), "spot": ("pos", "dir"), "directional": ("dir",)}


def parse_light(spec: str, where: str = "--light") -> Light:
    """``point:pos=X,Y,Z[:color=R,G,B][:intensity=I][:range=R]``, ``directional:dir=X,Y,Z[:...]``
    or ``spot:pos=X,Y,Z:dir=X,Y,Z[:inner=DEG][:outer=DEG][:...]`` (cone half-angles, default 0
    and 45 degrees, as KHR_lights_punctual's defaults). What places a light has no default and
    must be given: a point's ``pos``, a spot's ``pos`` and ``dir``, a directional light's ``dir``
    (a point at the origin sits inside the mesh and lights nothing: a black image, exit 0).

    Raises AlightError (one line naming the spec, after ``where``: the flag, or the API call) for
    an unknown kind or field, a bad number, or a missing required field."""
    fields = spec.split(":")
    kind = {"point": "point", "dir": "directional", "directional": "directional", "sun": "directional",
            "spot": "spot"}.get(fields[0])
    if kind is None:
        raise AlightError(f"{where}: '{spec}': the kind must be point, directional or spot")
    light = Light(kind=kind, vector=(0.0, -1.0, 0.0) if kind == "directional" else (0.0, 0.0, 0.0),
                  intensity=3.0 if kind == "directional" else 10.0)
    given = set()
    for item in fields[1:]:
        key, _, value = item.partition("=")
        given.add({"position": "pos", "direction": "dir"}.get(key, key))
        if key in ("pos", "position") and kind != "directional":
            light.vector = _floats(value, 3, key, where)
        elif key in ("dir", "direction") and kind != "point":
            direction = _floats(value, 3, key, where)
            if np.linalg.norm(direction) == 0.0:
                raise AlightError(f"{where}: '{spec}': the direction is zero")
            if kind == "spot":
                light.direction = direction
            else:
                light.vector = direction
        elif key in ("inner", "outer") and kind == "spot":
            (angle,) = _floats(value, 1, key, where)
            if not 0.0 <= angle <= 90.0:
                raise AlightError(f"{where}: '{spec}': {key} must be from 0 to 90 degrees")
            setattr(light, f"{key}_cone_deg", angle)
        elif key == "range" and kind != "directional":
            (light.range,) = _floats(value, 1, key, where)
            if light.range <= 0:
                raise AlightError(f"{where}: '{spec}': range must be > 0")
        elif key in ("color", "colour"):
            light.color = _floats(value, 3, key, where)
            if min(light.color) < 0:
                raise AlightError(f"{where}: '{spec}': colour components must be >= 0")
        elif key == "intensity":
            (light.intensity,) = _floats(value, 1, key, where)
            if light.intensity < 0:
                raise AlightError(f"{where}: '{spec}': intensity must be >= 0")
        else:
            raise AlightError(f"{where}: '{spec}': unknown field '{key}' (point takes pos=, directional "
                              f"dir=, spot pos=, dir=, inner=, outer=; all take color= and intensity=)")
    missing = [k for k in _LIGHT_NEEDS[kind] if k not in given]
    if missing:
        form = {"point": "point:pos=X,Y,Z", "directional": "directional:dir=X,Y,Z",
                "spot": "spot:pos=X,Y,Z:dir=X,Y,Z"}[kind]
        raise AlightError(f"{where}: '{spec}': a {kind} light needs {' and '.join(k + '=' for k in missing)} "
                          f"(the form is {form}[:...])")
    if kind == "spot" and light.inner_cone_deg >= light.outer_cone_deg:
        raise AlightError(f"{where}: '{spec}': inner must be below outer")
    return light


def light_spec(light: Light) -> str:
    """``light`` in ``--light``'s syntax: ``parse_light``'s inverse (it reads the spec back as the
    same light; numbers to 9 significant digits)."""
    def g(x: float) -> str:
        return f"{float(x):.9g}"

    def xyz(v) -> str:
        return ",".join(g(x) for x in v)

    if light.kind == "directional":
        spec = f"directional:dir={xyz(light.vector)}"
    elif light.kind == "spot":
        spec = (f"spot:pos={xyz(light.vector)}:dir={xyz(light.direction)}"
                f":inner={g(light.inner_cone_deg)}:outer={g(light.outer_cone_deg)}")
    else:
        spec = f"point:pos={xyz(light.vector)}"
    spec += f":color={xyz(light.color)}:intensity={g(light.intensity)}"
    if light.range is not None and light.kind != "directional":
        spec += f":range={g(light.range)}"
    return spec


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
    shadows: str = "auto"      # auto, on, off (alight.render.shadows: auto where something can be shadowed)
    ground: bool = False       # a shadow-catching ground under the model (alight.render.ground)
    debug_view: int = 0        # 0: shaded; else a DebugView (app/core/shader_names.py)
    debug_mip: float = 0.0     # the prefiltered mip shown by that debug view
    # User-loaded maps for ``material`` (app/core/texture_maps.py: paths and UV tiling) and their
    # decoded images by path; parts shaded with a file's own material ignore them.
    texture_maps: "TextureMaps | None" = None
    texture_images: dict = field(default_factory=dict)
    # Occlusion of the environment light by the mesh itself (alight.core.visibility): 'auto'
    # bakes it where the mesh occludes enough of itself (screen-space GTAO for a mesh too big to
    # bake), 'on' for every mesh but the built-in sphere, 'gtao' screen-space GTAO per frame
    # (alight.render.screen_ao), no bake. The still previews ('alight render', alight.Renderer) default to 'auto', and so
    # does the editor's 'occlusion' combo (its bake made by a child process,
    # app/frontends/editor/occlusion_bake.py); a bare Scene (batch) stays 'off'.
    occlusion: str = "off"
