"""The material state (docs/conventions.md, material model), its validation, and the F0 table's names
(the preset files are read and written by ``alight.exchange.presets``).

Everything a user can hand us (a preset file, a CLI option, a GUI edit) passes through
``validate_material`` so the renderer never sees a value outside the model's ranges, and every
problem surfaces as a one-line ``AlightError`` naming the file, then the field, then the reason.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass
from typing import Any

from alight.core.shading import linear_to_srgb
from alight.errors import AlightError

Vec3 = tuple[float, float, float]


# The layers beyond the lecture's BRDF, each with the fields that belong to it, named
# after the glTF extension's parameters in snake case. Every default is glTF's, and is the
# value at which the layer is off: such a material shades exactly as the base model does.
LAYERS: dict[str, tuple[str, ...]] = {
    "clearcoat": ("clearcoat", "clearcoat_roughness"),                          # KHR_materials_clearcoat
    "sheen": ("sheen_color", "sheen_roughness"),                                # KHR_materials_sheen
    "anisotropy": ("anisotropy_strength", "anisotropy_rotation"),               # KHR_materials_anisotropy
    "transmission": ("transmission",),                                          # KHR_materials_transmission
    "volume": ("thickness", "attenuation_color", "attenuation_distance"),       # KHR_materials_volume
    "iridescence": ("iridescence", "iridescence_ior", "iridescence_thickness_minimum",
                    "iridescence_thickness_maximum"),                           # KHR_materials_iridescence
    "dispersion": ("dispersion",),                                              # KHR_materials_dispersion
    "diffuse_transmission": ("diffuse_transmission", "diffuse_transmission_color"),  # KHR_materials_diffuse_transmission
}
LAYER_FIELDS: tuple[str, ...] = tuple(f for fields in LAYERS.values() for f in fields)
DEFAULT_IOR = 1.5  # glTF's; F0 = ((1.5 - 1) / (1.5 + 1))^2 = 0.04
# Above this F0 the ior grows without bound (F0 = 1 needs ior = inf): ior_from_f0 stops here
# (ior 37.97), and KHR_materials_specular carries the rest.
MAX_IOR_F0 = 0.9
# Rec. 709's weights of linear RGB: the grey a coloured specular F0 reflects as. The ior rule
# reads a coloured F0 by it (the editor's panel and the command line alike): one channel at 0.32
# over 0.04 made the brightest channel's ior 3.6, a new user's surprise.
LUMINANCE = (0.2126, 0.7152, 0.0722)


def luminance(c) -> float:
    """Rec. 709 luminance of linear RGB ``c`` (3 numbers)."""
    return sum(w * float(x) for w, x in zip(LUMINANCE, c))


def f0_from_ior(ior: float) -> float:
    """Normal-incidence Fresnel reflectance of a dielectric interface with air: ((ior - 1)/(ior + 1))^2
    (KHR_materials_ior). Rounded to 12 decimals so that ior 1.5 gives glTF's 0.04 exactly."""
    return round(((ior - 1.0) / (ior + 1.0)) ** 2, 12)


def ior_from_f0(f0: float) -> float:
    """The inverse of f0_from_ior: (1 + sqrt(F0)) / (1 - sqrt(F0)), F0 capped at MAX_IOR_F0."""
    s = math.sqrt(min(max(f0, 0.0), MAX_IOR_F0))
    return round((1.0 + s) / (1.0 - s), 12)


def specular_f0_for_ior(ior: float, like: Vec3 | None = None) -> Vec3:
    """The specular_f0 of ``ior`` with the specular colour of ``like`` (like / luminance(like),
    each channel at most 1; grey when ``like`` is None or black): the rule's 'ior given alone'
    case."""
    f0 = f0_from_ior(ior)
    lum = luminance(like) if like is not None else 0.0
    if lum <= 0.0:
        return (f0, f0, f0)
    return tuple(min(f0 * c / lum, 1.0) for c in like)  # type: ignore[return-value]


@dataclass(frozen=True)
class Material:
    """Metal-roughness material with an explicit dielectric F0 (frozen: edits make new values,
    so a renderer holding one never sees it change under it), and the glTF layers.

    ``ior`` and ``specular_f0`` describe one dielectric interface (the rule, docs/layers.md):
    ``specular_f0 = ((ior - 1)/(ior + 1))^2 * specular colour`` (KHR_materials_ior times
    KHR_materials_specular). Give one and the other follows: ``Material(specular_f0=...)`` gets
    ``ior = ior_from_f0(luminance(specular_f0))``, ``Material(ior=...)`` the grey
    ``specular_f0 = f0_from_ior(ior)``, neither gives glTF's 1.5 and 0.04; give both for a
    specular colour or strength that is not the ior's. The base layer reflects with
    ``specular_f0``; refraction (transmission, volume) uses ``ior``.
    """

    base_color: Vec3 = (0.8, 0.8, 0.8)
    metallic: float = 0.0
    roughness: float = 0.5
    specular_f0: Vec3 = None  # type: ignore[assignment]  # None: from ior (the rule); 0.04 when neither
    emissive: Vec3 = (0.0, 0.0, 0.0)
    name: str = "default"
    ior: float = None  # type: ignore[assignment]  # None: from specular_f0 (the rule); 1.5 when neither
    # KHR_materials_transmission: the fraction of the dielectric's diffuse that is transmitted.
    transmission: float = 0.0
    # KHR_materials_volume: thickness in the mesh's units (0: thin-walled); Beer-Lambert
    # attenuation reaching attenuation_color after attenuation_distance (inf: none).
    thickness: float = 0.0
    attenuation_color: Vec3 = (1.0, 1.0, 1.0)
    attenuation_distance: float = math.inf
    # KHR_materials_dispersion: 20 / Abbe number (0: none); spreads the volume's ior per channel.
    dispersion: float = 0.0
    # KHR_materials_diffuse_transmission: the share of the diffuse lobe that leaves through the
    # back side (a Lambertian BTDF) and its linear colour.
    diffuse_transmission: float = 0.0
    diffuse_transmission_color: Vec3 = (1.0, 1.0, 1.0)
    # KHR_materials_clearcoat: the coat's weight and perceptual roughness.
    clearcoat: float = 0.0
    clearcoat_roughness: float = 0.0
    # KHR_materials_sheen: linear sheen colour (black: off) and perceptual sheen roughness.
    sheen_color: Vec3 = (0.0, 0.0, 0.0)
    sheen_roughness: float = 0.0
    # KHR_materials_anisotropy: strength in [0, 1], rotation (radians, counter-clockwise from
    # the tangent in the tangent plane).
    anisotropy_strength: float = 0.0
    anisotropy_rotation: float = 0.0
    # KHR_materials_iridescence: the thin film's weight, index and thickness range (nm); without
    # a thickness map the film is thickness_maximum thick (alight.core.layers.iridescence).
    iridescence: float = 0.0
    iridescence_ior: float = 1.3
    iridescence_thickness_minimum: float = 100.0
    iridescence_thickness_maximum: float = 400.0

    def __post_init__(self) -> None:
        # The ior rule (class docstring), applied once at construction; dataclasses.replace passes
        # both fields, so it keeps them as they are (with_overrides applies the rule to edits).
        f0, ior = self.specular_f0, self.ior
        if hasattr(f0, "tolist") and not isinstance(f0, (list, tuple)):
            f0 = tuple(f0.tolist())   # numpy arrays from the editor
        if f0 is None and ior is None:
            f0, ior = (0.04, 0.04, 0.04), DEFAULT_IOR
        elif f0 is None:
            f0 = specular_f0_for_ior(ior) if _is_number(ior) else f0
        elif ior is None and _is_vector(f0):
            ior = ior_from_f0(luminance(f0))
        object.__setattr__(self, "specular_f0", f0)
        object.__setattr__(self, "ior", ior)

    def f0(self) -> Vec3:
        """mix(specular_f0, base_color, metallic): written so metallic 0 or 1 gives an input exactly."""
        m = self.metallic
        return tuple(s * (1.0 - m) + b * m for s, b in zip(self.specular_f0, self.base_color))  # type: ignore[return-value]

    def layers(self) -> frozenset[str]:
        """The layers this material uses (names of ``LAYERS``); empty: the base model alone.

        A layer is on when its strength is above zero: clearcoat > 0, max(sheen_color) > 0,
        anisotropy_strength > 0, iridescence > 0, transmission > 0; volume when thickness > 0 and
        transmission > 0 or diffuse_transmission > 0 (KHR_materials_volume acts through the light
        that crosses the surface: KHR_materials_diffuse_transmission's "combined with
        KHR_materials_volume" section, its Beer-Lambert attenuation on the diffusely transmitted
        light as the Khronos Sample Viewer applies it); dispersion when transmission and the volume
        are on and dispersion > 0 (KHR_materials_dispersion acts only on a volume's refraction);
        diffuse_transmission when diffuse_transmission > 0."""
        used = set()
        if self.clearcoat > 0.0:
            used.add("clearcoat")
        if max(self.sheen_color) > 0.0:
            used.add("sheen")
        if self.anisotropy_strength > 0.0:
            used.add("anisotropy")
        if self.iridescence > 0.0:
            used.add("iridescence")
        if self.diffuse_transmission > 0.0:
            used.add("diffuse_transmission")
        if self.thickness > 0.0 and (self.transmission > 0.0 or self.diffuse_transmission > 0.0):
            used.add("volume")
        if self.transmission > 0.0:
            used.add("transmission")
            if self.thickness > 0.0 and self.dispersion > 0.0:
                used.add("dispersion")
        return frozenset(used)

    def to_dict(self) -> dict[str, Any]:
        """The preset file's material fields, in the file's order, as JSON-ready lists. A layer
        field at its default and an ior that the rule derives from specular_f0 are left out, so
        a material without layers writes the same file as before the layers existed."""
        d: dict[str, Any] = {
            "name": self.name,
            "base_color": list(self.base_color),
            "metallic": self.metallic,
            "roughness": self.roughness,
            "specular_f0": list(self.specular_f0),
            "emissive": list(self.emissive),
        }
        if abs(self.ior - ior_from_f0(luminance(self.specular_f0))) > 1e-9:
            d["ior"] = self.ior
        for field in LAYER_FIELDS:
            value = getattr(self, field)
            if value != _DEFAULTS[field]:
                d[field] = list(value) if isinstance(value, tuple) else value
        return d


def _is_number(x: Any) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(float(x))


def _is_vector(x: Any) -> bool:
    return isinstance(x, (list, tuple)) and len(x) == 3 and all(_is_number(c) for c in x)


_FIELDS = tuple(f.name for f in dataclasses.fields(Material))
_DEFAULTS = {f.name: f.default for f in dataclasses.fields(Material)}
_OPTIONAL = ("description", "f0_linear", "f0_srgb")
_UNIT = (0.0, 1.0)
_NONNEG = (0.0, math.inf)
_RANGES: dict[str, tuple[float, float]] = {
    "base_color": _UNIT, "metallic": _UNIT, "roughness": _UNIT,
    "specular_f0": _UNIT, "emissive": _NONNEG, "f0_linear": _UNIT, "f0_srgb": _UNIT,
    "ior": (1.0, math.inf), "transmission": _UNIT, "thickness": _NONNEG, "attenuation_color": _UNIT,
    "attenuation_distance": (0.0, math.inf), "clearcoat": _UNIT, "clearcoat_roughness": _UNIT,
    "sheen_color": _UNIT, "sheen_roughness": _UNIT, "anisotropy_strength": _UNIT,
    "anisotropy_rotation": (-math.inf, math.inf),
    "iridescence": _UNIT, "iridescence_ior": (1.0, math.inf), "iridescence_thickness_minimum": _NONNEG,
    "iridescence_thickness_maximum": _NONNEG, "dispersion": _NONNEG,
    "diffuse_transmission": _UNIT, "diffuse_transmission_color": _UNIT,
}
_VECTORS = ("base_color", "specular_f0", "emissive", "f0_linear", "f0_srgb", "attenuation_color", "sheen_color",
            "diffuse_transmission_color")
# Fields a preset file may leave out: every layer field (the layer is then off) and the ior
# (then derived from specular_f0); specular_f0 may be left out when the ior is given.
_MAY_OMIT = ("ior", *LAYER_FIELDS)

# The lecture's F0 table order (LearnOpenGL "PBR Theory", after Real-Time Rendering).
PRESET_NAMES: tuple[str, ...] = (
    "water", "plastic_glass_low", "plastic_high", "glass_high_ruby", "diamond",
    "iron", "copper", "gold", "aluminium", "silver",
)


def _fail(source: str, message: str) -> AlightError:
    # A newline in a file name must not break the one-line message contract. No source (the
    # editor's panel): the field names itself, and a prefix would name nothing the artist sees.
    text = f"{source}: {message}" if source else message
    return AlightError(text.replace("\n", "\\n").replace("\r", "\\r"))


def _type_name(value: Any) -> str:
    """JSON's names for types, since that is the language the user wrote the file in."""
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, numbers.Real):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, (list, tuple)):
        return f"array of {len(value)}"
    if isinstance(value, dict):
        return "object"
    if value is None:
        return "null"
    return type(value).__name__


def _fmt(x: float) -> str:
    return f"{x:g}"


def _number(value: Any, source: str, field: str, component: int | None = None) -> float:
    """One finite float; bools are refused because JSON true would otherwise pass as 1."""
    where = f"field '{field}'" + ("" if component is None else f", component {component}")
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise _fail(source, f"{where}: expected a number, got {_type_name(value)}")
    try:
        x = float(value)
    except OverflowError:  # a 400-digit integer literal
        x = math.inf
    if not math.isfinite(x):
        raise _fail(source, f"{where}: {_fmt(x)} is not a finite number")
    lo, hi = _RANGES[field]
    if field == "attenuation_distance" and x <= 0.0:
        raise _fail(source, f"{where}: {_fmt(x)} is out of range (0, inf] (leave it out for no attenuation)")
    if not lo <= x <= hi:
        rng = f"[{_fmt(lo)}, inf)" if hi == math.inf else f"[{_fmt(lo)}, {_fmt(hi)}]"
        raise _fail(source, f"{where}: {_fmt(x)} is out of range {rng}")
    return x


def _vector(value: Any, source: str, field: str) -> Vec3:
    if hasattr(value, "tolist") and not isinstance(value, (list, tuple)):
        value = value.tolist()  # numpy arrays from the editor
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        raise _fail(source, f"field '{field}': expected an array of 3 numbers, got {_type_name(value)}")
    return tuple(_number(c, source, field, i) for i, c in enumerate(value))  # type: ignore[return-value]


def _check(values: dict[str, Any], source: str) -> Material:
    """The single place ranges and types are enforced; returns a normalised (float, tuple) copy
    so that values loaded from JSON ints compare equal to those saved from floats."""
    name = values["name"]
    if not isinstance(name, str) or not name.strip() or not name.isprintable():
        raise _fail(source, f"field 'name': expected a non-empty one-line string, got {_type_name(name) if not isinstance(name, str) else repr(name)}")
    out: dict[str, Any] = {"name": name}
    for field in _FIELDS:
        if field == "name" or values.get(field) is None and field in ("ior", "specular_f0"):
            continue   # left to the ior rule (Material.__post_init__)
        v = values.get(field, _DEFAULTS[field])
        if field == "attenuation_distance" and isinstance(v, float) and v == math.inf:
            out[field] = v   # glTF's default: no attenuation (JSON cannot write it; files leave it out)
            continue
        out[field] = _vector(v, source, field) if field in _VECTORS else _number(v, source, field)
    return Material(**out)


def validate_material(m: Material, source: str = "material") -> Material:
    """Check a material built in code (GUI, CLI) against the model's ranges; returns it normalised."""
    return _check({f: getattr(m, f) for f in _FIELDS}, source)


def material_from_dict(d: dict, source: str) -> Material:
    """Strict: a typo'd or extra field is refused rather than silently ignored, because a preset
    with 'rougness' would otherwise render with the default roughness and nobody would notice."""
    if not isinstance(d, dict):
        raise _fail(source, f"expected a JSON object, got {_type_name(d)}")
    for key in d:
        if key not in _FIELDS and key not in _OPTIONAL:
            raise _fail(source, f"unknown field {str(key)!r}")
    for key in _FIELDS:
        if key not in d and key not in _MAY_OMIT and not (key == "specular_f0" and "ior" in d):
            raise _fail(source, f"missing field '{key}'")
    m = _check(d, source)
    if "description" in d and not isinstance(d["description"], str):
        raise _fail(source, f"field 'description': expected a string, got {_type_name(d['description'])}")
    f0 = m.f0()
    if "f0_linear" in d:
        doc = _vector(d["f0_linear"], source, "f0_linear")
        if any(abs(a - b) > 1e-6 for a, b in zip(doc, f0)):
            raise _fail(source, f"field 'f0_linear': {_fmt_vec(doc)} does not match the material's F0 {_fmt_vec(f0)}")
    if "f0_srgb" in d:
        doc = _vector(d["f0_srgb"], source, "f0_srgb")
        want = tuple(float(x) for x in linear_to_srgb(f0))
        if any(abs(a - b) > 0.01 for a, b in zip(doc, want)):
            raise _fail(source, f"field 'f0_srgb': {_fmt_vec(doc)} does not match the sRGB of the material's F0 {_fmt_vec(want, 3)}")
    return m


def _fmt_vec(v: Vec3, digits: int = 6) -> str:
    return "[" + ", ".join(_fmt(round(x, digits)) for x in v) + "]"


def with_overrides(m: Material, source: str = "material", **fields: Any) -> Material:
    """None means 'option not given', so CLI flags can be passed straight through.

    The ior rule (``Material``) applies to edits: an ior given without specular_f0 sets
    specular_f0 to the ior's F0 in the material's specular colour, a specular_f0 given without
    an ior sets the ior from it."""
    given = {k: v for k, v in fields.items() if v is not None}
    for key in given:
        if key not in _FIELDS:
            raise _fail(source, f"unknown field {key!r}")
    if "ior" in given and "specular_f0" not in given:
        ior = _number(given["ior"], source, "ior")
        given["specular_f0"] = specular_f0_for_ior(ior, validate_material(m).specular_f0)
    elif "specular_f0" in given and "ior" not in given:
        given["ior"] = None   # derived again by Material.__post_init__
    return validate_material(dataclasses.replace(m, **given), source)


def parse_color(text: str, option: str) -> Vec3:
    """'R,G,B' or one 'X' for grey; ranges per field are checked later by validate_material,
    but nothing in the model is negative or non-finite, so those fail here, naming the option."""
    parts = [p.strip() for p in str(text).split(",")]
    bad = _fail(option, f"expected R,G,B or a single number, got {text!r}")
    if len(parts) not in (1, 3):
        raise bad
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise bad from None
    if not all(math.isfinite(v) and v >= 0.0 for v in values):
        raise _fail(option, f"components must be finite and >= 0, got {text!r}")
    return (values[0],) * 3 if len(values) == 1 else tuple(values)  # type: ignore[return-value]
