"""The panel's layer sections, made from the material-field registry (alight.core.material_fields):
one section per layer of ``alight.core.material.LAYERS``, one row per field of it, so a field added
to the registry is editable in the editor at once. Plain data, no imgui: panel.py draws it.

What a row's widget is follows from the field: a colour ("color") is an sRGB colour edit; a number
with a finite range a slider over it; an angle (metavar RAD) a slider in degrees; any other number
a drag clamped to its range. A field whose default is infinite (attenuation_distance: no
attenuation) has a checkbox that switches it between that and a finite value. The labels are the
field's name in words ("clearcoat roughness", "sheen colour (sRGB)"); tests/editor_ui_checks.py
operates the widgets by them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from alight.core.material_fields import FIELDS, MaterialField

# What the registry cannot say: the line under a section's title (a layer that acts only
# through another), and the checkbox of a field whose default is infinite.
_NOTES = {
    "volume": "acts through transmission or diffuse transmission; thickness 0 is thin-walled",
    "dispersion": "acts through a volume's refraction (transmission, thickness > 0)",
    # The panel has no thickness-map slot: without a map the film is the maximum throughout.
    "iridescence": "thickness minimum acts only through a thickness map (a glTF file's)",
}
_SWITCH_LABELS = {"attenuation_distance": "attenuate"}
_UNITS = {"NM": "nm"}   # metavar -> the unit shown in the widget's number
FINITE_START = 1.0      # the value a switched-on infinite field starts at (attenuation_distance)


@dataclass(frozen=True)
class LayerRow:
    """One widget. ``widget``: "color", "slider", "angle" or "drag". ``low``/``high``: the
    range edits are clamped to (for a drag with an open high end, inf; a low_open field's low is
    the smallest value the drag gives). ``speed``: a drag's change per pixel. ``switch``: the
    checkbox's label of a field whose default (infinite) is 'off', else ''."""

    field: str
    label: str
    widget: str
    low: float
    high: float
    speed: float
    fmt: str
    help: str
    switch: str = ""


@dataclass(frozen=True)
class LayerSection:
    """A collapsible section: ``layer`` (a name of LAYERS; its tree node's ID is
    ``###layer_<layer>``), ``title``, its glTF ``extension``, a ``note`` (may be '') and rows."""

    layer: str
    title: str
    extension: str
    note: str
    rows: tuple[LayerRow, ...]


def row_for(f: MaterialField) -> LayerRow:
    """The widget of one registry field (see the module's docstring for the rules)."""
    words = f.name.replace("_", " ")
    if f.kind == "color":
        return LayerRow(f.name, words.replace("color", "colour") + " (sRGB)", "color", f.low, f.high, 0.0, "",
                        f.help)
    if f.metavar == "RAD":
        return LayerRow(f.name, words, "angle", -math.pi, math.pi, 0.0, "%.0f deg", f.help)
    unit = _UNITS.get(f.metavar, "")
    fmt = "%.0f " + unit if unit else "%.3f"
    if math.isfinite(f.low) and math.isfinite(f.high):
        return LayerRow(f.name, words, "slider", f.low, f.high, 0.0, fmt, f.help)
    low = 1e-3 if f.low_open else f.low
    switch = _SWITCH_LABELS.get(f.name, "enable " + words) if math.isinf(f.default) else ""
    # A drag's speed in proportion to the field's size: 0.005 per pixel for a unit-sized value.
    scale = abs(f.default) if math.isfinite(f.default) and f.default else 1.0
    speed = 0.005 * max(scale, 1.0) if not switch else 0.01
    return LayerRow(f.name, words, "drag", low, f.high, speed, fmt, f.help, switch)


def sections() -> tuple[LayerSection, ...]:
    """Every layer of the registry with its fields, in the registry's order (LAYERS')."""
    by_layer: dict[str, list[MaterialField]] = {}
    for f in FIELDS:
        if f.layer is not None:
            by_layer.setdefault(f.layer, []).append(f)
    out = []
    for layer, fields in by_layer.items():
        out.append(LayerSection(layer, layer.replace("_", " ").capitalize(), fields[0].extension or "",
                                _NOTES.get(layer, ""), tuple(row_for(f) for f in fields)))
    return tuple(out)


SECTIONS: tuple[LayerSection, ...] = sections()
