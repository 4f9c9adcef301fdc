"""The Python API: one object that renders materials headless, without the CLI.

    from alight import Renderer

    with Renderer(width=256, height=256, quality="low") as r:
        r.set_environment("studio")
        for name in ("gold", "copper", "silver"):
            r.set_material(name)
            r.save(f"{name}.png")

The GL context and shader programs are created once (on the first render); bakes are cached
per environment content and quality by ``alight.render.renderer.ForwardRenderer``, so any number of
materials under one environment cost one bake. Leaving the ``with`` block (or ``close()``)
releases every GPU resource.
"""

from __future__ import annotations

import contextlib
import functools
import os
from pathlib import Path
from typing import Iterable, Literal

import numpy as np

from alight.core.material import Material, validate_material, with_overrides
from alight.core.mesh import Mesh, select_variant
from alight.core.texture_maps import TextureMaps
from alight.core.scene import (
    BACKGROUNDS,
    TONEMAPS,
    Camera,
    Display,
    Light,
    Scene,
    parse_light,
)
from alight.errors import AlightError, warn
from alight.frontends.scene_setup import framing_warnings, load_scene_environment, load_scene_mesh
from alight.ibl.environment import Environment, load_environment

Quality = Literal["low", "medium", "high", "auto"]
MESH_SHADING = ("auto", "forward", "vbuffer")   # alight.render.vbuffer.MESH_SHADING (not imported: it imports moderngl)
AA = Literal["none", "msaa", "ssaa"]


class Renderer:
    """A headless renderer with its own scene state.

    Parameters are the defaults for ``render()``; every ``set_*`` method returns ``self`` so
    calls can be chained. Nothing touches the GPU until the first render (or ``open()``).
    ``mesh_shading`` (also an attribute): how a mesh file is shaded under msaa, 'auto' (the
    default: from a visibility buffer where the mesh has under 3 estimated covered pixels per
    triangle, alight.render.vbuffer), 'forward' or 'vbuffer'.
    """

    def __init__(self, width: int = 512, height: int | None = None, *, quality: Quality | str = "medium",
                 aa: AA = "msaa", tonemap: str = "aces", exposure: float = 0.0, background: str = "env",
                 error_budget: float = 0.02, mesh_shading: str = "auto"):
        self.width, self.height = _size(width, width if height is None else height)
        # What reset() goes back to (the pytest plugin's fixture resets the shared renderer per test).
        self._initial = dict(width=self.width, height=self.height, quality=quality, aa=aa, tonemap=tonemap,
                             exposure=exposure, background=background, error_budget=float(error_budget),
                             mesh_shading=mesh_shading)
        self.quality = quality
        # quality="auto": app/accuracy/auto_quality.py chooses per render within this error budget (a
        # fraction); the last choice is kept in self.last_auto_choice.
        self.error_budget = float(error_budget)
        self.last_auto_choice = None
        self.last_texture_set = None   # the assignment of the last set_material(texture_set=...)
        self._features: dict[str, object] = {}
        self.aa: str = aa
        # How mesh files are shaded under msaa (alight.render.vbuffer): 'auto' (the visibility
        # buffer where the mesh is dense on screen), 'forward' or 'vbuffer'; read at each render.
        if mesh_shading not in MESH_SHADING:
            raise AlightError(f"mesh_shading: {mesh_shading!r} is not one of {', '.join(MESH_SHADING)}")
        self.mesh_shading: str = mesh_shading
        self._renderer = None  # alight.render.renderer.ForwardRenderer, created lazily: importing moderngl is not free
        # close() was called: a later render raises rather than silently open a context nobody releases.
        self._closed = False
        self.bakes_done = 0    # how many bakes actually ran (misses of the memory and disk caches)
        self._mesh: Mesh | None = None
        self._frame_of: tuple | None = None   # (mesh, its _mesh_frame), for the mesh it was made of
        self._sphere: Mesh | None = None   # the constructor's mesh, kept so reset() need not rebuild it
        self._framing_checked: Mesh | None = None   # the mesh framing_warnings last looked at
        # set_camera(orbit_deg=...)'s arguments: the camera is framed at each render, for that
        # render's size and the mesh of that moment (None: no orbit camera).
        self._orbit: dict | None = None
        self.reset()

    def reset(self) -> "Renderer":
        """Go back to the constructor's state: its size, quality, aa, mesh_shading and display
        (tonemap, exposure, background), the built-in sphere, the default material with no maps
        and no field overrides (a mesh file's own materials on), the default camera, the studio
        environment (no rotation, intensity 1), no lights, the camera view, the default IBL model,
        shadows, ground and occlusion. The GL context, the programs, the bakes and the loaded
        meshes are kept, so a reset costs no bake of the studio again (``bakes_done`` goes on
        counting). The pytest plugin's ``alight_renderer`` fixture resets before each test."""
        init = self._initial
        self.width, self.height = init["width"], init["height"]
        self.quality, self.aa, self.mesh_shading = init["quality"], init["aa"], init["mesh_shading"]
        self.error_budget = init["error_budget"]
        self.last_auto_choice = None
        self.last_texture_set = None
        self._orbit = None
        self._framing_checked = None
        self._env = _studio()   # the one shared studio: its content hash finds the bake already made
        self.scene = Scene(mesh=None, material=Material(), use_file_materials=True, ibl_enabled=True,
                           display=Display(), occlusion="auto")
        self.set_display(tonemap=init["tonemap"], exposure=init["exposure"], background=init["background"])
        if self._sphere is None:
            self._sphere = load_scene_mesh("sphere", warn)
        return self.set_mesh(self._sphere)

    # --- lifetime ------------------------------------------------------------------------

    def open(self) -> "Renderer":
        """Create the EGL context and programs now rather than on the first render; after
        ``close``, a fresh context (``with r:`` again does the same), released by the next close."""
        self._closed = False
        if self._renderer is None:
            from alight.render.renderer import ForwardRenderer

            with _keep_current_context():
                self._renderer = ForwardRenderer()
        return self

    def close(self) -> None:
        """Release the GPU resources (bakes, meshes, targets, programs, the context). Idempotent.
        A render after it raises alight.Error until ``open`` (or ``with r:``) opens it again:
        rendering would otherwise open a new context that nothing releases."""
        self._closed = True
        r, self._renderer = self._renderer, None
        if r is not None:
            with _keep_current_context():
                r.release()     # its own context too (alight.render.renderer)

    @property
    def is_open(self) -> bool:
        return self._renderer is not None

    def __enter__(self) -> "Renderer":
        return self.open()

    def __exit__(self, *exc) -> None:
        self.close()

    # --- scene state ---------------------------------------------------------------------

    def set_mesh(self, mesh: str | os.PathLike | Mesh, *, variant: str | None = None) -> "Renderer":
        """'sphere', 'cube', 'plane', 'shader_ball', 'rounded_cube', 'drape', a mesh file (.obj .gltf .glb .ply .stl), or a loaded Mesh.
        What the file is drawn without is said as an ``alight.AlightWarning`` each (a Python
        warning: alight.errors.warn); the file's own lines stay in ``self.mesh.warnings``.

        The material is left as it is, as ``alight render``'s flags combine whatever their order: a
        file's own materials are drawn unless a material, texture set or maps was given to
        ``set_material`` (then that material is drawn on every part: ``set_material("gold")``
        then ``set_mesh("Duck.glb")`` is a gold duck, as ``alight render --mesh Duck.glb --preset
        gold``); ``set_material(use_file_materials=True)`` or ``reset()`` gives the file's own back.
        The camera (None or an orbit) is framed for the new mesh at the next render.

        ``variant``: a glTF file's material variant (KHR_materials_variants) to draw, by name, as
        ``alight render --variant NAME`` (``set_variant`` switches it later; the names are
        ``r.mesh.variants``). An error of one line where the file has no variants or no such name."""
        if isinstance(mesh, Mesh):
            self._mesh = mesh if variant is None else select_variant(mesh, variant)
            for line in mesh.warnings:
                warn(line)
        else:
            loaded = load_scene_mesh(os.fspath(mesh), warn)
            self._mesh = loaded if variant is None else select_variant(loaded, variant)
        self._frame_of = None   # made again even for the same Mesh: its vertices may have been edited
        self.scene.mesh = self._mesh
        return self

    def set_variant(self, name: str | None) -> "Renderer":
        """Draw the current mesh's material variant ``name`` (KHR_materials_variants; the names
        are ``r.mesh.variants``), or with None each part's own material again. Only the parts'
        materials change: the geometry is the same arrays, and the camera's framing is kept. An
        error of one line (AlightError) where the mesh has no variants or no such name, listing
        the names it has."""
        if self._mesh is None:
            raise AlightError("set_variant: no mesh is set (set_mesh first)")
        chosen = select_variant(self._mesh, name)
        if self._frame_of is not None and self._frame_of[0] is self._mesh:
            self._frame_of = (chosen, self._frame_of[1])   # the same vertices: the same frame
        if self._framing_checked is self._mesh:
            self._framing_checked = chosen
        self._mesh = chosen
        self.scene.mesh = chosen
        return self

    def set_environment(self, env: str | os.PathLike | Environment | None, *, rotation_deg: float | None = None,
                        intensity: float | None = None) -> "Renderer":
        """'studio', an equirectangular .hdr/.exr, a loaded Environment, or None (no IBL)."""
        if env is None or isinstance(env, Environment):
            self._env = env
            for line in env.warnings if env is not None else ():
                warn(line)
        elif os.fspath(env) == "studio":
            self._env = _studio()   # built in: nothing to warn about
        else:   # what was repaired or clamped is said (alight.errors.warn: an AlightWarning)
            self._env = load_scene_environment(os.fspath(env), warn)
        self.scene.ibl_enabled = self._env is not None
        if rotation_deg is not None:
            self.scene.env_rotation_deg = float(rotation_deg)
        if intensity is not None:
            if not intensity >= 0:
                raise AlightError(f"intensity: {intensity} must be >= 0")
            self.scene.env_intensity = float(intensity)
        return self

    @property
    def environment(self) -> Environment | None:
        return self._env

    def set_material(self, material: Material | str | os.PathLike | None = None, *,
                     maps: TextureMaps | dict[str, str] | None = None,
                     texture_set: str | os.PathLike | Iterable[str | os.PathLike] | None = None,
                     use_file_materials: bool | None = None, **fields) -> "Renderer":
        """A Material, a preset name, a preset .json or a .gltf/.glb file (its first material
        with its maps); keyword fields (``roughness=0.3``) on top: any name of
        ``alight.core.material_fields.NAMES`` (the fields of ``alight render``'s material flags
        and of a batch spec's materials; colours as (R, G, B) linear), and ``name``.

        ``texture_set``: a folder of maps, or a list of files, assigned to slots by their names
        (alight.exchange.texture_sets; the assignment is kept in ``last_texture_set``).
        ``maps``: a TextureMaps, or {slot: path} with the slots of ``alight render --map``
        (base_color, metallic_roughness, metallic, roughness, normal, emissive, occlusion,
        normal_dx, gloss, orm), applied after the set. The slots these load get factor 1
        (glTF's convention) before ``fields`` apply. A new material without maps clears the
        maps; with no material, only fields, the current material and maps are edited.

        A material, a texture set or maps given here replace a mesh file's own materials on every
        part unless ``use_file_materials`` is True, whether set before or after ``set_mesh``, as
        ``alight render --mesh Duck.glb --preset gold`` draws a gold duck. Fields given with no
        material edit the current material and, where a file's own materials are drawn, apply on
        top of them too (kept in ``scene.material_overrides`` until a new material or ``reset``),
        as ``alight render --mesh Duck.glb --roughness 0.2`` does: ``set_material(roughness=0.2)``
        on the duck keeps its texture and changes its roughness, never nothing.
        Errors: AlightError of one line (a bad slot, a missing file).
        """
        from alight.core.material_fields import NAMES
        from alight.core.texture_maps import map_factors
        from alight.exchange.material_files import API_MESH_HINT, load_material_file

        for key in fields:
            if key not in NAMES and key != "name":
                import difflib

                close = difflib.get_close_matches(key, [*NAMES, "name"], n=1)
                hint = f"did you mean {close[0]!r}? " if close else ""
                raise AlightError(f"set_material: unknown field {key!r} ({hint}the fields: {', '.join(NAMES)}, name)")
        from alight.exchange.texture_sets import apply_map, assign_files, assign_folder, load_map_images

        current = self.scene.texture_maps
        if material is None:
            base = self.scene.material
        elif isinstance(material, Material):
            base, current = validate_material(material), None
        else:
            base, current, warnings = load_material_file(material, mesh_hint=API_MESH_HINT)
            for line in warnings:
                warn(line)
        loaded: set[str] = set()
        if texture_set is not None:
            if isinstance(texture_set, (str, os.PathLike)):
                found = assign_folder(texture_set, current)
            else:
                found = assign_files(list(texture_set), current)
            for entry in found.notes():
                warn(f"texture set: {entry}")
            self.last_texture_set = found
            current = found.maps
            loaded.update(found.slots)
        if isinstance(maps, TextureMaps):
            current = maps
            loaded.update(maps.paths())
        elif maps is not None:
            for name, path in dict(maps).items():
                current, slots = apply_map(current or TextureMaps(), str(name), os.fspath(path), f"maps[{name!r}]")
                loaded.update(slots)
        if loaded:
            base = with_overrides(base, **map_factors(loaded))
        self.scene.material = with_overrides(base, **fields) if fields else base
        if material is not None:
            self.scene.material_overrides = {}
        elif fields:   # on the file's own materials too (app/render/variants.py part_material), as the CLI's flags
            self.scene.material_overrides = {**self.scene.material_overrides,
                                             **{k: v for k, v in fields.items() if k != "name"}}
        if current is not None and current.paths():
            self.scene.texture_maps, self.scene.texture_images = current, load_map_images(current)
        else:
            self.scene.texture_maps, self.scene.texture_images = None, {}
        if use_file_materials is not None:
            self.scene.use_file_materials = bool(use_file_materials)
        elif material is not None or self.scene.texture_maps is not None:
            self.scene.use_file_materials = False
        return self

    @property
    def texture_maps(self) -> TextureMaps | None:
        """The material's maps (None: none)."""
        return self.scene.texture_maps

    @property
    def material(self) -> Material:
        return self.scene.material

    def set_lights(self, lights: Iterable[Light | str]) -> "Renderer":
        """Punctual lights: Light objects or CLI specs such as 'point:pos=2,3,4:intensity=30'."""
        self.scene.lights = [parse_light(x, "set_lights") if isinstance(x, str) else x for x in lights]
        return self

    def set_shadows(self, mode: str | None = None, *, ground: bool | None = None,
                    occlusion: str | None = None) -> "Renderer":
        """Shadow maps for the lights and the environment's suns: ``mode`` 'auto' (the default:
        only where something can be shadowed, never for a convex mesh such as the built-in
        sphere), 'on' or 'off' (alight.render.shadows). ``ground``: a shadow-catching ground under
        the model's bounding box (alight.render.ground): it darkens the background by the model's
        shadow, or with background 'transparent' leaves the shadow in alpha. ``occlusion``: as
        ``set_occlusion``."""
        if mode is not None:
            if mode not in ("auto", "on", "off"):
                raise AlightError(f"shadows: {mode!r} is not one of auto, on, off")
            self.scene.shadows = mode
        if ground is not None:
            self.scene.ground = bool(ground)
        if occlusion is not None:
            self.set_occlusion(occlusion)
        return self

    def add_light(self, light: Light | str) -> "Renderer":
        """Add one punctual light to those already set (``set_lights`` replaces them; ``reset``
        removes them): an ``alight.Light`` or a spec as ``alight render --light`` takes:
        ``point:pos=X,Y,Z[:color=R,G,B][:intensity=I][:range=R]``,
        ``directional:dir=X,Y,Z[:...]`` (the direction the light travels) or
        ``spot:pos=X,Y,Z:dir=X,Y,Z[:inner=DEG][:outer=DEG][:...]`` (cone half-angles in degrees).
        Positions in the mesh's units (world space, +Y up), colours linear R, G, B;
        ``intensity`` is divided by the squared distance for a point or spot light (default 10)
        and is the irradiance of a directional one (default 3). Lights add to the environment's
        light (``set_environment(None)`` for lights alone). Raises AlightError of one line
        naming add_light and the spec (an unknown kind or field, a bad number, a missing
        ``pos``/``dir``)."""
        self.scene.lights.append(parse_light(light, "add_light") if isinstance(light, str) else light)
        return self

    def set_camera(self, camera: Camera | None = None, *, orbit_deg: float | None = None,
                   elevation_deg: float = 0.0, distance: float | None = None, fov_deg: float = 35.0,
                   target=None) -> "Renderer":
        """A Camera, None (frame the mesh from +Z, a built-in from its 3/4 view, Mesh.view), or
        ``orbit_deg``: look at ``target`` (x, y, z; default: the mesh's centre) from a direction
        turned that many degrees about +Y from +Z (right-handed), raised by ``elevation_deg``, at
        ``distance`` (scene units; default: framing the mesh), with a vertical field of view of
        ``fov_deg`` degrees. Like None, the orbit camera is framed at each render, for that
        render's size (``render(w, h)``, not the constructor's) and the mesh set at that time,
        so a later ``set_mesh`` is framed too. A Camera is used as given, except that a
        near or far plane left unset (None) is fitted to the mesh at render (alight.Camera).
        A mesh file's own cameras are ``r.mesh.cameras`` (glTF). Raises AlightError for a
        non-finite angle, distance or field of view."""
        if orbit_deg is not None:
            values = {"orbit_deg": orbit_deg, "elevation_deg": elevation_deg, "fov_deg": fov_deg}
            if distance is not None:
                values["distance"] = distance
            for name, value in values.items():
                try:
                    ok = np.isfinite(float(value))
                except (TypeError, ValueError):
                    ok = False
                if not ok:
                    raise AlightError(f"set_camera: {name}={value!r} is not a finite number")
            if not 0.0 < float(fov_deg) < 180.0:
                raise AlightError(f"set_camera: fov_deg={fov_deg!r} must be between 0 and 180 degrees")
            if distance is not None and not float(distance) > 0.0:
                raise AlightError(f"set_camera: distance={distance!r} must be > 0")
            self._orbit = dict(orbit_deg=float(orbit_deg), elevation_deg=float(elevation_deg),
                               distance=None if distance is None else float(distance), fov_y_deg=float(fov_deg),
                               target=None if target is None else tuple(float(x) for x in target))
            camera = self._orbit_camera(self.width, self.height)
        else:
            self._orbit = None
        self.scene.camera = camera
        return self

    def _orbit_camera(self, w: int, h: int) -> Camera:
        """set_camera(orbit_deg=...)'s camera framed for a w x h image of the current mesh."""
        from alight.core.scene import orbit_camera

        if self._mesh is None:
            return orbit_camera((0, 0, 0), 1.0, w / h, corners=None, **self._orbit)
        centre, radius, corners = self._mesh_frame()
        return orbit_camera(centre, radius, w / h, corners=corners, **self._orbit)

    def _mesh_frame(self) -> tuple[np.ndarray, float, np.ndarray]:
        """The current mesh's bounding sphere (centre, radius) and box corners (8, 3), kept for
        that mesh: each render frames its camera with them, and each is a pass over every vertex
        (0.38 s a render for a 2.6M-vertex icosphere on this 2-core machine)."""
        if self._frame_of is None or self._frame_of[0] is not self._mesh:
            centre, radius = self._mesh.bounding_sphere()
            self._frame_of = (self._mesh, (centre, radius, self._mesh.corners()))
        return self._frame_of[1]

    def _render_camera(self, w: int, h: int) -> Camera | None:
        """The camera of a w x h render: the orbit camera framed for this size; a Camera whose
        near or far is None with them fitted to the mesh (a fixed 0.05..100 drew nothing of a
        5 mm model seen from 3 cm); a Camera whose clip range misses the whole mesh said in one
        warning line."""
        from dataclasses import replace

        if self.scene.view != "camera":
            return self.scene.camera
        if self._orbit is not None:
            return self._orbit_camera(w, h)
        camera = self.scene.camera
        if camera is None or self._mesh is None:
            return camera
        centre, radius, _ = self._mesh_frame()
        if camera.near is None or camera.far is None:
            near, far = camera.fit_clip(centre, radius)
            if camera.near is not None:     # one plane given: the fitted other stays beyond it
                near, far = camera.near, max(far, camera.near * 2.0)
            elif camera.far is not None:
                near, far = min(near, camera.far * 0.5), camera.far
            camera = replace(camera, near=near, far=far)
        d = float(np.linalg.norm(np.asarray(camera.position, np.float64) - np.asarray(centre, np.float64)))
        if d + radius < camera.near or d - radius > camera.far:
            warn(f"set_camera: the mesh lies outside the camera's clip range (near {camera.near:g}, far "
                 f"{camera.far:g}; the mesh is {max(d - radius, 0.0):.3g} to {d + radius:.3g} away), so none of "
                 f"it is drawn; leave near and far unset (None) to fit them to the mesh")
        return camera

    @property
    def mesh(self) -> Mesh | None:
        return self._mesh

    def set_view(self, view: Literal["camera", "probe"]) -> "Renderer":
        """'camera' (the default): the mesh through the camera (``set_camera``). 'probe': the
        material alone on a unit sphere through its own orthographic camera, the mesh and camera
        ignored (docs/conventions.md); its images are square (``render(w, h)`` with w != h
        raises), and a ground, shadows 'on' or occlusion 'on'/'gtao' with it raise AlightError
        at render. Raises AlightError for another view."""
        if view not in ("camera", "probe"):
            raise AlightError(f"view: {view!r} is not 'camera' or 'probe'")
        self.scene.view = view
        return self

    def set_ibl_model(self, model: str, *, multiple_scattering: bool | None = None) -> "Renderer":
        """An IBL model of app/core/ibl_models.py ('alight' by default, 'lecture' for the lecture's
        split sum), and optionally Fdez-Aguera's multiple-scattering compensation."""
        from alight.core.ibl_models import IBL_MODELS

        if model not in IBL_MODELS:
            raise AlightError(f"ibl model: {model!r} is not one of {', '.join(IBL_MODELS)}")
        self.scene.ibl_model = model
        if multiple_scattering is not None:
            self.scene.multiple_scattering = bool(multiple_scattering)
        return self

    def set_occlusion(self, mode: Literal["auto", "on", "off", "gtao"]) -> "Renderer":
        """Occlusion of the environment light by the mesh itself, with one diffuse bounce
        (alight.core.visibility: a per-vertex ray-traced bake, cached like the IBL bake): 'auto'
        (the default) bakes it where the mesh occludes enough of its own surface
        (alight.core.visibility.wants_occlusion: never the built-in sphere or a convex mesh), 'on'
        for every mesh but the built-in sphere, 'off' never, 'gtao' screen-space ambient occlusion
        per frame with no bake (alight.render.screen_ao; 'auto' uses it for a mesh too big to bake).
        Raises AlightError for another mode."""
        if mode not in ("auto", "on", "off", "gtao"):
            raise AlightError(f"occlusion: {mode!r} is not 'auto', 'on', 'off' or 'gtao'")
        self.scene.occlusion = mode
        return self

    def set_display(self, *, tonemap: str | None = None, exposure: float | None = None,
                    background: str | None = None) -> "Renderer":
        """How radiance becomes the sRGB image (a ``render(linear=True)`` or .exr is before all of
        it but the background); each argument left None keeps its value.

        ``tonemap``: one of alight.core.scene.TONEMAPS ('aces', the default; 'none' clips;
        'neutral' is Khronos PBR Neutral; 'agx', ...). ``exposure``: in EV (stops), radiance
        times 2**exposure before the curve (0: as is). ``background``: 'env' (the environment
        itself, the default), 'blur' (the environment blurred), 'color' (a dark grey) or
        'transparent' (alpha 0 where there is no mesh: ``save`` writes an RGBA .png, and
        ``render()`` returns alpha in [:, :, 3]; use it for screenshots to composite).
        Raises AlightError naming the field for an unknown tonemap or background."""
        d = self.scene.display
        if tonemap is not None:
            if tonemap not in TONEMAPS:
                raise AlightError(f"tonemap: {tonemap!r} is not one of {', '.join(TONEMAPS)}")
            d.tonemap = tonemap
        if exposure is not None:
            d.exposure = float(exposure)
        if background is not None:
            if background not in BACKGROUNDS:
                raise AlightError(f"background: {background!r} is not one of {', '.join(BACKGROUNDS)}")
            d.background = background
        return self

    # --- output --------------------------------------------------------------------------

    def render(self, width: int | None = None, height: int | None = None, *,
               linear: bool = False) -> np.ndarray:
        """Render the scene; returns (H, W, 4) float32 linear radiance (``linear=True``) or
        (H, W, 4) uint8 sRGB after exposure and tone mapping. Row 0 is the top. A flat mesh that
        the default camera (set_camera(None), on +Z) sees edge-on is said in one warning line, as
        ``alight render`` says it."""
        # Each side as given (render(0, 0) is refused as 0x0, not as the default width by 0).
        w, h = _size(self.width if width is None else width,
                     height if height is not None else (self.height if width is None else width))
        if self.scene.view == "probe" and w != h:
            raise AlightError(f"size: the probe view is square; got {w}x{h}")
        self._check_probe()
        if self.scene.view == "camera" and self.scene.camera is None and self._framing_checked is not self._mesh:
            self._framing_checked = self._mesh   # once per mesh: flat_normal reads every vertex
            for line in framing_warnings(self._mesh, self._mesh.source, None,
                                         "set_camera(orbit_deg=0, elevation_deg=30)"):
                warn(line)   # as alight render says it (app/frontends/scene_setup.py)
        if self._closed:   # before the camera's warnings: nothing is drawn
            raise AlightError("render: this Renderer is closed (its with block ended, or close() was called); "
                              "reopen it with r.open() or `with r:`, or make a new Renderer")
        from dataclasses import replace

        scene = replace(self.scene, camera=self._render_camera(w, h))
        frame = self._frame(w, h, linear=linear, srgb=not linear, scene=scene)
        idle = getattr(self._renderer, "last_ground_idle", "")
        if idle:   # in the setters' words (the renderer leaves its words to each front end)
            why = "set_shadows('off')" if idle == "shadows off" else \
                "no light, and no sun in the map that the IBL model shades exactly (add_light(...), or use a map with a sun)"
            warn(f"set_shadows(ground=True): nothing casts a shadow on it, so it changes nothing: {why}")
        return frame.linear if linear else frame.srgb

    def _check_probe(self) -> None:
        """The probe view draws the material on its unit sphere (docs/conventions.md): a ground,
        shadows 'on' or occlusion 'on'/'gtao' asked for with it would be silently ignored, so they
        are refused in one line naming the setter, as ``alight render --view probe`` refuses the
        flags (app/frontends/scene_setup.py check_probe_flags)."""
        if self.scene.view != "probe":
            return
        asked = [("set_shadows(ground=True)", self.scene.ground, "the probe view draws no ground"),
                 (f"set_shadows({self.scene.shadows!r})", self.scene.shadows == "on",
                  "the probe view draws no shadows (there is no mesh to cast them)"),
                 (f"set_occlusion({self.scene.occlusion!r})", self.scene.occlusion in ("on", "gtao"),
                  "the probe view has no mesh to occlude")]
        for setter, given, why in asked:
            if given:
                raise AlightError(f"{setter}: not with set_view('probe') ({why}); use set_view('camera')")

    def save(self, path: str | os.PathLike, width: int | None = None, height: int | None = None) -> Path:
        """Render and write ``path`` atomically: .png (sRGB, tone mapped) or .exr (linear float32)."""
        from alight.exchange.output import check_output_path, write_image

        out = check_output_path(path)
        exr = out.suffix.lower() == ".exr"
        pixels = self.render(width, height, linear=exr)
        if not exr and self.scene.display.background != "transparent":
            pixels = pixels[:, :, :3]
        write_image(out, pixels, linear=exr)
        return out

    def _frame(self, w: int, h: int, linear: bool, srgb: bool, scene: Scene):
        self.open()
        with _keep_current_context():
            self._renderer.ctx.__enter__()  # another renderer in this process may have made its own current
            return self._frame_current(w, h, linear, srgb, scene)

    def _frame_current(self, w: int, h: int, linear: bool, srgb: bool, scene: Scene):
        from alight.ibl.bake import QUALITY

        r = self._renderer
        if self.mesh_shading not in MESH_SHADING:
            raise AlightError(f"mesh_shading: {self.mesh_shading!r} is not one of {', '.join(MESH_SHADING)}")
        r.mesh_shading = self.mesh_shading
        maps = None
        if self.quality == "auto":
            return self._frame_auto(w, h, linear, srgb, scene)
        if self._env is not None and scene.ibl_enabled:
            before = r.bakes_run
            quality = self.quality if not isinstance(self.quality, str) else QUALITY.get(self.quality)
            if quality is None:
                raise AlightError(f"quality: {self.quality!r} is not one of {', '.join(QUALITY)}")
            maps = r.bake(self._env, quality)
            self.bakes_done += r.bakes_run - before
        return r.render(scene, maps, w, h, aa=self.aa, read_linear=linear, read_srgb=srgb)


    def _frame_auto(self, w: int, h: int, linear: bool, srgb: bool, scene: Scene):
        """quality="auto": the cheapest measured bake within error_budget for this scene."""
        from dataclasses import replace

        from alight.accuracy.auto_quality import (
            choose_quality,
            environment_features,
            scene_needs,
        )

        r = self._renderer
        on = self._env is not None and scene.ibl_enabled and scene.env_intensity > 0.0
        features = None
        if on:
            key = self._env.content_hash
            if key not in self._features:
                self._features[key] = environment_features(self._env.radiance)
            features = self._features[key]
        choice = self.last_auto_choice = choose_quality(scene_needs(scene), features, self.error_budget)
        maps = None
        if choice.quality is not None:
            before = r.bakes_run
            maps = r.bake(self._env, choice.quality)
            self.bakes_done += r.bakes_run - before
        return r.render(scene if on else replace(scene, ibl_enabled=False), maps, w, h, aa=self.aa,
                        read_linear=linear, read_srgb=srgb)


@functools.lru_cache(maxsize=1)
def _studio() -> Environment:
    """The built-in studio, built once per process (0.3 s) and shared: environments are not
    modified after loading, and a shared one also shares its content hash."""
    return load_environment("studio")


_EGL_DRAW, _EGL_READ = 0x3059, 0x305A


@contextlib.contextmanager
def _keep_current_context():
    """Restore whatever EGL context was current before the block.

    moderngl issues GL calls to the thread's current context, and creating a context makes it
    current; without this, opening an Renderer would silently redirect another renderer's
    draws in the same process (another library's, or a test suite's shared one) to ours.
    """
    egl = _libegl()
    state = None
    if egl is not None:
        state = (egl.eglGetCurrentDisplay(), egl.eglGetCurrentSurface(_EGL_DRAW),
                 egl.eglGetCurrentSurface(_EGL_READ), egl.eglGetCurrentContext())
    try:
        yield
    finally:
        if state is not None and state[3]:
            egl.eglMakeCurrent(*state)


@functools.lru_cache(maxsize=1)
def _libegl():
    import ctypes
    import ctypes.util

    name = ctypes.util.find_library("EGL")
    if name is None:
        return None
    lib = ctypes.CDLL(name)
    for fn in ("eglGetCurrentDisplay", "eglGetCurrentContext"):
        getattr(lib, fn).restype = ctypes.c_void_p
    lib.eglGetCurrentSurface.restype = ctypes.c_void_p
    lib.eglGetCurrentSurface.argtypes = [ctypes.c_int]
    lib.eglMakeCurrent.argtypes = [ctypes.c_void_p] * 4
    lib.eglMakeCurrent.restype = ctypes.c_uint
    return lib


def _size(w, h) -> tuple[int, int]:
    try:
        w, h = int(w), int(h)
    except (TypeError, ValueError):
        raise AlightError(f"size: {w}x{h} is not two integers") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise AlightError(f"size: {w}x{h} must have sides 1..16384")
    return w, h
