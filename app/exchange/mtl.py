"""Wavefront MTL diffuse maps (``map_Kd``) with their options, which trimesh's MTL reader takes
for the file name (``map_Kd -s 1 1 1 checker.png`` loses its texture there).

The options are those of the MTL specification (Wavefront "Advanced Visualizer" manual,
appendix B1, "Texture map statements"): ``-o u v w`` moves the map's origin and ``-s u v w``
scales it, so a surface's uv reads the map at ``s * uv + o`` (kept as the texture transform);
``-blendu -blendv -boost -mm -t -texres -clamp -bm -imfchan -type -cc`` are read past. The
file name is everything after the options, spaces included.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

# Option name -> how many arguments it takes (None: 1 to 3 numbers).
_OPTIONS = {"-blendu": 1, "-blendv": 1, "-boost": 1, "-mm": 2, "-o": None, "-s": None, "-t": None,
            "-texres": 1, "-clamp": 1, "-bm": 1, "-imfchan": 1, "-type": 1, "-cc": 1}


@dataclass(frozen=True)
class DiffuseMap:
    """A material's map_Kd: the image file and its -o offset and -s scale (u, v)."""

    path: Path
    offset: tuple[float, float] = (0.0, 0.0)
    scale: tuple[float, float] = (1.0, 1.0)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def parse_map_statement(rest: str) -> tuple[str, dict[str, list[str]]]:
    """(file name, {option: arguments}) of the text after ``map_Kd``."""
    tokens = [(m.start(), m.group()) for m in re.finditer(r"\S+", rest)]
    options: dict[str, list[str]] = {}
    i = 0
    while i < len(tokens) and tokens[i][1] in _OPTIONS:
        name = tokens[i][1]
        count = _OPTIONS[name]
        i += 1
        args = []
        if count is None:
            while i < len(tokens) and len(args) < 3 and _is_number(tokens[i][1]):
                args.append(tokens[i][1])
                i += 1
        else:
            args = [t for _, t in tokens[i:i + count]]
            i += count
        options[name] = args
    name = rest[tokens[i][0]:].strip() if i < len(tokens) else ""
    return name, options


def _libraries(obj_path: Path) -> list[Path]:
    """The MTL files an OBJ names (``mtllib``; a name with spaces is tried whole first)."""
    try:
        data = obj_path.read_bytes()
    except OSError:
        return []
    out = []
    for match in re.finditer(rb"^[ \t]*mtllib[ \t]+(.+?)[ \t]*\r?$", data, re.MULTILINE):
        text = match.group(1).decode("utf-8", "replace")
        whole = obj_path.parent / text
        out.extend([whole] if whole.is_file() else [obj_path.parent / t for t in text.split()])
    return out


def missing_libraries(obj_path: Path) -> list[str]:
    """The names of the MTL files an OBJ's ``mtllib`` statements give that are not there (their
    materials are then drawn with the current material: worth one warning line)."""
    return list(dict.fromkeys(lib.name for lib in _libraries(obj_path) if not lib.is_file()))


def diffuse_maps(obj_path: Path) -> dict[str, DiffuseMap]:
    """map_Kd of every material in the OBJ's MTL files, by material name."""
    maps: dict[str, DiffuseMap] = {}
    for lib in _libraries(obj_path):
        try:
            lines = lib.read_text("utf-8", "replace").splitlines()
        except OSError:
            continue
        current = None
        for line in lines:
            key, _, rest = line.strip().partition(" ")
            if key == "newmtl":
                current = rest.strip()
            elif key.lower() == "map_kd" and current is not None:
                name, options = parse_map_statement(rest)
                if not name:
                    continue

                def pair(values, default):
                    numbers = [float(v) for v in values] or [default]
                    return (numbers[0], numbers[1] if len(numbers) > 1 else default)

                maps[current] = DiffuseMap(lib.parent / name.replace("\\", "/"),
                                           offset=pair(options.get("-o", []), 0.0),
                                           scale=pair(options.get("-s", []), 1.0))
    return maps


def material_names(obj_path: Path) -> set[str]:
    """The names every MTL file the OBJ names defines (``newmtl``)."""
    names: set[str] = set()
    for lib in _libraries(obj_path):
        try:
            text = lib.read_text("utf-8", "replace")
        except OSError:
            continue
        for line in text.splitlines():
            key, _, rest = line.strip().partition(" ")
            if key == "newmtl":
                names.add(rest.strip())
    return names
