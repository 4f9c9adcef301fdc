"""The editor's plain state: what the panel edits and the renderer draws. No GL, no imgui here.

Loading a file (a drop, the panel's path box, ``--script``) happens before anything is
assigned, so a bad file leaves the previous mesh, environment or material in place and only
sets ``error``.
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from alight.core.ibl_models import DEFAULT_IBL_MODEL, IBL_MODELS
from alight.core.material import Material, validate_material, with_overrides
from alight.core.material_fields import FIELDS
from alight.core.scene import TONEMAPS, Display, Light, Scene, light_spec
from alight.core.shader_names import DATA_VIEWS, DEBUG_VIEWS
from alight.core.visibility import OCCLUSION_MODES
from alight.core.texture_maps import MAP_SLOTS, TextureMaps
from alight.errors import AlightError
from alight.exchange.images import IMAGE_SUFFIXES
from alight.exchange.texture_sets import load_slot_image
from alight.frontends.editor.compare import CompareState
from alight.ibl.bake import QUALITY
from alight.render.shadows import SHADOW_MODES

ENV_SUFFIXES = (".hdr", ".exr")
PRESET_SUFFIXES = (".json",)
# A material file's layer textures are drawn where the file is the mesh (material_files.MESH_HINT's
# words for the editor's controls).
EDITOR_MESH_HINT = "open the file as the mesh ('mesh', Environment) with 'mesh file's own materials' ticked to use them"
# From the registry, so a layer added there is a --script key too (a colour as R,G,B).
VECTOR_LAYER_FIELDS = tuple(f.name for f in FIELDS if f.layer and f.kind == "color")
SCALAR_LAYER_FIELDS = tuple(f.name for f in FIELDS if f.layer and f.kind == "number")
# The --script keys that edit the panel's material (with map_SLOT): as the panel's controls, they
# untick the mesh file's own materials.
MATERIAL_EDIT_KEYS = ("roughness", "metallic", "ior", "base_color", "emissive", "specular_f0", "preset",
                      "uv_scale", "uv_offset", *SCALAR_LAYER_FIELDS, *VECTOR_LAYER_FIELDS)


def default_lights() -> list[Light]:
    """Three lights, so the default view exercises the punctual path (the editor's benchmark scene)."""
    return [Light("point", (2.0, 3.0, 4.0), (1.0, 0.95, 0.9), 10.0),
            Light("point", (-3.0, 1.0, 2.0), (0.6, 0.7, 1.0), 6.0),
            Light("directional", (-0.3, -1.0, -0.5), (1.0, 1.0, 1.0), 1.0)]


def read_mesh(spec: str):
    """A built-in mesh or a mesh file, read and decoded (CPU only, no GL, no state: safe on a
    worker thread). Errors: AlightError of one line."""
    from alight.exchange.meshes import load_mesh

    return load_mesh(spec)


def short_warning(line: str) -> str:
    """A reader's warning line for the status row: the file named by its name, not its absolute
    path ('/long/path/to/x.exr: 2-part file: ...' -> 'x.exr: 2-part file: ...'). The row
    already says which file was opened, and a path in front pushed the warning itself out of
    the panel's width (stderr keeps the whole line)."""
    path, sep, rest = line.partition(": ")
    if sep and os.path.isabs(path) and os.path.basename(path):
        return f"{os.path.basename(path)}: {rest}"
    return line


@dataclass
class EditorState:
    mesh_spec: str = "sphere"
    env_spec: str = "studio"
    material: Material = field(default_factory=Material)
    texture_maps: TextureMaps = field(default_factory=TextureMaps)   # user-loaded maps, UV tiling
    armed_slot: str = "base_color"     # the texture slot a dropped image file fills
    saved_material: Material = field(default_factory=Material)   # what 'revert' goes back to ...
    saved_texture_maps: TextureMaps = field(default_factory=TextureMaps)   # ... with these maps
    quality: str = "medium"
    display: Display = field(default_factory=Display)
    lights: list[Light] = field(default_factory=default_lights)
    ibl_enabled: bool = True
    ibl_model: str = DEFAULT_IBL_MODEL     # app/core/ibl_models.py
    multiple_scattering: bool = False
    # Occlusion of the environment light by the mesh (Scene.occlusion), as 'alight render''s
    # default: its bake is made by a child process (occlusion_bake.py), the view drawn without meanwhile.
    occlusion: str = "auto"
    # Shadow maps (Scene.shadows), 'alight render --shadows''s choices and default, and the ground
    # under the model that catches its shadow (Scene.ground, 'alight render --ground'), as the renderer draws them.
    shadows: str = "auto"
    ground: bool = False
    env_rotation_deg: float = 0.0
    lights_follow_env: bool = False   # turning the environment turns the lights with it (env_turn.py)
    env_intensity: float = 1.0
    aa: str = "none"
    render_scale: float = 1.0     # the view's resolution relative to the window
    motion_scale: float = 1.0     # times render_scale while the camera moves (0.5: a quarter of the pixels)
    adaptive_motion: bool = False  # while moving, the scale that holds TARGET_FPS instead (at least 0.25)
    use_file_materials: bool = False   # a mesh file's own materials and texture maps instead of the panel's
    history_steps: int = 0   # undo and redo steps taken (untick_own_for_edit tells an edit from a step)
    debug_view: int = 0
    debug_mip: float = 0.0
    compare: CompareState = field(default_factory=CompareState)   # the A/B split view (compare.py)
    error: str = ""          # the last error, shown in the panel until the next success
    message: str = ""        # the last success ("saved gold.json")
    typed_name: str = ""     # the material name the artist typed last: a texture set loaded keeps it
    texture_set_folder: str = ""   # the folder the last texture set was read from ('' for files)
    warnings: int = 0        # warning lines of the last mesh or environment file opened
    warning_lines: tuple = ()   # ... and their text (the status row shows it: with_warnings)
    # Loaded CPU data (numpy arrays, no GL): set only by the loaders below.
    mesh: object = None
    env: object = None
    _fill_of: tuple = field(default=(None, 0.0), repr=False, compare=False)   # (env, its mean irradiance): added_light's
    map_images: dict = field(default_factory=dict)   # path -> decoded image, for texture_maps
    map_conversions: dict = field(default_factory=dict)   # path -> the conversion its image was decoded with
    # Set by the window: opens a mesh file off the UI thread (Panel.open_mesh, file_jobs.py) for a
    # drop, --script open= and mesh=, and a restored session's mesh (``f(spec, then=None)``);
    # None (no window: tests of the state alone) reads it here.
    open_mesh_async: object = field(default=None, repr=False, compare=False)

    @property
    def look(self) -> tuple[Material, TextureMaps, bool, tuple]:
        """What undo/redo acts on: the material's factors, its maps, the 'mesh file's own
        materials' box (an edit that unticked it is undone with it ticked again) and the lights
        (Lights replaced, never changed in place: an artist's Ctrl+Z after a light edit takes that edit back, not an older
        material edit under it)."""
        return (self.material, self.texture_maps, self.use_file_materials, tuple(self.lights))

    @look.setter
    def look(self, value: tuple) -> None:
        self.material, self.texture_maps = value[0], value[1]
        if len(value) > 2:
            self.use_file_materials = value[2]
        if len(value) > 3 and tuple(self.lights) != value[3]:
            self.lights = list(value[3])   # a new list: the renderer's "lights changed?" check compares values

    def settings(self) -> dict:
        """The view's settings that are no undo steps, by the panel's words: an undo after one of
        them changed says it stayed (``step_history``), not reaching past it silently."""
        d = self.display
        return {"tone map": d.tonemap, "exposure": d.exposure, "background": (d.background, d.background_color),
                "environment rotation": self.env_rotation_deg, "environment intensity": self.env_intensity,
                "image-based lighting": self.ibl_enabled, "ground": self.ground, "shadows": self.shadows,
                "occlusion": self.occlusion, "quality": self.quality, "anti-aliasing": self.aa}

    def edit_mark(self) -> tuple:
        """What ``untick_own_for_edit`` compares with after an edit: the look, the steps, the message."""
        return (self.look, self.history_steps, self.message)

    def untick_own_for_edit(self, mark: tuple) -> None:
        """An edit of the panel's material or maps (a slider, a colour, a layer row, a map, a
        library entry, a drop) while the mesh file's own materials are drawn would change
        nothing on screen: the box is unticked, so the edit is seen on every part, and the
        status row says so (after what the edit said, if it said anything). ``mark``:
        ``edit_mark()`` before the edit (an undo or redo in between restores the box itself).
        The edit and the untick are one undo step (History), which gives the file's materials back."""
        before, steps, said = mark
        # (A new name alone, typed or a library entry's, changes nothing drawn.)
        renamed = dataclasses.replace(before[0], name=self.material.name)
        if (steps != self.history_steps or not self.use_file_materials or not before[2]
                or (self.material, self.texture_maps) == (renamed, before[1])):
            return
        self.use_file_materials = False
        note = "the mesh file's own materials unticked to show the panel's material (Ctrl+Z gives them back)"
        if self.error:
            return
        self.message = f"{self.message}; {note}" if self.message and self.message != said else note

    def render_flags(self) -> list[str]:
        """The view's lights and settings as ``alight render``'s flags, those that differ from its
        defaults: with the camera's (OrbitCamera.render_flags) the command draws the view's
        picture of the same mesh, environment and material ('copy camera as flags'). Every light
        is written (the editor's three defaults are not the command line's: it has none); none at
        all is --no-file-lights, so a glTF file's own lights do not come in."""
        from alight.core.ibl_models import DEFAULT_IBL_MODEL

        flags = []
        for light in self.lights:
            flags += ["--light", light_spec(light)]   # (alight.core.scene: parse_light's inverse)
        if not self.lights:
            flags.append("--no-file-lights")
        if self.env_rotation_deg % 360.0:
            flags += ["--env-rotation", _g(self.env_rotation_deg)]
        if self.env_intensity != 1.0:
            flags += ["--env-intensity", _g(self.env_intensity)]
        if not self.ibl_enabled:
            flags.append("--no-ibl")
        if self.ibl_model != DEFAULT_IBL_MODEL:
            flags += ["--ibl", self.ibl_model]
        if self.multiple_scattering:
            flags.append("--multiple-scattering")
        if self.quality != "medium":
            flags += ["--quality", self.quality]
        if self.occlusion != "auto":
            flags += ["--occlusion", self.occlusion]
        if self.shadows != "auto":
            flags += ["--shadows", self.shadows]
        if self.ground:
            flags.append("--ground")
        d, default = self.display, Display()
        if d.tonemap != default.tonemap:
            flags += ["--tonemap", d.tonemap]
        if d.exposure != default.exposure:
            flags += ["--exposure", _g(d.exposure)]
        if d.background != default.background:
            flags += ["--background", d.background]
            if d.background == "color":
                flags += ["--background-color", ",".join(_g(x) for x in d.background_color)]
        if self.aa != "msaa":   # (the command line's default)
            flags += ["--aa", self.aa]
        return flags

    def scene(self, camera) -> Scene:
        # Off by default: the editor's material is what the artist is shaping.
        return Scene(mesh=self.mesh, material=self.material, use_file_materials=self.use_file_materials,
                     lights=self.lights, camera=camera, env_rotation_deg=self.env_rotation_deg,
                     env_intensity=self.env_intensity, ibl_enabled=self.ibl_enabled and self.env is not None,
                     ibl_model=self.ibl_model, multiple_scattering=self.multiple_scattering,
                     occlusion=self.occlusion, shadows=self.shadows, ground=self.ground,
                     # Data views are shown as values: no exposure, no tone curve.
                     display=dataclasses.replace(self.display, tonemap="none", exposure=0.0)
                     if self.debug_view in DATA_VIEWS else self.display,
                     debug_view=self.debug_view,
                     debug_mip=self.debug_mip,
                     texture_maps=self.texture_maps,
                     texture_images=self.map_images)

    # --- loading (all or nothing) -----------------------------------------------------------

    def load_mesh(self, spec: str) -> None:
        self.apply_mesh(spec, read_mesh(spec))

    def apply_mesh(self, spec: str, mesh) -> None:
        """A mesh read by ``read_mesh`` (here, or on the panel's worker thread: file_jobs.py)."""
        from alight.core.mesh import BUILTIN_MESHES
        from alight.paths import absolute

        # A file kept by its absolute path: the session reopens it from any folder.
        self.mesh, self.mesh_spec = mesh, spec if spec in BUILTIN_MESHES else absolute(spec)
        # As 'alight render' draws a file: its own materials where it has any (the panel's
        # checkbox switches to the panel's material), the panel's where it has none.
        self.use_file_materials = any(part.material is not None for part in mesh.parts)
        # A part without its material is drawn with "the current material": here the panel's (its
        # checkbox 'mesh file's own materials' decides only for parts that have one).
        self._say(mesh.warnings)

    def added_light(self, kind: str) -> Light:
        """A new light that shows: about the mesh's bounds, twice the environment's mean
        irradiance at its centre (as a key light over the fill; at least 1 with no image-based
        light). ``alight.core.scene.added_light`` does the placing."""
        from alight.core.scene import added_light
        from alight.ibl.environment import mean_irradiance

        if self.mesh is not None:
            centre, radius = self.mesh.bounding_sphere()
        else:   # the built-in sphere
            centre, radius = (0.0, 0.0, 0.0), 1.0
        fill = 0.0
        if self.ibl_enabled and self.env is not None:
            if self._fill_of[0] is not self.env:
                self._fill_of = (self.env, mean_irradiance(self.env.radiance))
            fill = self._fill_of[1] * self.env_intensity
        light = added_light(kind, centre, radius, max(2.0 * fill, 1.0))
        # Three significant digits: the panel's intensity field reads 38.5, not 38.4537.
        return dataclasses.replace(light, intensity=float(f"{light.intensity:.3g}"))

    def set_variant(self, name: str | None) -> None:
        """The mesh file's material variant (KHR_materials_variants) by name; None: each part's
        own material (alight.core.mesh.select_variant: the same geometry, other materials).
        Errors: AlightError of one line listing the file's variants."""
        from alight.core.mesh import select_variant

        self.mesh = select_variant(self.mesh, name)

    def load_env(self, spec: str) -> None:
        from alight.ibl.environment import load_environment

        from alight.paths import absolute

        env = load_environment(spec)
        self.env, self.env_spec = env, spec if spec == "studio" else absolute(spec)   # (as load_mesh)
        self._say(env.warnings)

    def _say(self, warnings) -> None:
        """What a file is drawn without: on stderr (once per process, alight.errors.warn) and
        counted in the panel's message, whenever the file is opened (at start or dropped)."""
        from alight.errors import warn

        for line in warnings:
            warn(line)
        self.warnings = len(warnings)
        self.warning_lines = tuple(warnings)

    def with_warnings(self, message: str) -> str:
        """``message`` with the last file's warnings, for the status row (hovering it shows the
        line whole): 'opened X; warning: TEXT', or 'opened X; 2 warnings: A | B'; each warning
        names its file by its name (short_warning)."""
        lines = [short_warning(line) for line in self.warning_lines]
        if not lines:
            return message
        if len(lines) == 1:
            return f"{message}; warning: {lines[0]}"
        return f"{message}; {len(lines)} warnings: " + " | ".join(lines)

    def set_map(self, slot: str, path: str, factor_to_1: bool = True) -> None:
        """Fill a texture slot from an image file (read now: a bad file raises, nothing changes).
        The slot's factor becomes 1 (glTF's convention: the map is the value), unless
        ``factor_to_1`` is False (a restored session keeps the factors it saved)."""
        from alight.core.texture_maps import map_factors
        from alight.paths import absolute

        path = absolute(path)   # kept so: the session, the watcher and undo name one file from any folder
        maps = self.texture_maps.with_slot(slot, path)
        image = load_slot_image(maps, slot)
        self.map_images = {p: self.map_images[p] for p in maps.paths().values() if p in self.map_images}
        self.map_images[path] = image
        self.texture_maps = maps
        if factor_to_1:
            self.material = with_overrides(self.material, **map_factors((slot,)))

    def set_map_conversion(self, name: str, on: bool) -> None:
        """'normal_dx' (the normal map is DirectX's: green flipped) or 'roughness_gloss' (the
        roughness slot holds gloss: inverted); the slot's image is decoded again."""
        if name not in ("normal_dx", "roughness_gloss"):
            raise AlightError(f"'{name}' is not a map conversion (normal_dx, roughness_gloss)")
        maps = dataclasses.replace(self.texture_maps, **{name: bool(on)})
        slot = "normal" if name == "normal_dx" else "roughness"
        if getattr(maps, slot):
            self.map_images = {**self.map_images, getattr(maps, slot): load_slot_image(maps, slot)}
        self.texture_maps = maps

    def clear_map(self, slot: str) -> None:
        self.texture_maps = self.texture_maps.with_slot(slot, "")

    def watched_files(self) -> set[str]:
        """The files whose change on disk the editor reloads: every map's and the environment's."""
        paths = set(self.texture_maps.paths().values())
        if self.env_spec and self.env_spec != "studio":   # the watcher's thread stats it, not the frame
            paths.add(self.env_spec)
        return paths

    def reload_files(self, paths) -> bool:
        """Decode again the maps and the environment read from ``paths`` (changed on disk). A file
        that does not read now (half written, broken) keeps what was drawn and sets ``error``;
        it is tried again at its next change. Returns whether anything was reloaded."""
        done, failed = [], False
        for slot, path in self.texture_maps.paths().items():
            if path in paths:
                try:
                    self.map_images = {**self.map_images, path: load_slot_image(self.texture_maps, slot)}
                    done.append(path)
                except AlightError as exc:
                    self.fail(exc)
                    failed = True
        if self.env_spec in paths:
            try:
                self.load_env(self.env_spec)
                done.append(self.env_spec)
            except AlightError as exc:
                self.fail(exc)
                failed = True
        if done:
            from pathlib import Path

            if not failed:   # the file that failed to read before reads now: its error goes
                self.error = ""
            self.message = "reloaded " + ", ".join(sorted({Path(p).name for p in done}))
        return bool(done)

    def sync_map_images(self) -> None:
        """Decode any slot's file not yet decoded (after undo/redo or a restored session); a file
        that no longer reads empties its slot and sets ``error``."""
        maps = self.texture_maps
        # An image decoded under the other conversion (undo of the DirectX or gloss toggle) again.
        flags = {"normal": maps.normal_dx, "roughness": maps.roughness_gloss}
        for slot, on in flags.items():
            path = getattr(maps, slot)
            if path and self.map_conversions.get(path, False) != on:
                self.map_images.pop(path, None)
            if path:
                self.map_conversions[path] = on
        for slot, path in self.texture_maps.paths().items():
            if path not in self.map_images:
                try:
                    self.map_images[path] = load_slot_image(self.texture_maps, slot)
                except AlightError as exc:
                    self.texture_maps = self.texture_maps.with_slot(slot, "")
                    self.fail(exc)

    def mark_saved(self) -> None:
        """The look now is what 'revert' goes back to (after a save)."""
        self.saved_material, self.saved_texture_maps = self.material, self.texture_maps

    def revert(self) -> None:
        """Back to the material and maps last applied, loaded or saved (a preset, a library
        entry, a file); an undo step like any edit."""
        self.material, self.texture_maps = self.saved_material, self.saved_texture_maps
        self.sync_map_images()
        self.error, self.message = "", f"reverted to {self.material.name}"

    def step_history(self, history, redo: bool = False) -> None:
        """Undo (or redo) one step. Stepping away from the look 'revert' goes back to takes
        'revert' along: after a preset click is undone, 'revert' returns to the look before the
        click, not to the preset the artist took back."""
        leaving_saved = (self.material, self.texture_maps) == (self.saved_material, self.saved_texture_maps)
        word = "redo" if redo else "undo"
        before = self.look
        self.look = history.redo(self.look) if redo else history.undo(self.look)
        self.history_steps += 1
        self.sync_map_images()
        if leaving_saved:
            self.saved_material, self.saved_texture_maps = self.material, self.texture_maps
        # Settings changed since the history's last step stay as they are: the row says so after
        # the step (an exposure change, then Ctrl+Z, took back an older edit without a word).
        now_settings, seen = self.settings(), history.settings_seen
        history.settings_seen = now_settings
        stayed = [k for k, v in now_settings.items() if seen is not None and seen.get(k) != v]
        self._step_message(before, word)
        if stayed and not self.error:
            self.message += f"; not undone: {', '.join(stayed)} (not in the history)"

    def _step_message(self, before: tuple, word: str) -> None:
        """The status row after an undo or redo step (``step_history``)."""
        # The status row said what the step took back ('applied silver'): it says where it is now
        # and what changed, so two steps over one material's fields do not read the same.
        maps = len(self.texture_maps.paths())
        now = f"{self.material.name}{f' with {maps} map' + ('s' if maps > 1 else '') if maps else ''}"
        if self.use_file_materials and self.mesh is not None and any(
                part.material is not None for part in self.mesh.parts):
            now = "the mesh file's own materials"   # what the view draws, not the panel's hidden material
        # While the view is split, undo acts on B (the live material) alone: A's snapshot or
        # preset and the compare mode are no undo steps, and the row says so.
        split = self.compare.active
        where = f"{word} on B" if split else word
        self.error = ""
        if self.look == before:
            self.message = f"nothing to {where}" + (
                " (A's snapshot or preset and the compare mode are not undo steps)" if split else "")
            return
        if tuple(self.look[:3]) == tuple(before[:3]):   # a light's step: the material's name says nothing
            self.message = f"{where}: {lights_change(before[3], self.look[3])}"
            return
        self.message = f"{where}: {now} ({look_change(before, self.look)})"
        if self.compare.mode == "reference":
            from alight.frontends.editor.compare import reference_problem

            problem = reference_problem(self)
            if problem:   # the reference's error would replace the row: it follows the step instead
                self.error = f"{self.message}; {problem}"

    def apply_preset(self, preset: Material) -> None:
        """A preset of the F0 table: a whole material, so its factors and no maps (maps loaded
        before would multiply its factors); 'revert' goes back to it. One undo step (History)."""
        self.material = self.saved_material = preset
        self.texture_maps = self.saved_texture_maps = TextureMaps()
        self.error, self.message = "", f"applied {preset.name}"
        if self.use_file_materials:   # a click on a preset is to see it: on every part of the mesh
            self.use_file_materials = False
            self.message += " (the mesh file's own materials unticked)"

    def load_material(self, name_or_path: str) -> None:
        """A preset (.json: factors; .gltf/.glb: factors and maps, alight.exchange.material_files)."""
        from alight.exchange.material_files import load_material_file
        from alight.exchange.texture_sets import load_map_images

        from alight.paths import absolute_maps

        m, maps, warnings = load_material_file(name_or_path, mesh_hint=EDITOR_MESH_HINT)
        maps = absolute_maps(maps)   # (a relative preset's maps are relative to where it was read from)
        images = load_map_images(maps)   # read first: a bad map changes nothing
        self._say(warnings)
        self.material = self.saved_material = m
        self.texture_maps = self.saved_texture_maps = dataclasses.replace(maps)
        self.map_images = images

    def save_material(self, path: str) -> str:
        """The material with its maps: .gltf (images beside it) or .glb with the mesh shown, so
        the file reopens (here, in ``alight render --preset/--mesh``, other viewers) as drawn.
        A .json preset holds factors only: with maps loaded it is written with the factors that
        look closest without them (``preset_material``), and the returned note (else '') says
        the maps were left out and where they are kept. (The CLI's ``alight export`` still
        refuses: it has no status row to say so.)"""
        from alight.exchange.material_files import is_gltf, save_material_file

        gltf = is_gltf(path)
        left_out = {} if gltf else self.texture_maps.paths()
        save_material_file(self.material if gltf else self.preset_material(), path,
                           self.texture_maps if gltf else None, mesh=self.mesh if gltf else None)
        self.mark_saved()
        if not left_out:
            return ""
        n = len(left_out)
        return (f"factors only: {n} map{'s' if n > 1 else ''} left out ({', '.join(left_out)}), "
                f"their average look kept in the factors; save as .gltf or .glb to keep them")

    def preset_material(self):
        """The material as a .json preset holds it: without maps, the factors that draw it
        closest to how it looks with them (alight.core.texture_maps.factors_without_maps: the
        glTF factors of 1 alone drew a white, metallic, self-lit object)."""
        from alight.core.texture_maps import factors_without_maps

        if not self.texture_maps.paths():
            return self.material
        return factors_without_maps(self.material, self.texture_maps, self.map_images)

    def export_gltf(self, path: str) -> str:
        """The mesh with what the view draws on it, and the edited material with its maps, as
        .gltf or .glb (alight.exchange.gltf_export: F0 other than 0.04 goes out as
        KHR_materials_ior/specular). Where the view shows the mesh file's own materials, each
        part keeps its own (textures, samplers and transforms included); else the panel's goes on
        every part. The returned note (else '') says in one line what was left out."""
        return self.export_job(path)()

    def export_job(self, path: str):
        """``export_gltf``'s work as a function of what is shown now (the material, its maps, the
        mesh: all replaced, never changed in place), to run on a worker thread (file_jobs.py):
        it returns the note."""
        from alight.exchange.gltf_export import export_gltf

        material, maps, mesh, own = self.material, self.texture_maps, self.mesh, self.use_file_materials

        def run() -> str:
            _, notes = export_gltf(material, path, maps, mesh, file_materials=own)
            return "; ".join(n for n in notes if "left out" in n)
        return run

    def open_texture_set(self, paths, folder: str = "") -> list[str]:
        """Image files dropped together (or ``folder``'s), assigned to slots by their names
        (alight.exchange.texture_sets); the loaded slots' factors become 1 (glTF's convention)
        and the material is named after the set (the folder's name, else the files' common
        stem) unless its name is one the artist typed; one undo step. Returns the assignment's
        lines, also shown as the panel's message."""
        from alight.core.texture_maps import map_factors
        from alight.exchange.texture_sets import assign_files, load_map_images, set_name
        from alight.paths import absolute

        paths, folder = [absolute(p) for p in paths], absolute(folder)   # (as set_map)
        before = self.texture_maps
        # A set is whole: it replaces the maps before it (a slot it leaves empty is empty, not the
        # last set's map, which would tint it), keeping only the UV tiling.
        found = assign_files(paths, TextureMaps(uv_scale=before.uv_scale, uv_offset=before.uv_offset))
        if not found.slots:
            raise AlightError(f"{os.path.basename(paths[0])}: no file of the {len(paths)} has a texture map's name "
                              f"(e.g. NAME_BaseColor.png, NAME_Normal.png); drop one at a time into the armed slot")
        images = load_map_images(found.maps)
        self.map_images = images
        self.texture_maps = found.maps
        self.texture_set_folder = folder
        factors = map_factors(found.slots)
        # The last set's metal or emission map set its factor to 1; a set without one is a
        # dielectric that does not glow, not a white metal or a white light.
        filled, had = set(found.maps.paths()), set(before.paths())
        metal = {"metallic", "metallic_roughness"}
        if had & metal and not filled & metal:
            factors["metallic"] = 0.0
        if "emissive" in had and "emissive" not in filled:
            factors["emissive"] = (0.0, 0.0, 0.0)
        self.material = with_overrides(self.material, **factors)
        name = set_name(paths, folder)
        if name and name.isprintable() and self.material.name != self.typed_name:
            self.material = dataclasses.replace(self.material, name=name)
        self.error, self.message = "", "texture set: " + "; ".join(found.lines())
        return found.lines()

    def open_texture_folder(self, folder: str) -> list[str]:
        """Every image file in ``folder`` as one texture set (``open_texture_set``)."""
        try:
            files = sorted(os.path.join(folder, f) for f in os.listdir(folder)
                           if os.path.splitext(f)[1].lower() in IMAGE_SUFFIXES)
        except OSError as exc:
            raise AlightError(f"{folder}: cannot read the folder ({exc.strerror})") from None
        if not files:
            raise AlightError(f"{folder}: no image files in the folder")
        return self.open_texture_set(files, folder)

    def texture_set_files(self) -> list[str]:
        """The loaded maps' files, each once (an ORM fills two slots), sorted; [] for images
        inside a .glb/.gltf (a library entry): no files to name or load again."""
        paths = sorted(set(self.texture_maps.paths().values()))
        return [] if any("#" in os.path.basename(p) for p in paths) else paths

    def _set_folder_whole(self, paths: list[str]) -> bool:
        folder = self.texture_set_folder
        return bool(folder and paths and all(os.path.dirname(p) == folder.rstrip(os.sep) for p in paths))

    def texture_set_text(self) -> str:
        """What the 'texture set' field shows for the maps loaded: the folder they were read from
        while every map is in it, one map's path, or, for several files, their shared name, their
        count and their folder (``Bricks_2K_* (4 maps) in /x/bricks``): their paths one after
        another showed only the first in the field, which read as the one map loaded. '' without
        maps. 'load set' on it unchanged loads ``texture_set_spec()``."""
        paths = self.texture_set_files()
        if self._set_folder_whole(paths):
            return self.texture_set_folder
        if len(paths) <= 1:
            return paths[0] if paths else ""
        folders = {os.path.dirname(p) for p in paths}
        if len(folders) > 1:
            return f"{len(paths)} maps from {len(folders)} folders"
        names = [os.path.basename(p) for p in paths]
        stem = os.path.commonprefix(names)
        # Cut back to a separator: 'rock_' of rock_diff and rocky_nor is not a name they share.
        cut = max(stem.rfind(c) for c in "_-. ") + 1
        stem = stem[:cut] if cut else ""
        return f"{stem + '* (' if stem else ''}{len(paths)} maps{')' if stem else ''} in {folders.pop()}"

    def texture_set_spec(self) -> str:
        """The 'texture set' field's text as 'load set' reads it, for the maps loaded: the folder
        ``texture_set_text`` shows, else the files separated by ';'."""
        paths = self.texture_set_files()
        return self.texture_set_folder if self._set_folder_whole(paths) else ";".join(paths)

    def texture_set_listing(self) -> str:
        """The maps loaded, a line each with the slots it fills (the 'texture set' field's
        tooltip: the field names the set, this the files in it); '' without maps."""
        from alight.core.texture_maps import SLOT_LABELS

        paths = self.texture_set_files()
        if not paths:
            return ""
        slots: dict[str, list[str]] = {}
        for slot, path in self.texture_maps.paths().items():
            slots.setdefault(path, []).append(SLOT_LABELS[slot])
        folders = {os.path.dirname(p) for p in paths}
        one = folders.pop() if len(folders) == 1 else ""
        head = f"{len(paths)} map{'s' if len(paths) > 1 else ''}" + (f" in {one}:" if one else ":")
        return "\n".join([head] + [f"  {os.path.basename(p) if one else p}: {', '.join(slots[p])}" for p in paths])

    def open_file(self, path: str) -> bool:
        """A dropped or typed file, by its suffix. Returns False (and sets ``error``) on failure."""
        from alight.exchange.meshes import MESH_EXTENSIONS

        suffix = Path(path).suffix.lower()
        try:
            if suffix in ENV_SUFFIXES:
                self.load_env(path)
            elif suffix in MESH_EXTENSIONS and not _material_only(path):
                if self.open_mesh_async is not None:
                    self.open_mesh_async(path)   # read on the panel's worker; its errors come later
                else:
                    self.load_mesh(path)
            elif suffix in (".gltf", ".glb"):   # a material without a mesh (alight export --out X.gltf)
                self.load_material(path)
            elif suffix in PRESET_SUFFIXES:
                self.load_material(path)
            elif suffix in IMAGE_SUFFIXES:    # a texture map, into the armed slot
                self.set_map(self.armed_slot, path)
            else:
                raise AlightError(f"{path}: not an environment (.hdr .exr), a mesh "
                                  f"({' '.join(MESH_EXTENSIONS)}), a preset (.json) "
                                  f"or a texture map ({' '.join(IMAGE_SUFFIXES)})")
        except Exception as exc:
            self.fail(exc)
            return False
        warned = suffix != "" and suffix not in IMAGE_SUFFIXES   # (a map's read says nothing)
        self.error, self.message = "", f"opened {os.path.basename(path)}"
        if suffix in IMAGE_SUFFIXES:   # which slot it went to: the armed one, chosen frames ago
            from alight.core.texture_maps import SLOT_LABELS

            self.message += f" as the {SLOT_LABELS[self.armed_slot].split(' (')[0]} map"
        if warned:
            self.message = self.with_warnings(self.message)
        return True

    def open_environment(self, path: str) -> bool:
        """The environment row's file: always the environment, whatever its suffix (a 2:1 PNG as
        ``alight render --env`` takes it), never a texture map by way of ``open_file``'s routing.
        Returns False (and sets ``error``) on failure."""
        try:
            self.load_env(path)
        except Exception as exc:
            self.fail(exc)
            return False
        self.error, self.message = "", self.with_warnings(f"opened {os.path.basename(path)} as the environment")
        return True

    def fail(self, exc: Exception) -> None:
        """One line, never a traceback: a loader's surprise is named by its type."""
        text = str(exc) if isinstance(exc, AlightError) else f"{type(exc).__name__}: {exc}"
        self.error = " ".join(text.split())
        self.message = ""

    # --- scripted edits (``alight edit --script``; the tests drive the editor with these) ------

    def apply_edit(self, edit: str) -> None:
        """``field=value``: roughness / metallic / ior and the layers' numbers (clearcoat, ...),
        base_color / emissive / specular_f0 and the layers' colours (sheen_color, ...: R,G,B linear),
        preset / open / mesh / env (a name or path), exposure, tonemap,
        env_rotation, env_intensity, ibl (0/1), ibl_model, multiple_scattering (0/1), occlusion
        (auto/on/off), shadows (auto/on/off), ground (0/1), quality;
        map_SLOT (an image path, '' clears; SLOT one of alight.core.texture_maps.MAP_SLOTS), uv_scale /
        uv_offset (U,V). Edits of the material or its maps untick the mesh file's own materials."""
        key, sep, value = edit.partition("=")
        key = key.strip().replace("-", "_")
        if not sep:
            raise AlightError(f"--script: '{edit}' is not FIELD=VALUE")
        # An edit of the material or its maps unticks the mesh file's own materials as the panel's
        # controls do (untick_own_for_edit): with the box ticked a script's roughness= drew nothing.
        mark = self.edit_mark()
        self._apply_edit(key, value, edit)
        if key in MATERIAL_EDIT_KEYS or (key.startswith("map_") and key[4:] in MAP_SLOTS):
            self.untick_own_for_edit(mark)

    def _apply_edit(self, key: str, value: str, edit: str) -> None:
        from alight.core.material import parse_color

        try:
            if key in ("roughness", "metallic", "ior", *SCALAR_LAYER_FIELDS):
                self.material = with_overrides(self.material, "--script", **{key: _finite(value, edit)})
            elif key in ("base_color", "emissive", "specular_f0", *VECTOR_LAYER_FIELDS):
                self.material = with_overrides(self.material, "--script", **{key: parse_color(value, "--script")})
            elif key == "preset":
                self.load_material(value)
            elif key == "open":
                if not self.open_file(value):   # (a drop shows it in the panel; a script stops)
                    raise AlightError(self.error)
            elif key == "mesh":
                if self.open_mesh_async is not None:   # read on the panel's worker: the script
                    self.open_mesh_async(value)        # waits for it, as for open= (run.py)
                else:
                    self.load_mesh(value)
            elif key == "env":
                self.load_env(value)
            elif key == "exposure":
                self.display = dataclasses.replace(self.display, exposure=_finite(value, edit))
            elif key == "tonemap":
                if value not in TONEMAPS:
                    raise AlightError(f"--script: tonemap '{value}' is not one of {', '.join(TONEMAPS)}")
                self.display = dataclasses.replace(self.display, tonemap=value)
            elif key in ("env_rotation", "env_intensity"):
                setattr(self, key + ("_deg" if key == "env_rotation" else ""), _finite(value, edit))
            elif key == "ibl":
                self.ibl_enabled = value not in ("0", "false", "off")
            elif key == "ibl_model":
                if value not in IBL_MODELS:
                    raise AlightError(f"--script: ibl_model '{value}' is not one of {', '.join(IBL_MODELS)}")
                self.ibl_model = value
            elif key == "multiple_scattering":
                self.multiple_scattering = value not in ("0", "false", "off")
            elif key == "occlusion":
                if value not in OCCLUSION_MODES:
                    raise AlightError(f"--script: occlusion '{value}' is not one of {', '.join(OCCLUSION_MODES)}")
                self.occlusion = value
            elif key == "shadows":
                if value not in SHADOW_MODES:
                    raise AlightError(f"--script: shadows '{value}' is not one of {', '.join(SHADOW_MODES)}")
                self.shadows = value
            elif key == "ground":
                self.ground = value not in ("0", "false", "off")
            elif key == "quality":
                if value not in (*QUALITY, "auto"):
                    raise AlightError(f"--script: quality '{value}' is not one of {', '.join(QUALITY)}, auto")
                self.quality = value
            elif key == "debug_view":
                if value not in DEBUG_VIEWS:
                    raise AlightError(f"--script: debug_view '{value}' is not one of {', '.join(DEBUG_VIEWS)}")
                self.debug_view = DEBUG_VIEWS.index(value)
            elif key.startswith("map_") and key[4:] in MAP_SLOTS:
                if value:
                    self.set_map(key[4:], value)
                else:
                    self.clear_map(key[4:])
            elif key in ("uv_scale", "uv_offset"):
                pair = tuple(_finite(x, edit) for x in value.split(","))
                if len(pair) != 2:
                    raise AlightError(f"--script: '{edit}': {key} takes U,V")
                self.texture_maps = dataclasses.replace(self.texture_maps, **{key: pair})
            elif key.startswith("compare"):   # compare=MODE, compare_divider=, compare_a=, ... (compare.py)
                from alight.frontends.editor.compare import apply_edit

                apply_edit(self.compare, self, key, value)
            elif key == "debug_mip":
                self.debug_mip = max(0.0, _finite(value, edit))
            else:
                raise AlightError(f"--script: unknown field '{key}'")
        except ValueError:
            raise AlightError(f"--script: '{edit}': '{value}' is not a number") from None


def _g(x: float) -> str:
    return f"{float(x):.9g}"


def _material_only(path: str) -> bool:
    """A glTF file with materials and no meshes: opened as a material."""
    from alight.exchange.gltf_material import read_gltf_json

    try:
        doc = read_gltf_json(path)
    except AlightError:
        return False   # load_mesh says what is wrong with it
    return not doc.get("meshes") and bool(doc.get("materials"))


def _value(v) -> str:
    """A number as the panel's widgets show it (imgui's '%.3f'), without trailing zeros."""
    return f"{round(v, 3):g}" if isinstance(v, float) else str(v)


def look_change(before: tuple, after: tuple, most: int = 3) -> str:
    """What an undo or redo step changed, in a few words for the status row: the material it
    left where the name changed ('was copper'), else the fields that changed, a number's old and
    new value ('roughness 0.3 -> 0.5'), and the map slots loaded or cleared."""
    (m0, maps0, *own0), (m1, maps1, *own1) = before, after
    own0, own1 = bool(own0 and own0[0]), bool(own1 and own1[0])
    n = len(maps0.paths())
    was = f"was {m0.name}" + (f" with {n} map{'s' if n > 1 else ''}" if n else "")
    if own1 and not own0:   # the file's materials back: what the step took away was the panel's
        if m0.name == m1.name:   # an edit of its fields: the values it had ('was default, roughness 0.8')
            edited = [f"{f.name.replace('_', ' ')} {_value(getattr(m0, f.name))}"
                      for f in dataclasses.fields(m0) if getattr(m0, f.name) != getattr(m1, f.name)
                      and isinstance(getattr(m0, f.name), (int, float))][:most]
            return ", ".join([was, *edited])
        return was
    if own0 and not own1:
        return "was the mesh file's own materials"
    if m0.name != m1.name:
        return was
    changes = []
    for f in dataclasses.fields(m1):
        a, b = getattr(m0, f.name), getattr(m1, f.name)
        if a != b:
            label = f.name.replace("_", " ")
            changes.append(f"{label} {_value(a)} -> {_value(b)}" if isinstance(b, (int, float)) else label)
    p0, p1 = maps0.paths(), maps1.paths()
    for slot in MAP_SLOTS:
        if p0.get(slot) != p1.get(slot):
            changes.append(f"{slot.replace('_', ' ')} map " + (
                "cleared" if not p1.get(slot) else "loaded" if not p0.get(slot) else "replaced"))
    if maps0 != maps1 and not any(p0.get(k) != p1.get(k) for k in MAP_SLOTS):
        changes.append("map tiling")
    if not changes:
        return "no visible change"
    return ", ".join(changes[:most]) + (f" and {len(changes) - most} more" if len(changes) > most else "")


_LIGHT_LABELS = {"vector": "position", "inner_cone_deg": "inner cone", "outer_cone_deg": "outer cone"}


def lights_change(before: tuple, after: tuple) -> str:
    """What an undo or redo step did to the lights, for the status row: the light it took away or
    brought back ('light 3 (spot) removed'), else the fields of the light that changed, a number's
    old and new value ('light 3 intensity 500 -> 30')."""
    if len(after) != len(before):
        gone = len(after) < len(before)
        longer, shorter = (before, after) if gone else (after, before)
        i = next((k for k in range(len(shorter)) if shorter[k] != longer[k]), len(shorter))
        return f"light {i} ({longer[i].kind}) {'removed' if gone else 'back'}"
    for i, (a, b) in enumerate(zip(before, after)):
        if a == b:
            continue
        changes = []
        for f in dataclasses.fields(b):
            x, y = getattr(a, f.name), getattr(b, f.name)
            if x != y:
                label = _LIGHT_LABELS.get(f.name, f.name.replace("_", " "))
                if f.name == "vector" and b.kind == "directional":
                    label = "direction"
                changes.append(f"{label} {_value(x)} -> {_value(y)}" if isinstance(y, (int, float)) else label)
        return f"light {i} " + ", ".join(changes)
    return "no visible change"


def _finite(value: str, edit: str) -> float:
    x = float(value)
    if not math.isfinite(x):
        raise AlightError(f"--script: '{edit}': '{value}' is not finite")
    return x


class History:
    """Undo/redo of material and light edits, in the order made, as snapshots of
    EditorState.look (the Material, the TextureMaps are frozen and the Lights are replaced, never changed in place, so a snapshot is
    the value).

    A drag of a slider is one step: ``settle`` records a step only once no widget is active.
    """

    def __init__(self, look):
        self.committed = look
        self.settings_seen = None   # EditorState.settings() at the last step (the window notes it)
        self.undo_stack: list = []
        self.redo_stack: list = []

    def settle(self, current, editing: bool) -> None:
        if editing or current == self.committed:
            return
        if tuple(current[:2]) == tuple(self.committed[:2]) and tuple(current[3:]) == tuple(self.committed[3:]):
            # The 'own materials' box alone (its click, a mesh opened): no step of its own, but
            # the snapshot keeps it, so the next edit's undo brings the box back as it was.
            self.committed = current
            return
        self.undo_stack.append(self.committed)
        self.redo_stack.clear()
        self.committed = current

    def turn_lights(self, turn) -> None:
        """The lights turned with the environment (env_turn.py): not an undo step, so every
        snapshot's lights turn too; an undo of an older edit then leaves them where the
        environment put them, not where they were before its turn."""
        def turned(look):
            return (*look[:3], tuple(turn(list(look[3])))) if len(look) > 3 else look
        self.committed = turned(self.committed)
        self.undo_stack[:] = [turned(look) for look in self.undo_stack]
        self.redo_stack[:] = [turned(look) for look in self.redo_stack]

    def undo(self, current) -> tuple:
        return self._step(current, self.undo_stack, self.redo_stack)

    def redo(self, current) -> tuple:
        return self._step(current, self.redo_stack, self.undo_stack)

    def _step(self, current, source: list, target: list) -> tuple:
        """Move one state from ``source`` to the committed one, keeping the old in ``target``."""
        self.settle(current, False)
        if not source:
            return current
        target.append(self.committed)
        self.committed = source.pop()
        return self.committed
