"""Texture maps loaded by the user for the edited material: which file fills each slot (plain,
comparable state the editor's undo and session keep). ``alight.exchange.images`` reads the files.

This is the one model of a material's maps that presets, the CLI, the Python API, batch and the
editor share. Each slot is a glTF textureInfo with the defaults alight writes and reads for it:
the image (a path), texCoord 0, the default sampler (repeat, trilinear) and one
KHR_texture_transform shared by every slot (``uv_scale``/``uv_offset``, no rotation);
``alight.exchange.gltf_export`` writes exactly that, ``alight.exchange.material_files`` reads it
back.

Slots follow glTF's metal-roughness model, plus separate greyscale metallic and roughness maps
as many texture sets ship them (their R channel is read; over a metallic-roughness map they
replace its B or G channel). Colour maps (base colour, emissive) are sRGB-encoded; the others
hold data. The renderer gets paths and decoded images, never a file to read
(``alight.exchange.texture_sets.load_map_images`` decodes them, applying the two conversions
below).

A path may name an image inside a glTF file: ``FILE.glb#images[N]``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

from alight.errors import AlightError

MAP_SLOTS = ("base_color", "metallic_roughness", "metallic", "roughness", "normal", "emissive", "occlusion")
SLOT_LABELS = {"base_color": "base colour", "metallic_roughness": "metal-rough (G rough, B metal)",
               "metallic": "metallic (grey)", "roughness": "roughness (grey)", "normal": "normal (tangent)",
               "emissive": "emissive", "occlusion": "occlusion (R)"}
SRGB_SLOTS = ("base_color", "emissive")
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
    # Conversions applied as the file is decoded: a DirectX normal map (green down) has its
    # green flipped to glTF's (OpenGL, green up); a gloss map in the roughness slot is inverted.
    normal_dx: bool = False
    roughness_gloss: bool = False

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
        for name in ("normal_dx", "roughness_gloss"):
            value = data.get(name, False)
            if not isinstance(value, bool):
                raise AlightError(f"{where}: texture_maps.{name} is not true or false")
            kwargs[name] = value
        return cls(**kwargs)


# The factor each slot multiplies (glTF 2.0 section 3.9: a map is multiplied by its factor).
SLOT_FACTORS = {"base_color": {"base_color": (1.0, 1.0, 1.0)},
                "metallic_roughness": {"metallic": 1.0, "roughness": 1.0},
                "metallic": {"metallic": 1.0}, "roughness": {"roughness": 1.0},
                "emissive": {"emissive": (1.0, 1.0, 1.0)}}


def map_factors(slots) -> dict:
    """The material fields set to 1 when maps are loaded into ``slots`` (glTF's convention:
    a loaded map is the value, its factor 1), so a set loaded over gold is not tinted by it."""
    out: dict = {}
    for slot in slots:
        out.update(SLOT_FACTORS.get(slot, {}))
    return out


def factors_without_maps(material, maps: TextureMaps, images: dict):
    """The factors that draw ``material`` without its maps closest to how it looks with them
    (a .json preset holds factors only): each scaled factor times its map's mean texel (colour
    maps decoded from sRGB first), except the emissive factor, times the map's median: an
    emissive map lights a few spots and leaves the rest dark, and its mean spread over the whole
    surface read as a self-lit object. glTF sets a loaded map's factor to 1 (``map_factors``),
    so the factors alone drew DamagedHelmet white, fully metallic and glowing. Normal and
    occlusion maps have no factor to carry. ``images``: path -> (H, W, 4) uint8, as
    ``EditorState.map_images``; a slot whose image is missing keeps its factor."""
    import numpy as np

    from alight.core.shading import srgb_to_linear

    def texels(slot):
        image = images.get(getattr(maps, slot))
        if image is None or not getattr(maps, slot):
            return None
        rgb = np.asarray(image)[..., :3].reshape(-1, 3).astype(np.float64) / 255.0
        return srgb_to_linear(rgb) if slot in SRGB_SLOTS else rgb

    fields = {}
    if (t := texels("base_color")) is not None:
        fields["base_color"] = tuple(float(f * v) for f, v in zip(material.base_color, t.mean(axis=0)))
    metallic, roughness = material.metallic, material.roughness
    if (t := texels("metallic_roughness")) is not None:
        roughness, metallic = roughness * float(t[:, 1].mean()), metallic * float(t[:, 2].mean())
    if (t := texels("metallic")) is not None:   # (over a metal-rough map: replaces its B, as drawn)
        metallic = material.metallic * float(t[:, 0].mean())
    if (t := texels("roughness")) is not None:
        roughness = material.roughness * float(t[:, 0].mean())
    if (metallic, roughness) != (material.metallic, material.roughness):
        fields.update(metallic=metallic, roughness=roughness)
    if (t := texels("emissive")) is not None:
        fields["emissive"] = tuple(float(f * v) for f, v in zip(material.emissive, np.median(t, axis=0)))
    return replace(material, **fields)
