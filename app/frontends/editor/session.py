"""The last session (mesh, environment, material, camera, the view's settings and debug view,
its render and motion scales, the turntable's frames and file, the panel's preset and glTF file
fields and which of its sections are open), so the editor reopens
where the artist left it. A JSON file in the user's config folder (``alight.paths.config_dir``),
written atomically on close."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

from alight.core.material import material_from_dict
from alight.core.shader_names import DEBUG_VIEWS
from alight.core.texture_maps import MAP_SLOTS, TextureMaps
from alight.errors import AlightError
from alight.exchange.output import write_text_atomic
from alight.frontends.editor import compare
from alight.paths import config_dir

CAMERA_FIELDS = ("target", "yaw_deg", "pitch_deg", "distance", "fov_y_deg", "radius")
# The view's settings kept beside the material and camera (with the display and the lights).
SETTING_FIELDS = ("env_rotation_deg", "env_intensity", "ibl_enabled", "ibl_model", "multiple_scattering",
                  "lights_follow_env", "occlusion", "shadows", "ground")
# The view's scales, kept from 0.25 to 1 as the panel's sliders are (older sessions lack them).
SCALE_FIELDS = ("render_scale", "motion_scale", "adaptive_motion")
EDITOR_AA = ("none", "msaa")   # the editor's anti-aliasing (alight edit --aa, the panel's combo)


def session_path() -> Path:
    return config_dir() / "editor-session.json"


def save_session(state, orbit, turntable=None, panel=None) -> None:
    """``turntable``: the window's turntable.TurntableSettings, ``panel``: its panel.Panel (the
    'preset file' and 'glTF file' fields), each kept when given. Every path is written absolute
    (the loaders keep them so; the rest are made so here, against the folder the editor ran in,
    which it never leaves): a session reopened from another folder names the same files. The
    output fields left at their defaults (material.json, material.gltf, turntable.webp) stay
    relative: they name a file in the folder the editor runs in when it writes, as on a first
    start, not in the folder of the session that saved them."""
    from alight.core.mesh import BUILTIN_MESHES
    from alight.frontends.editor.panel import DEFAULT_PATHS
    from alight.frontends.editor.turntable import DEFAULT_PATH
    from alight.paths import absolute, absolute_maps

    def output(path, default):
        return path if path == default else absolute(path)

    compare_dict = compare.to_dict(state.compare)
    compare_dict["a_texture_maps"] = absolute_maps(state.compare.a_texture_maps).to_dict()
    # A mesh still being read (opened just before the close, or the last session's at start-up)
    # is the one the artist chose: kept, not the one on screen meanwhile.
    # So is the 'own materials' box it will have: the placeholder's on screen meanwhile (the
    # built-in sphere's, never ticked) unticked the helmet's box in the next session.
    jobs = getattr(panel, "file_jobs", None)
    opening = getattr(jobs, "opening", "")
    mesh = opening or state.mesh_spec
    own_materials = jobs.own_materials if opening else state.use_file_materials
    data = {"mesh": mesh if mesh in BUILTIN_MESHES else absolute(mesh),
            "env": state.env_spec if state.env_spec == "studio" else absolute(state.env_spec),
            "material": state.material.to_dict(),
            "texture_maps": absolute_maps(state.texture_maps).to_dict(),
            # The folder the set was read from (the 'texture set' field names it) and the slot a
            # dropped image fills: older sessions lack both.
            "texture_set_folder": absolute(state.texture_set_folder), "armed_slot": state.armed_slot,
            "camera": {k: getattr(orbit, k) for k in CAMERA_FIELDS},
            "settings": {**{k: getattr(state, k) for k in SETTING_FIELDS},
                         "use_file_materials": own_materials, "aa": state.aa,
                         # The view's resolution and its scale while moving (fixed or adaptive).
                         **{k: getattr(state, k) for k in SCALE_FIELDS},
                         # By name: a view added to DEBUG_VIEWS later does not shift a kept one.
                         "debug_view": DEBUG_VIEWS[state.debug_view], "debug_mip": state.debug_mip,
                         "display": dataclasses.asdict(state.display),
                         "lights": [dataclasses.asdict(light) for light in state.lights]},
            "compare": compare_dict}
    if turntable is not None:
        data["turntable"] = {"frames": turntable.frames, "path": output(turntable.path, DEFAULT_PATH)}
    if panel is not None:
        data["files"] = {k: output(v, DEFAULT_PATHS.get(k)) if isinstance(v, str) else v
                         for k, v in panel.kept_paths().items()}
        data["sections"] = panel.kept_sections()   # which of the panel's sections are open
    path = session_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, json.dumps(data, indent=1))


def restore_session(state, orbit, turntable=None, panel=None) -> str:
    """Apply the saved session to ``state`` and ``orbit`` (and ``turntable``, the window's
    turntable.TurntableSettings, and ``panel``'s path fields, when given). Returns '' or a one-line
    warning: a missing mesh or environment file (moved since) or a broken session file restores
    what it can."""
    path = session_path()
    if not path.is_file():
        return ""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        material = material_from_dict(data["material"], str(path))
        maps = TextureMaps.from_dict(data.get("texture_maps", {}), str(path))
    except (OSError, ValueError, KeyError, TypeError, AlightError) as exc:
        return f"{path}: last session not restored ({' '.join(str(exc).split())})"
    warning = ""
    state.material = material
    # Each map is read again; one that no longer reads (moved, broken since) is left empty.
    state.texture_maps = TextureMaps(uv_scale=maps.uv_scale, uv_offset=maps.uv_offset,
                                     normal_dx=maps.normal_dx, roughness_gloss=maps.roughness_gloss)
    for slot, map_path in maps.paths().items():
        try:
            state.set_map(slot, map_path, factor_to_1=False)
        except AlightError as exc:
            warning = str(exc)
    state.mark_saved()   # 'revert' goes back to the restored material with its maps
    if isinstance(data.get("texture_set_folder"), str):
        state.texture_set_folder = data["texture_set_folder"]
    if data.get("armed_slot") in MAP_SLOTS:
        state.armed_slot = data["armed_slot"]
    from alight.core.mesh import BUILTIN_MESHES

    said = ()
    # A mesh file is read on the panel's worker where the window made one (open_mesh_async): the
    # helmet's read and upload held the first frame for seconds. The own-materials box and the
    # camera then wait for it (``after_mesh``); a built-in is built here (7-41 ms).
    mesh_spec, after_mesh, pending_own = data.get("mesh"), [], True
    deferred = isinstance(mesh_spec, str) and mesh_spec not in BUILTIN_MESHES and state.open_mesh_async is not None
    for loader, spec in ((state.load_mesh, None if deferred else mesh_spec), (state.load_env, data.get("env"))):
        if isinstance(spec, str):
            try:
                loader(spec)
                said += state.warning_lines
            except AlightError as exc:
                warning = str(exc)
    if said:   # what the restored files are drawn without, in the status row
        state.warning_lines = said
        state.message = state.with_warnings("restored the last session")
    settings = data.get("settings")
    if isinstance(settings, dict):
        try:
            values, display, lights = _read_settings(settings)
        except (KeyError, TypeError, ValueError) as exc:
            warning = f"{path}: the view's settings not restored ({' '.join(str(exc).split())})"
        else:
            for k, v in values.items():
                setattr(state, k, v)
            state.display, state.lights = display, lights
            # The mesh file's own materials, as the artist left the box (loading the mesh ticked it
            # wherever the file has materials); older sessions lack it: the mesh's default stays.
            own = settings.get("use_file_materials")

            def own_materials(own=own) -> None:
                if isinstance(own, bool) and state.mesh is not None:
                    state.use_file_materials = own and any(part.material is not None for part in state.mesh.parts)

            after_mesh.append(own_materials)
            if isinstance(own, bool):
                pending_own = own
    if "compare" in data:   # the split view: on or off, the divider, what A is
        try:
            state.compare = compare.from_dict(data["compare"], str(path))
        except AlightError as exc:
            warning = " ".join(str(exc).split())
    spin = data.get("turntable")
    if turntable is not None and isinstance(spin, dict):   # (older sessions lack it)
        try:
            turntable.frames, turntable.path = _read_turntable(spin)
        except (KeyError, TypeError, ValueError) as exc:
            warning = f"{path}: the turntable's settings not restored ({' '.join(str(exc).split())})"
    files = data.get("files")
    if panel is not None and isinstance(files, dict):   # (older sessions lack it: the defaults stay)
        panel.restore_paths(files)
    sections = data.get("sections")
    if panel is not None and isinstance(sections, dict):   # (older sessions lack it: the defaults stay)
        panel.restore_sections(sections)
    camera = data.get("camera")
    if isinstance(camera, dict):
        try:
            values = {k: (tuple(float(x) for x in camera[k]) if k == "target" else float(camera[k]))
                      for k in CAMERA_FIELDS}
            for k, v in values.items():
                setattr(orbit, k, v)
            orbit.restored = True
            # The camera is kept for the restored mesh, not framed anew when it arrives (the
            # frame that showed the mesh before it took the flag).
            after_mesh.append(lambda: setattr(orbit, "restored", True))
        except (KeyError, TypeError, ValueError):
            pass
    if deferred:
        state.open_mesh_async(mesh_spec, then=lambda: [f() for f in after_mesh], own_materials=pending_own)
    else:
        for f in after_mesh:
            f()
    return warning


def _read_turntable(data: dict) -> tuple[int, str]:
    """(frames, path) from a session's "turntable". Errors: KeyError, TypeError, ValueError."""
    from alight.frontends.editor.turntable import MAX_FRAMES

    frames, path = data["frames"], data["path"]
    if isinstance(frames, bool) or not isinstance(frames, int) or not 2 <= frames <= MAX_FRAMES:
        raise ValueError(f"frames {frames!r} is not a whole number from 2 to {MAX_FRAMES}")
    if not isinstance(path, str):
        raise TypeError(f"path {path!r} is not text")
    return frames, path


def _read_settings(data: dict):
    """(state fields, Display, lights) from a session's "settings", checked as strictly as the
    CLI checks them. Errors: KeyError, TypeError, ValueError naming the field."""
    from alight.core.ibl_models import IBL_MODELS
    from alight.core.scene import BACKGROUNDS, LIGHT_KINDS, TONEMAPS, Display, Light
    from alight.core.visibility import OCCLUSION_MODES
    from alight.render.shadows import SHADOW_MODES

    def number(v, what):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ValueError(f"{what} is not a finite number")
        return float(v)

    def vec3(v, what):
        if not isinstance(v, (list, tuple)) or len(v) != 3:
            raise ValueError(f"{what} is not 3 numbers")
        return tuple(number(x, what) for x in v)

    def choice(v, options, what):
        if v not in options:
            raise ValueError(f"{what} '{v}' is not one of {', '.join(options)}")
        return v

    values = {"env_rotation_deg": number(data["env_rotation_deg"], "env_rotation_deg"),
              "env_intensity": max(0.0, number(data["env_intensity"], "env_intensity")),
              "ibl_enabled": bool(data["ibl_enabled"]),
              "ibl_model": choice(data["ibl_model"], tuple(IBL_MODELS), "ibl_model"),
              "multiple_scattering": bool(data["multiple_scattering"]),
              "lights_follow_env": bool(data.get("lights_follow_env", False)),   # (older sessions lack it)
              "occlusion": choice(data.get("occlusion", "auto"), OCCLUSION_MODES, "occlusion"),   # (... and it)
              # (... and these: 'alight render''s defaults)
              "shadows": choice(data.get("shadows", "auto"), SHADOW_MODES, "shadows"),
              "ground": bool(data.get("ground", False))}
    if "aa" in data:   # the anti-aliasing (older sessions lack it: the command line's stays)
        values["aa"] = choice(data["aa"], EDITOR_AA, "aa")
    for k in ("render_scale", "motion_scale"):   # (older sessions lack them: the command line's stay)
        if k in data:
            values[k] = min(1.0, max(0.25, number(data[k], k)))
    if "adaptive_motion" in data:
        values["adaptive_motion"] = bool(data["adaptive_motion"])
    if "debug_view" in data:   # (older sessions lack it and its mip: the shaded view stays)
        values["debug_view"] = DEBUG_VIEWS.index(choice(data["debug_view"], DEBUG_VIEWS, "debug_view"))
        values["debug_mip"] = number(data.get("debug_mip", 0.0), "debug_mip")
    d = data["display"]
    display = Display(tonemap=choice(d["tonemap"], TONEMAPS, "tonemap"), exposure=number(d["exposure"], "exposure"),
                      background=choice(d["background"], BACKGROUNDS, "background"),
                      background_color=vec3(d["background_color"], "background_color"),
                      blur_roughness=number(d["blur_roughness"], "blur_roughness"))
    lights = []
    for i, item in enumerate(data["lights"]):
        what = f"lights[{i}]"
        lights.append(Light(kind=choice(item["kind"], LIGHT_KINDS, f"{what}.kind"), vector=vec3(item["vector"], what),
                            color=vec3(item["color"], what), intensity=max(0.0, number(item["intensity"], what)),
                            direction=vec3(item["direction"], what),
                            inner_cone_deg=number(item["inner_cone_deg"], what),
                            outer_cone_deg=number(item["outer_cone_deg"], what),
                            range=None if item.get("range") is None else number(item["range"], what)))
    return values, display, lights
