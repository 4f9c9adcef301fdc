"""The registry of the material fields a user can set: one entry per field of ``Material``.

The command line's flags (``alight render --clearcoat 0.5``), the batch spec's material keys
(``{preset = "gold", clearcoat = 0.5}``) and ``Renderer.set_material(clearcoat=0.5)`` are all
made from ``FIELDS``, so a field added to ``Material`` is settable from every front end at once
(and ``tests/test_material_fields.py`` runs each field through ``alight render`` and ``alight
batch``). What can be derived is: the names and their order (the base fields in the dataclass's
order, then ``LAYER_FIELDS``), the defaults, the kind (number or R,G,B) and the range, from
``alight.core.material``. What cannot is written here once: the glTF extension a field belongs
to, the flag's metavar and its help text.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from alight.core import material as _material
from alight.core.material import LAYER_FIELDS, LAYERS, Material


@dataclass(frozen=True)
class MaterialField:
    """One settable field of ``Material``.

    ``kind``: "number" (a float) or "color" (three floats, linear). ``low``/``high``: the range
    of the value or of each component (inf where unbounded); ``low_open``: the low end itself is
    refused (attenuation_distance > 0). ``extension``: the glTF extension that carries it (None:
    the core metal-roughness material). ``layer``: the name in ``LAYERS`` (None: the base model).
    """

    name: str
    kind: str
    low: float
    high: float
    default: Any
    extension: str | None
    layer: str | None
    metavar: str
    help: str
    low_open: bool = False

    @property
    def flag(self) -> str:
        """The command-line option: ``--clearcoat-roughness`` for clearcoat_roughness."""
        return "--" + self.name.replace("_", "-")


# The glTF extension of each layer (LAYERS' names); the base model's ior and specular_f0 are
# KHR_materials_ior's and KHR_materials_specular's.
_LAYER_EXTENSION = {
    "clearcoat": "KHR_materials_clearcoat", "sheen": "KHR_materials_sheen",
    "anisotropy": "KHR_materials_anisotropy", "transmission": "KHR_materials_transmission",
    "volume": "KHR_materials_volume", "iridescence": "KHR_materials_iridescence",
    "dispersion": "KHR_materials_dispersion", "diffuse_transmission": "KHR_materials_diffuse_transmission",
}
_BASE_EXTENSION = {"ior": "KHR_materials_ior", "specular_f0": "KHR_materials_specular"}

# (metavar, help) of each field: the text of its command-line flag.
_TEXT: dict[str, tuple[str, str]] = {
    "base_color": ("R,G,B", "linear base colour in [0,1]; the F0 of metals"),
    "metallic": ("X", "0 dielectric .. 1 metal"),
    "roughness": ("X", "perceptual roughness r in [0,1]; alpha = r^2"),
    "specular_f0": ("X|R,G,B", "F0 of the dielectric part, linear (default 0.04)"),
    "emissive": ("R,G,B", "linear emitted radiance, >= 0"),
    "ior": ("X", "index of refraction (KHR_materials_ior); given alone it sets --specular-f0 to "
                 "((ior-1)/(ior+1))^2, and --specular-f0 alone sets it (docs/layers.md)"),
    "clearcoat": ("X", "KHR_materials_clearcoat: the coat's weight in [0,1] (default 0: no coat)"),
    "clearcoat_roughness": ("X", "the coat's perceptual roughness in [0,1] (default 0)"),
    "sheen_color": ("R,G,B", "KHR_materials_sheen: linear sheen colour in [0,1] (default 0: no sheen)"),
    "sheen_roughness": ("X", "the sheen's perceptual roughness in [0,1] (default 0)"),
    "anisotropy_strength": ("X", "KHR_materials_anisotropy: strength in [0,1] (default 0: isotropic)"),
    "anisotropy_rotation": ("RAD", "the stretch's direction, radians counter-clockwise from the tangent (default 0)"),
    "transmission": ("X", "KHR_materials_transmission: the transmitted fraction in [0,1] (default 0: opaque)"),
    "thickness": ("X", "KHR_materials_volume: thickness in mesh units, >= 0 (default 0: thin-walled)"),
    "attenuation_color": ("R,G,B", "the volume's colour after --attenuation-distance, linear in [0,1] (default 1,1,1)"),
    "attenuation_distance": ("X", "distance at which light reaches --attenuation-color, > 0 (default: none)"),
    "iridescence": ("X", "KHR_materials_iridescence: the thin film's weight in [0,1] (default 0: no film)"),
    "iridescence_ior": ("X", "the thin film's index of refraction, >= 1 (default 1.3)"),
    "iridescence_thickness_minimum": ("NM", "the film's thickness in nm where the thickness map is 0 (default 100)"),
    "iridescence_thickness_maximum": ("NM", "the film's thickness in nm where the map is 1, and without a map (default 400)"),
    "diffuse_transmission": ("X", "KHR_materials_diffuse_transmission: the diffuse share leaving through the back side, in [0,1] (default 0: none)"),
    "diffuse_transmission_color": ("R,G,B", "the diffusely transmitted light's linear colour in [0,1] (default 1,1,1)"),
    "dispersion": ("X", "KHR_materials_dispersion: 20 / Abbe number, >= 0, spreads a volume's ior per channel (default 0: none)"),
}
# Fields whose low end is excluded (material._number refuses attenuation_distance <= 0).
_LOW_OPEN = ("attenuation_distance",)


def _build() -> tuple[MaterialField, ...]:
    layer_of = {f: layer for layer, fields in LAYERS.items() for f in fields}
    declared = [f for f in dataclasses.fields(Material) if f.name != "name"]
    base = [f.name for f in declared if f.name not in LAYER_FIELDS]
    names = (*base, *LAYER_FIELDS)
    missing = set(names) ^ set(_TEXT)
    if missing:   # a field added to Material (or removed) without its entry here
        raise RuntimeError(f"material_fields: no help text for (or a stale entry of) {sorted(missing)}")
    defaults = {f.name: f.default for f in declared}
    out = []
    for name in names:
        low, high = _material._RANGES[name]
        layer = layer_of.get(name)
        metavar, text = _TEXT[name]
        out.append(MaterialField(
            name=name, kind="color" if name in _material._VECTORS else "number", low=low, high=high,
            default=defaults[name], extension=_LAYER_EXTENSION[layer] if layer else _BASE_EXTENSION.get(name),
            layer=layer, metavar=metavar, help=text, low_open=name in _LOW_OPEN))
    return tuple(out)


FIELDS: tuple[MaterialField, ...] = _build()
BY_NAME: dict[str, MaterialField] = {f.name: f for f in FIELDS}
NAMES: tuple[str, ...] = tuple(BY_NAME)
