"""The material library: materials saved from the editor, listed beside the F0 table's presets.

Each entry is one ``.glb`` file (factors and maps in one file, written by the glTF material
writer, ``alight.exchange.material_files``) in the library folder: ``ALIGHT_LIBRARY_DIR``, else
``library/`` in the user's data folder (``alight.paths.data_dir``). No GL and no imgui here: the
thumbnails are rendered by ``thumbnails.Thumbnails``, the panel draws the list.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path

from alight.core.material import Material
from alight.core.texture_maps import TextureMaps
from alight.errors import AlightError

LIBRARY_SUFFIX = ".glb"


def library_dir() -> Path:
    """Where library entries live: ``ALIGHT_LIBRARY_DIR``, else ``DATA/library`` (platformdirs'
    user data folder, ``~/.local/share/alight`` on Linux)."""
    explicit = os.environ.get("ALIGHT_LIBRARY_DIR")
    if explicit:   # absolute: the entries' paths (kept in a session) name them from any folder
        return Path(explicit).absolute()
    from alight.paths import data_dir

    return data_dir().absolute() / "library"


@dataclass(frozen=True)
class Entry:
    """One saved material: its name (the file's stem), the file, and what the file holds."""

    name: str
    path: str
    material: Material
    maps: TextureMaps


def holds(entry: Entry, material: Material, maps: TextureMaps) -> bool:
    """Whether ``entry`` holds ``material`` with ``maps``: numbers equal to float32 rounding, as
    the .glb stores them (a preset's F0 of 0.04 comes back from the file's ior as 0.04000000000000001:
    compared exactly, saving an unchanged material again asked to replace its own entry)."""
    if entry.maps != maps:
        return False
    a, b = dataclasses.asdict(entry.material), dataclasses.asdict(material)
    return all(_close(a[k], b[k]) for k in a)


def _close(x, y) -> bool:
    if isinstance(x, (tuple, list)) and isinstance(y, (tuple, list)):
        return len(x) == len(y) and all(_close(p, q) for p, q in zip(x, y))
    if isinstance(x, float) and isinstance(y, (int, float)) and not isinstance(y, bool):
        return x == y or abs(x - y) <= 1e-6 * max(abs(x), abs(y))   # float32's 2^-23 and then some
    return x == y


def entry_name(text: str) -> str:
    """A library name from a file name or typed text: the stem, with characters that do not
    belong in a file name replaced by '_'. Errors: AlightError when nothing is left."""
    stem = Path(text.strip()).stem if text.strip() else ""
    name = re.sub(r"[^A-Za-z0-9_.-]+", "_", stem).strip("._")
    if not name:
        raise AlightError(f"'{text}': not a library name (letters, digits, '_', '-', '.')")
    return name


def save_entry(material: Material, maps: TextureMaps, name: str, folder: Path | None = None) -> Path:
    """Write ``material`` and its maps into the library as ``NAME.glb`` (replacing an entry of
    that name; atomic). Returns the file. Errors: one-line AlightError naming the file."""
    from alight.exchange.material_files import save_material_file

    folder = Path(folder or library_dir())
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise AlightError(f"{folder}: cannot create the library folder ({exc.strerror})") from None
    path = folder / f"{entry_name(name)}{LIBRARY_SUFFIX}"
    save_material_file(material, path, maps)
    return path


def list_entries(folder: Path | None = None) -> tuple[list[Entry], list[str]]:
    """(entries by name, one line per file that does not read): a broken file in the library
    is listed as a problem, never stops the editor."""
    from alight.exchange.material_files import load_material_file

    folder = Path(folder or library_dir())
    entries, problems = [], []
    if not folder.is_dir():
        return entries, problems
    for path in sorted(folder.glob(f"*{LIBRARY_SUFFIX}")):
        try:
            material, maps, _ = load_material_file(str(path))
        except AlightError as exc:
            problems.append(" ".join(str(exc).split()))
            continue
        entries.append(Entry(path.stem, str(path), material, maps))
    return entries, problems


def preset_clashes(entries: list[Entry], presets) -> list[str]:
    """One warning line per entry named as a built-in preset (``presets``: their names; compared
    without case, as ``load_preset`` finds a preset): the panel lists such an entry as
    'NAME (library)', so the F0 table's NAME stays the preset and neither hides the other."""
    names = {p.lower() for p in presets}
    return [f"{e.path}: the library entry '{e.name}' has a built-in preset's name: listed as "
            f"'{e.name} (library)'; the F0 table's '{e.name}' is the preset"
            for e in entries if e.name.lower() in names]


def folder_stamp(folder: Path | None = None) -> tuple:
    """What changes when an entry is added, replaced or removed (names, mtimes, sizes): the
    panel lists the folder again only then."""
    folder = Path(folder or library_dir())
    try:
        return tuple(sorted((e.name, e.stat().st_mtime_ns, e.stat().st_size)
                            for e in os.scandir(folder) if e.name.endswith(LIBRARY_SUFFIX)))
    except OSError:
        return ()


def content_key(material: Material, maps: TextureMaps, salt: str = "") -> str:
    """A hex digest of what a thumbnail shows: every material field, the maps' tiling and
    conversions and the bytes of each map's file (a ``FILE#images[N]`` path: FILE's bytes and
    N). The same material saved under two names shares one thumbnail; a map file changed on
    disk gets a new one."""
    h = hashlib.sha256(salt.encode())
    h.update(json.dumps(dataclasses.asdict(material), sort_keys=True, default=repr).encode())
    paths = maps.paths()
    h.update(json.dumps({k: v for k, v in dataclasses.asdict(maps).items() if k not in paths},
                        sort_keys=True, default=repr).encode())
    for slot, path in sorted(paths.items()):
        file, _, part = path.partition("#")
        h.update(f"{slot}:{part}:".encode())
        try:
            h.update(hashlib.sha256(Path(file).read_bytes()).digest())
        except OSError:
            h.update(b"missing:" + file.encode())
    return h.hexdigest()[:32]
