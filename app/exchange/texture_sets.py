"""Texture sets: the files of a folder (or several files dropped at once) assigned to a material's
texture slots (``alight.core.texture_maps``) by the names artists' tools give them, and the
decoding of a slot's file with the conversions the assignment asks for.

Names are matched on the file's stem, case-insensitive, separators ignored, after a trailing
resolution (``_2K``, ``_4k``, ``_2048``) is dropped. The suffixes each tool writes:

    Substance      _BaseColor _Normal _Roughness _Metallic _AO/_AmbientOcclusion _Emissive _Height _Opacity
    ambientCG      _Color _NormalGL _NormalDX _Roughness _Metalness _AmbientOcclusion _Displacement
    Poly Haven     _diff _nor_gl _nor_dx _rough _metal _ao _arm
    Quixel/Unreal  _Albedo _Normal _Roughness _Gloss _ORM
    glTF exports   _baseColor _metallicRoughness _metalRoughness _occlusionRoughnessMetallic (Khronos samples)
    plain          albedo diffuse basecolor (the whole name or its end)

Conversions: a DirectX normal map (green down: ``_NormalDX``, ``_nor_dx``) has its green flipped
to glTF's OpenGL convention; a gloss map becomes roughness = 1 - gloss; a packed ORM/ARM map
(R occlusion, G roughness, B metal) fills the occlusion slot (glTF reads R) and the
metallic-roughness slot (glTF reads G = roughness, B = metal), the layout glTF itself packs, so it
is split by the channels each slot reads; a glTF metallic-roughness map (``_metalRoughness``, G
roughness, B metal) fills that slot (it went to the grey roughness slot by its name's end,
which reads R: DamagedHelmet's drew as a mirror); separate greyscale roughness and metal maps fill their
own slots and are packed into glTF's one metallic-roughness image when written
(``alight.exchange.gltf_export``). Heights, displacement and opacity are left out with a note:
alight draws no displacement and its maps are opaque.
"""

from __future__ import annotations

import dataclasses
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from alight.core.texture_maps import MAP_SLOTS, TextureMaps
from alight.errors import AlightError
from alight.exchange.images import IMAGE_SUFFIXES, load_map_image

# Roles a file can have: the slots plus the conversions and the files left out.
# name (compact: lower case, no separators) -> role
_NAMES: dict[str, str] = {}
for _role, _names in {
    "base_color": ("basecolor", "basecolour", "color", "colour", "albedo", "diffuse", "diff", "col"),
    "normal": ("normal", "normalgl", "norgl", "normalopengl", "nor", "nrm"),
    "normal_dx": ("normaldx", "nordx", "normaldirectx"),
    "roughness": ("roughness", "rough"),
    # glTF's packed layout (G roughness, B metal): matched before 'roughness' by being longer.
    "metallic_roughness": ("metallicroughness", "metalroughness", "metalrough", "roughmetal", "roughnessmetallic",
                           "roughnessmetalness", "metalnessroughness", "roughnessmetal"),
    "gloss": ("gloss", "glossiness"),
    "metallic": ("metallic", "metalness", "metal"),
    "occlusion": ("ao", "ambientocclusion", "occlusion"),
    "emissive": ("emissive", "emission", "emit"),
    "orm": ("orm", "arm", "occlusionroughnessmetallic", "occlusionroughnessmetalness", "occlusionroughmetal",
            "aoroughnessmetallic", "aoroughmetal"),
    "height": ("height", "displacement", "disp", "bump"),
    "opacity": ("opacity", "alpha", "mask"),
}.items():
    for _name in _names:
        _NAMES[_name] = _role

# What each role is called in the assignment's report.
ROLE_LABELS = {"base_color": "base colour", "normal": "normal", "normal_dx": "normal (DirectX: green flipped)",
               "roughness": "roughness", "gloss": "roughness (gloss inverted)", "metallic": "metallic",
               "occlusion": "occlusion", "emissive": "emissive",
               "metallic_roughness": "metal-rough (G rough, B metal)",
               "orm": "occlusion (R) + metal-rough (G rough, B metal)"}
LEFT_OUT = {"height": "heights and displacement are not drawn: alight has no displacement",
            "opacity": "opacity is not drawn: alight's maps are opaque"}
# Names --map accepts beside MAP_SLOTS: the conversions by name.
MAP_ALIASES = ("normal_dx", "gloss", "orm", "arm")
# Which file wins when two fill one slot: lossless formats first.
_SUFFIX_RANK = (".png", ".tif", ".tiff", ".exr", ".tga", ".bmp", ".webp", ".jpg", ".jpeg")
_RESOLUTION = re.compile(r"^(\d+k|\d+|\d+x\d+|\d+px)$")
SET_SUFFIXES = (*IMAGE_SUFFIXES, ".exr")


@dataclass(frozen=True)
class Assigned:
    """One file of a set and what became of it: ``slots`` it fills (empty: left out),
    ``name`` the suffix that was recognised ('' when none), ``note`` the conversion or why it
    was left out."""

    path: str
    slots: tuple[str, ...]
    name: str = ""
    note: str = ""

    def line(self) -> str:
        what = ", ".join(self.slots) if self.slots else "left out"
        return f"{os.path.basename(self.path)} -> {what}" + (f" ({self.note})" if self.note else "")


@dataclass
class TextureSet:
    """The assignment: ``maps`` (the base maps with the set's slots filled and conversions
    set) and every file's ``Assigned`` entry in name order."""

    maps: TextureMaps
    files: list[Assigned] = field(default_factory=list)

    @property
    def slots(self) -> tuple[str, ...]:
        """The slots this set's files filled (not those of the maps it was laid over)."""
        return tuple(s for s in MAP_SLOTS if any(s in a.slots for a in self.files))

    def lines(self) -> list[str]:
        return [a.line() for a in self.files]

    def notes(self) -> list[str]:
        """One line per file left out (what the picture is drawn without)."""
        return [a.line() for a in self.files if not a.slots]


def role_of(path: str | os.PathLike) -> tuple[str, str] | None:
    """(role, the name recognised) for a file name, or None. Roles: MAP_SLOTS' names and
    'normal_dx', 'gloss', 'orm', 'height', 'opacity'."""
    tokens = [t for t in re.split(r"[^a-z0-9]+", Path(path).stem.lower()) if t]
    while len(tokens) > 1 and _RESOLUTION.match(tokens[-1]):
        tokens.pop()
    # The last k tokens joined, longest first, so 'nor_gl' beats 'gl' and 'base_color' 'color'.
    for k in range(min(len(tokens), 3), 0, -1):
        name = "".join(tokens[-k:])
        if name in _NAMES:
            return _NAMES[name], name
    # Names written without separators ('RockBaseColor'): the longer names only, so that
    # 'gunmetal' is not a metal map.
    compact = "".join(tokens)
    for name in sorted(_NAMES, key=len, reverse=True):
        if len(name) >= 6 and compact.endswith(name):
            return _NAMES[name], name
    return None


def _rank(path: str) -> tuple:
    suffix = Path(path).suffix.lower()
    return (_SUFFIX_RANK.index(suffix) if suffix in _SUFFIX_RANK else len(_SUFFIX_RANK), path)


def assign_files(paths, base: TextureMaps | None = None) -> TextureSet:
    """Files to slots by their names (module docstring), on top of ``base`` (its tiling kept,
    its slots replaced where the set has a file). Files of no known name are left out with a
    note; two files for one slot: the lossless format, then the first name, wins; an OpenGL
    normal map wins over a DirectX twin, roughness over gloss, separate AO/roughness/metal
    maps over an ORM's channels."""
    paths = sorted(dict.fromkeys(os.fspath(p) for p in paths), key=_rank)
    by_role: dict[str, list[tuple[str, str]]] = {}
    files: dict[str, Assigned] = {}
    for p in paths:
        found = role_of(p)
        if found is None:
            files[p] = Assigned(p, (), "", "name not recognised")
            continue
        role, name = found
        if role in LEFT_OUT:
            files[p] = Assigned(p, (), name, LEFT_OUT[role])
            continue
        by_role.setdefault(role, []).append((p, name))
    maps = base or TextureMaps()   # its conversions change only where the set brings the slot

    def take(role: str, loser_note: str = "another file fills the slot") -> tuple[str, str] | None:
        found = by_role.get(role) or []
        for p, name in found[1:]:
            files[p] = Assigned(p, (), name, loser_note)
        return found[0] if found else None

    def put(p: str, name: str, slots: tuple[str, ...], note: str = "") -> None:
        nonlocal maps
        for slot in slots:
            maps = maps.with_slot(slot, p)
        files[p] = Assigned(p, slots, name, note)

    for role in ("base_color", "emissive", "metallic", "occlusion"):
        got = take(role)
        if got:
            put(*got, (role,))
    normal, normal_dx = take("normal"), take("normal_dx")
    if normal:
        put(*normal, ("normal",))
        maps = dataclasses.replace(maps, normal_dx=False)
        if normal_dx:
            files[normal_dx[0]] = Assigned(normal_dx[0], (), normal_dx[1], "its OpenGL twin fills the normal slot")
    elif normal_dx:
        put(*normal_dx, ("normal",), "DirectX normal: green flipped")
        maps = dataclasses.replace(maps, normal_dx=True)
    rough, gloss = take("roughness"), take("gloss")
    if rough:
        put(*rough, ("roughness",))
        maps = dataclasses.replace(maps, roughness_gloss=False)
        if gloss:
            files[gloss[0]] = Assigned(gloss[0], (), gloss[1], "a roughness map fills the slot")
    elif gloss:
        put(*gloss, ("roughness",), "gloss: inverted to roughness")
        maps = dataclasses.replace(maps, roughness_gloss=True)
    packed = take("metallic_roughness")
    if packed:
        if (rough or gloss) and by_role.get("metallic"):   # separate greyscale maps win, as over an ORM's
            files[packed[0]] = Assigned(packed[0], (), packed[1], "separate roughness and metal maps fill its slots")
        else:
            put(*packed, ("metallic_roughness",), "packed: G roughness, B metal")
    orm = take("orm")
    if orm:
        have = {s for s in ("occlusion", "roughness", "metallic", "metallic_roughness")
                if any(a.slots == (s,) for a in files.values())}
        slots = tuple(s for s, needed in (("occlusion", "occlusion" not in have),
                                          ("metallic_roughness", not ({"roughness", "metallic"} <= have
                                                                      or "metallic_roughness" in have))) if needed)
        if slots:
            put(*orm, slots, "packed: R occlusion, G roughness, B metal")
        else:
            files[orm[0]] = Assigned(orm[0], (), orm[1], "separate occlusion, roughness and metal maps fill its slots")
    return TextureSet(maps, [files[p] for p in sorted(files)])


def set_name(paths, folder: str | os.PathLike = "") -> str:
    """A texture set's name, for the material it makes: ``folder``'s name when the set is a
    folder, else the stem its map files share once the map names and resolutions are dropped
    (``Wood049`` from Wood049_2K_Color.png and Wood049_2K_NormalGL.png), else the files' folder's
    name; '' when there is none."""
    if folder:
        return Path(os.path.abspath(folder)).name
    stems = []
    for p in paths:
        found = role_of(p)
        if found is None:
            continue
        tokens = [t for t in re.split(r"[^A-Za-z0-9]+", Path(p).stem) if t]
        while len(tokens) > 1 and _RESOLUTION.match(tokens[-1].lower()):
            tokens.pop()
        for k in range(min(len(tokens), 3), 0, -1):   # the recognised name, as role_of matched it
            if "".join(tokens[-k:]).lower() == found[1]:
                tokens = tokens[:-k]
                break
        else:   # written without a separator ('RockBaseColor'): the name cut off the last token
            tokens[-1] = tokens[-1][:-len(found[1])]
            tokens = [t for t in tokens if t]
        while tokens and _RESOLUTION.match(tokens[-1].lower()):
            tokens.pop()
        stems.append(tokens)
    common = []
    for group in zip(*stems) if stems else ():
        if len(set(group)) > 1:
            break
        common.append(group[0])
    if common:
        return "_".join(common)
    parents = {Path(os.path.abspath(p)).parent.name for p in paths}
    return parents.pop() if len(parents) == 1 else ""


def assign_folder(folder: str | os.PathLike, base: TextureMaps | None = None) -> TextureSet:
    """Every image file directly in ``folder`` (not its subfolders), assigned by ``assign_files``.
    A missing folder, or one without an image of a known name, is an AlightError naming it."""
    d = Path(folder)
    if not d.is_dir():
        raise AlightError(f"{d}: {'no such folder' if not d.exists() else 'not a folder'} (a texture set is a folder of maps)")
    paths = [str(p) for p in d.iterdir() if p.is_file() and p.suffix.lower() in SET_SUFFIXES]
    result = assign_files(paths, base)
    if not result.slots:
        raise AlightError(f"{d}: no texture map of a known name in the folder "
                          f"(e.g. NAME_BaseColor.png, NAME_Normal.png, NAME_Roughness.png)")
    return result


def apply_map(maps: TextureMaps, name: str, path: str, source: str = "--map") -> tuple[TextureMaps, tuple[str, ...]]:
    """One map given by slot name: a MAP_SLOTS name or 'normal_dx' (a DirectX normal map),
    'gloss' (a gloss map, into roughness), 'orm'/'arm' (packed R occlusion, G roughness,
    B metal). Returns the maps and the slots filled; a bad name or a missing file is an
    AlightError of one line naming ``source``."""
    key = name.strip().lower().replace("-", "_")
    if key not in MAP_SLOTS and key not in MAP_ALIASES:
        raise AlightError(f"{source}: unknown texture slot {name!r} (slots: {', '.join((*MAP_SLOTS, *MAP_ALIASES))})")
    if not path:
        raise AlightError(f"{source}: {name}= needs an image file")
    if "#images[" not in path and not os.path.isfile(path):
        raise AlightError(f"{source}: {name}={path}: {'not a file' if os.path.exists(path) else 'no such file'}")
    if key == "normal_dx":
        return dataclasses.replace(maps.with_slot("normal", path), normal_dx=True), ("normal",)
    if key == "gloss":
        return dataclasses.replace(maps.with_slot("roughness", path), roughness_gloss=True), ("roughness",)
    if key in ("orm", "arm"):
        return maps.with_slot("occlusion", path).with_slot("metallic_roughness", path), ("occlusion", "metallic_roughness")
    if key == "normal":
        maps = dataclasses.replace(maps, normal_dx=False)
    if key == "roughness":
        maps = dataclasses.replace(maps, roughness_gloss=False)
    return maps.with_slot(key, path), (key,)


def parse_map_option(text: str, source: str = "--map") -> tuple[str, str]:
    """'SLOT=PATH' as (slot, path); the slot is checked by ``apply_map``."""
    name, sep, path = str(text).partition("=")
    if not sep or not name.strip():
        raise AlightError(f"{source}: expected SLOT=PATH, got {text!r}")
    return name.strip(), path


def load_slot_image(maps: TextureMaps, slot: str) -> np.ndarray:
    """The slot's file decoded ((H, W, 4) uint8, row 0 = top; ``alight.exchange.images``) with
    the maps' conversions: normal_dx flips the normal map's green (G' = 255 - G, exact in 8
    bits), roughness_gloss inverts the roughness slot's RGB. A path ``FILE#images[N]`` is an
    image inside a glTF file. Errors: one-line AlightError naming the file."""
    path = getattr(maps, slot)
    image = _decode(path)
    if slot == "normal" and maps.normal_dx:
        image = image.copy()
        image[:, :, 1] = 255 - image[:, :, 1]
    elif slot == "roughness" and maps.roughness_gloss:
        image = image.copy()
        image[:, :, :3] = 255 - image[:, :, :3]
    return image


def load_map_images(maps: TextureMaps) -> dict[str, np.ndarray]:
    """Every filled slot's image by path, as ``alight.core.scene.Scene.texture_images`` wants."""
    return {path: load_slot_image(maps, slot) for slot, path in maps.paths().items()}


def _decode(path: str) -> np.ndarray:
    m = re.fullmatch(r"(.*)#images\[(\d+)\]", path)
    if m is None:
        return load_map_image(path)
    from alight.exchange.gltf import gltf_image

    return gltf_image(m.group(1), int(m.group(2)))
