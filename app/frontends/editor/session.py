"""The last session (mesh, environment, material, camera), so the editor reopens where the
artist left it. A JSON file in the user's config folder (``alight.paths.config_dir``), written
atomically on close."""

from __future__ import annotations

import json
from pathlib import Path

from alight.core.material import material_from_dict
from alight.core.texture_maps import TextureMaps
from alight.errors import AlightError
from alight.exchange.output import write_text_atomic
from alight.paths import config_dir

CAMERA_FIELDS = ("target", "yaw_deg", "pitch_deg", "distance", "fov_y_deg", "radius")


def session_path() -> Path:
    return config_dir() / "editor-session.json"


def save_session(state, orbit) -> None:
    data = {"mesh": state.mesh_spec, "env": state.env_spec, "material": state.material.to_dict(),
            "texture_maps": state.texture_maps.to_dict(),
            "camera": {k: getattr(orbit, k) for k in CAMERA_FIELDS}}
    path = session_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, json.dumps(data, indent=1))


def restore_session(state, orbit) -> str:
    """Apply the saved session to ``state`` and ``orbit``. Returns '' or a one-line warning: a
    missing mesh or environment file (moved since) or a broken session file restores what it can."""
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
    state.material = state.saved_material = material
    # Each map is read again; one that no longer reads (moved, broken since) is left empty.
    state.texture_maps = TextureMaps(uv_scale=maps.uv_scale, uv_offset=maps.uv_offset,
                                     normal_dx=maps.normal_dx, roughness_gloss=maps.roughness_gloss)
    for slot, map_path in maps.paths().items():
        try:
            state.set_map(slot, map_path, factor_to_1=False)
        except AlightError as exc:
            warning = str(exc)
    for loader, spec in ((state.load_mesh, data.get("mesh")), (state.load_env, data.get("env"))):
        if isinstance(spec, str):
            try:
                loader(spec)
            except AlightError as exc:
                warning = str(exc)
    camera = data.get("camera")
    if isinstance(camera, dict):
        try:
            values = {k: (tuple(float(x) for x in camera[k]) if k == "target" else float(camera[k]))
                      for k in CAMERA_FIELDS}
            for k, v in values.items():
                setattr(orbit, k, v)
            orbit.restored = True
        except (KeyError, TypeError, ValueError):
            pass
    return warning
