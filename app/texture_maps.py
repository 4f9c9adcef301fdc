"""Texture maps loaded by the user for the edited material: which file fills each slot (plain,
comparable state the editor's undo and session keep) and the reading of those files.

Slots follow glTF's metal-roughness model, plus separate greyscale metallic and roughness maps
as many texture sets ship them (their R channel is read; over a metallic-roughness map they
replace its B or G channel). Colour maps (base colour, emissive) are sRGB-encoded; the others
hold data. The renderer gets paths and decoded images, never a file to read.
"""

from __future__ import annotations

import collections
import math
import os
from dataclasses import asdict, dataclass, replace

import numpy as np

from app.errors import AlightError

MAP_SLOTS = ("base_color", "metallic_roughness", "metallic", "roughness", "normal", "emissive", "occlusion")
SLOT_LABELS = {"base_color": "base colour", "metallic_roughness": "metal-rough (G rough, B metal)",
               "metallic": "metallic (grey)", "roughness": "roughness (grey)", "normal": "normal (tangent)",
               "emissive": "emissive", "occlusion": "occlusion (R)"}
SRGB_SLOTS = ("base_color", "emissive")
# What a dropped file with one of these suffixes is (.hdr and .exr stay environments).
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tga", ".tif", ".tiff", ".bmp", ".webp")
MAX_MAP_SIZE = 8192


@dataclass(frozen=True)
class TextureMaps:
    """A path per slot ('' = none) and the UV transform ``uv * uv_scale + uv_offset``."""

    base_color: str = ""
    metallic_roughness: str = ""
    metallic: str = ""
    roughness: str = ""
    normal: str = ""
    emissive: str = ""
    occlusion: str = ""
    uv_scale: tuple[float, float] = (1.0, 1.0)
    uv_offset: tuple[float, float] = (0.0, 0.0)

    def paths(self) -> dict[str, str]:
        """The filled slots: slot -> path."""
        return {slot: getattr(self, slot) for slot in MAP_SLOTS if getattr(self, slot)}

    def with_slot(self, slot: str, path: str) -> "TextureMaps":
        if slot not in MAP_SLOTS:
            raise AlightError(f"texture slot '{slot}' is not one of {', '.join(MAP_SLOTS)}")
        return replace(self, **{slot: path})

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict, where: str) -> "TextureMaps":
        """The session file's form back; a value of the wrong type is an AlightError naming ``where``."""
        if not isinstance(data, dict):
            raise AlightError(f"{where}: texture_maps is not an object")
        kwargs = {}
        for slot in MAP_SLOTS:
            value = data.get(slot, "")
            if not isinstance(value, str):
                raise AlightError(f"{where}: texture_maps.{slot} is not a path")
            kwargs[slot] = value
        for name in ("uv_scale", "uv_offset"):
            value = data.get(name, getattr(cls, name))
            try:
                pair = tuple(float(x) for x in value)
            except (TypeError, ValueError):
                raise AlightError(f"{where}: texture_maps.{name} is not two numbers") from None
            if len(pair) != 2 or not all(math.isfinite(x) for x in pair):
                raise AlightError(f"{where}: texture_maps.{name} is not two finite numbers")
            kwargs[name] = pair
        return cls(**kwargs)


# Decoded images by (absolute path, modification time, size): reloading an unchanged file is free.
_CACHE: collections.OrderedDict[tuple, np.ndarray] = collections.OrderedDict()
_CACHE_ENTRIES = 16


def load_map_image(path: str) -> np.ndarray:
    """An image file as (H, W, 4) uint8, row 0 = top (as app.mesh gives file textures): grey is
    spread to RGB, a missing alpha is 255, 16-bit and float files are rescaled to 8 bits.
    Any failure is an AlightError of one line naming the file."""
    if not os.path.exists(path):
        raise AlightError(f"{path}: no such file")
    if os.path.isdir(path):
        raise AlightError(f"{path}: is a directory, not an image")
    stat = os.stat(path)
    if stat.st_size == 0:
        raise AlightError(f"{path}: empty file")
    key = (os.path.abspath(path), stat.st_mtime_ns, stat.st_size)
    if key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key]
    try:
        image = _read(path)
    except AlightError:
        raise
    except MemoryError:
        raise AlightError(f"{path}: not enough memory to read the texture map") from None
    except Exception as exc:   # anything OIIO or numpy throws: one line, no traceback
        raise AlightError(f"{path}: cannot read texture map ({_one_line(exc)})") from None
    image.setflags(write=False)
    _CACHE[key] = image
    while len(_CACHE) > _CACHE_ENTRIES:
        _CACHE.popitem(last=False)
    return image


def _read(path: str) -> np.ndarray:
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise AlightError(f"{path}: cannot read texture map ({_one_line(oiio.geterror()) or 'unknown format'})")
    try:
        spec = inp.spec()
        w, h, c = int(spec.width), int(spec.height), int(spec.nchannels)
        if w <= 0 or h <= 0 or c <= 0:
            raise AlightError(f"{path}: empty image ({w}x{h}, {c} channels)")
        if max(w, h) > MAX_MAP_SIZE:
            raise AlightError(f"{path}: {w}x{h} is larger than {MAX_MAP_SIZE} pixels a side")
        pixels = inp.read_image(0, 0, 0, min(c, 4), oiio.UINT8)
        err = inp.geterror()
        if pixels is None or isinstance(pixels, bool) or err:
            raise AlightError(f"{path}: corrupt or truncated image ({_one_line(err or oiio.geterror()) or 'read failed'})")
    finally:
        inp.close()
    pixels = np.asarray(pixels, dtype=np.uint8).reshape(h, w, min(c, 4))
    if pixels.shape[2] in (1, 2):     # grey (and alpha)
        grey = np.repeat(pixels[:, :, :1], 3, axis=2)
        alpha = pixels[:, :, 1:2] if pixels.shape[2] == 2 else np.full((h, w, 1), 255, np.uint8)
        pixels = np.concatenate([grey, alpha], axis=2)
    elif pixels.shape[2] == 3:
        pixels = np.concatenate([pixels, np.full((h, w, 1), 255, np.uint8)], axis=2)
    return np.ascontiguousarray(pixels)


def _one_line(text) -> str:
    return " ".join(str(text or "").split())
