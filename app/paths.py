"""Where the shader and preset files are, in a source checkout and in an installed wheel."""

from __future__ import annotations

import os
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def _data_dir(name: str) -> Path:
    # An installed wheel carries the folder inside the package; a checkout has it beside app/.
    for candidate in (_PACKAGE / name, _PACKAGE.parent / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"alight's {name}/ folder is missing (looked in {_PACKAGE} and its parent)")


def shader_dir() -> Path:
    return _data_dir("shaders")


def preset_dir() -> Path:
    return _data_dir("presets")


def cache_dir() -> Path:
    """The user's cache directory for alight (ALIGHT_CACHE_DIR, else XDG_CACHE_HOME/alight)."""
    explicit = os.environ.get("ALIGHT_CACHE_DIR")
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "alight"
