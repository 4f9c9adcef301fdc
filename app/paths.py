"""Where alight's files are: its shaders and presets (in a checkout or an installed wheel), and
the user's cache and config folders (platformdirs; never the working directory)."""

from __future__ import annotations

import os
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def _data_dir(name: str) -> Path:
    # An installed wheel carries the folder inside the package; a checkout (and an editable
    # install, which maps the package onto app/) has it beside app/.
    for candidate in (_PACKAGE / name, _PACKAGE.parent / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"alight's {name}/ folder is missing (looked in {_PACKAGE} and its parent)")


def shader_dir() -> Path:
    return _data_dir("shaders")


def preset_dir() -> Path:
    return _data_dir("presets")


def cache_dir() -> Path:
    """Caches alight can rebuild (bakes, the BRDF LUT, chart references): ``ALIGHT_CACHE_DIR``,
    else the platform's user cache folder (``~/.cache/alight`` on Linux, honouring XDG_CACHE_HOME)."""
    explicit = os.environ.get("ALIGHT_CACHE_DIR")
    if explicit:
        return Path(explicit)
    import platformdirs

    return Path(platformdirs.user_cache_dir("alight", appauthor=False))


def config_dir() -> Path:
    """The editor's own state (its last session, imgui's window layout): ``ALIGHT_CONFIG_DIR``,
    else the platform's user config folder (``~/.config/alight`` on Linux, honouring XDG_CONFIG_HOME)."""
    explicit = os.environ.get("ALIGHT_CONFIG_DIR")
    if explicit:
        return Path(explicit)
    import platformdirs

    return Path(platformdirs.user_config_dir("alight", appauthor=False))


def data_dir() -> Path:
    """What the user keeps (the editor's material library): ``ALIGHT_DATA_DIR``, else the
    platform's user data folder (``~/.local/share/alight`` on Linux, honouring XDG_DATA_HOME)."""
    explicit = os.environ.get("ALIGHT_DATA_DIR")
    if explicit:
        return Path(explicit)
    import platformdirs

    return Path(platformdirs.user_data_dir("alight", appauthor=False))


def absolute(path: str) -> str:
    """``path`` made absolute against the working directory now ('' stays ''); '~' expanded.
    What the editor keeps (its session, the fields it restores, the maps it watches) is stored
    so: a relative path would name another file once the editor is started from another folder."""
    if not path:
        return path
    return os.path.abspath(os.path.expanduser(os.fspath(path)))


def absolute_maps(maps):
    """A TextureMaps with every slot's path ``absolute`` (a ``FILE#images[N]`` keeps its part)."""
    for slot, path in maps.paths().items():
        maps = maps.with_slot(slot, absolute(path))
    return maps
