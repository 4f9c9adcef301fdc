"""The material state (CONVENTIONS.md, material model), its validation, and the F0 table's names
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


@dataclass(frozen=True)
class Material:
    """Metal-roughness material with an explicit dielectric F0 (frozen: edits make new values,
    so a renderer holding one never sees it change under it)."""

    base_color: Vec3 = (0.8, 0.8, 0.8)
    metallic: float = 0.0
    roughness: float = 0.5
    specular_f0: Vec3 = (0.04, 0.04, 0.04)
    emissive: Vec3 = (0.0, 0.0, 0.0)
    name: str = "default"

    def f0(self) -> Vec3:
        """mix(specular_f0, base_color, metallic): written so metallic 0 or 1 gives an input exactly."""
        m = self.metallic
        return tuple(s * (1.0 - m) + b * m for s, b in zip(self.specular_f0, self.base_color))  # type: ignore[return-value]

    def to_dict(self) -> dict[str, Any]:
        """The preset file's material fields, in the file's order, as JSON-ready lists."""
        return {
            "name": self.name,
            "base_color": list(self.base_color),
            "metallic": self.metallic,
            "roughness": self.roughness,
            "specular_f0": list(self.specular_f0),
            "emissive": list(self.emissive),
        }


_FIELDS = tuple(f.name for f in dataclasses.fields(Material))
_OPTIONAL = ("description", "f0_linear", "f0_srgb")
_UNIT = (0.0, 1.0)
_NONNEG = (0.0, math.inf)
_RANGES: dict[str, tuple[float, float]] = {
    "base_color": _UNIT, "metallic": _UNIT, "roughness": _UNIT,
    "specular_f0": _UNIT, "emissive": _NONNEG, "f0_linear": _UNIT, "f0_srgb": _UNIT,
}
_VECTORS = ("base_color", "specular_f0", "emissive", "f0_linear", "f0_srgb")

# The lecture's F0 table order (LearnOpenGL "PBR Theory", after Real-Time Rendering).
PRESET_NAMES: tuple[str, ...] = (
    "water", "plastic_glass_low", "plastic_high", "glass_high_ruby", "diamond",
    "iron", "copper", "gold", "aluminium", "silver",
)


def _fail(source: str, message: str) -> AlightError:
    # A newline in a file name must not break the one-line message contract.
    return AlightError(f"{source}: {message}".replace("\n", "\\n").replace("\r", "\\r"))


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
    if not lo <= x <= hi:
        rng = "[0, inf)" if hi == math.inf else f"[{_fmt(lo)}, {_fmt(hi)}]"
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
        if field == "name":
            continue
        v = values[field]
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
        if key not in d:
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


def with_overrides(m: Material, **fields: Any) -> Material:
    """None means 'option not given', so CLI flags can be passed straight through."""
    given = {k: v for k, v in fields.items() if v is not None}
    for key in given:
        if key not in _FIELDS:
            raise _fail("material", f"unknown field {key!r}")
    return validate_material(dataclasses.replace(m, **given))


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
