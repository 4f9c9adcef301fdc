"""Preset files: the shipped F0 table (``presets/``) and users' material JSON files.

Reading goes through ``alight.core.material.material_from_dict`` (every field validated, one
line per problem naming the file); writing validates first and is atomic, so a bad material
never replaces a good file.
"""

from __future__ import annotations

import difflib
import json
import os
from pathlib import Path
from typing import Any

from alight.core.material import (
    PRESET_NAMES,
    Material,
    _fail,
    material_from_dict,
    validate_material,
)
from alight.core.shading import linear_to_srgb
from alight.exchange.output import write_text_atomic
from alight.paths import preset_dir


def list_presets() -> list[str]:
    """Table order first (the order people learn them in), then any extra files alphabetically."""
    found = {p.stem for p in preset_dir().glob("*.json") if p.is_file()}
    return [n for n in PRESET_NAMES if n in found] + sorted(found - set(PRESET_NAMES))


def did_you_mean(text: str) -> str:
    """' (did you mean gold?)' for a misspelt preset name ('gld'), else '': a user who mistyped
    one name should not have to find it in the list of all of them."""
    close = difflib.get_close_matches(Path(text).stem.lower(), list_presets(), n=1)
    return f" (did you mean {close[0]}?)" if close else ""


def _read_json(path: Path, source: str) -> Any:
    try:
        data = path.read_bytes()
    except OSError as e:
        raise _fail(source, f"cannot read ({e.strerror or e})") from None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise _fail(source, f"not UTF-8 text (bad byte at offset {e.start})") from None
    if not text.strip():
        raise _fail(source, "file is empty")
    try:
        return json.loads(text)
    except json.JSONDecodeError as e:
        raise _fail(source, f"not valid JSON (line {e.lineno}: {e.msg})") from None
    except RecursionError:
        raise _fail(source, "not valid JSON (nested too deeply)") from None


def load_preset(name_or_path: str | os.PathLike) -> Material:
    """A preset name wins over a same-named file in the working directory, so 'gold' always
    means the shipped gold; anything else is read as a path."""
    text = os.fspath(name_or_path)
    by_name = {p.stem.lower(): p for p in preset_dir().glob("*.json") if p.is_file()}
    path = by_name.get(text.lower())
    if path is None:
        path = Path(text)
        if not text or not os.path.lexists(path):
            raise _fail(text or "''", f"no preset or file of that name{did_you_mean(text)} "
                                       f"(presets: {', '.join(list_presets())})")
    source = str(path) if path.parent != preset_dir() else f"presets/{path.name}"
    return material_from_dict(_read_json(path, source), source)


def _to_json(d: dict[str, Any]) -> str:
    """One field per line with vectors kept on their line, so preset diffs stay readable."""
    return "{\n" + ",\n".join(f"  {json.dumps(k)}: {json.dumps(v)}" for k, v in d.items()) + "\n}\n"


def save_preset(m: Material, path: str | os.PathLike, description: str = "") -> None:
    """Validate first so an invalid material never replaces a good file; the atomic write means a
    failure part way leaves the old file (and no temporary) behind."""
    source = os.fspath(path)
    m = validate_material(m, source)
    f0 = m.f0()
    d = m.to_dict()
    if description:
        d["description"] = description
    # Documentation copies, rounded within the tolerances material_from_dict checks them to.
    d["f0_linear"] = [round(x, 6) for x in f0]
    d["f0_srgb"] = [round(float(x), 4) for x in linear_to_srgb(f0)]
    try:
        write_text_atomic(path, _to_json(d))
    except OSError as e:
        raise _fail(source, f"cannot write ({e.strerror or e})") from None
