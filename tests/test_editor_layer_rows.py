"""Every layer field of the material-field registry has a row in the editor's panel that edits it.

The panel's layer sections (Panel._layers) are drawn against a recording stand-in for imgui:
every widget drawn is then made to report an edit, one at a time, and the field that edit
changes is noted. The fields so reached must be exactly the registry's layer fields, each
with its help as the tooltip. (tests/editor_ui_checks.py operates the real widgets.)
"""

from __future__ import annotations

import dataclasses
import math
import sys
import types

import pytest

from alight.core.material import Material
from alight.core.material_fields import BY_NAME, FIELDS
from alight.frontends.editor.panel import Panel
from alight.frontends.editor.state import EditorState

LAYER_FIELDS = tuple(f.name for f in FIELDS if f.layer is not None)


class FakeImgui:
    """Records the widgets drawn (label, kind) and each one's tooltip; the widget labelled
    ``edit`` reports a change (a value 0.25 above the current one; a colour of 0.5 grey)."""

    class Cond_:
        always = 1

    class SliderFlags_:
        always_clamp = 1 << 4

    def __init__(self, edit: str | None = None):
        self.edit, self.drawn, self.tooltips, self.sections = edit, [], {}, {}
        self._last = None

    def _widget(self, label, kind, value):
        self.drawn.append((label, kind))
        self._last = label
        if label != self.edit:
            return False, value
        if kind == "color":
            return True, [0.5, 0.5, 0.5] if list(value) != [0.5, 0.5, 0.5] else [0.25, 0.25, 0.25]
        if kind == "checkbox":
            return True, not value
        return True, value + 0.25

    def slider_float(self, label, v, *_):
        return self._widget(label, "slider", v)

    def drag_float(self, label, v, *_):
        return self._widget(label, "drag", v)

    def slider_angle(self, label, v, *_):
        return self._widget(label, "angle", v)

    def color_edit3(self, label, col, *_):
        return self._widget(label, "color", col)

    def checkbox(self, label, v):
        return self._widget(label, "checkbox", v)

    def tree_node_ex(self, label, *_):
        self._last = ("section", label)
        return True

    def is_item_hovered(self):
        return True

    # A tooltip (widgets.tooltip): its text is recorded for the widget drawn last.
    def text_unformatted(self, text):
        if isinstance(self._last, tuple):
            self.sections[self._last[1]] = text
        else:
            self.tooltips[self._last] = text

    def begin_tooltip(self):
        pass

    end_tooltip = pop_text_wrap_pos = begin_tooltip

    def push_text_wrap_pos(self, _):
        pass

    def get_font_size(self):
        return 13.0

    def get_io(self):
        io = types.SimpleNamespace(display_size=self._Vec(1280.0, 720.0))
        return io

    def set_next_item_open(self, *_):
        pass

    def tree_pop(self):
        pass

    # Layout calls (the rows' width beside their labels): a fixed geometry.
    class _Vec:
        def __init__(self, x=0.0, y=0.0):
            self.x, self.y = x, y

    class _Style:
        item_inner_spacing = window_padding = None

    def calc_text_size(self, text):
        return self._Vec(7.0 * len(text), 13.0)

    def get_content_region_avail(self):
        return self._Vec(400.0, 600.0)

    def get_style(self):
        style = self._Style()
        style.item_inner_spacing = style.window_padding = self._Vec(4.0, 4.0)
        return style

    def push_item_width(self, _):
        pass

    def pop_item_width(self):
        pass

    def text_disabled(self, _):
        pass


def draw_layers(monkeypatch, m: Material, edit: str | None = None) -> tuple[FakeImgui, Material]:
    fake = FakeImgui(edit)
    monkeypatch.setitem(sys.modules, "imgui_bundle", types.SimpleNamespace(imgui=fake))
    panel = types.SimpleNamespace(_sections_for=None)
    state = types.SimpleNamespace(saved_material=m)
    return fake, Panel._layers(panel, state, m)


def changed_fields(a: Material, b: Material) -> set[str]:
    return {f.name for f in dataclasses.fields(Material) if getattr(a, f.name) != getattr(b, f.name)}


@pytest.mark.parametrize("attenuation_distance", [2.0, math.inf])
def test_every_layer_field_of_the_registry_has_a_panel_row(monkeypatch, attenuation_distance):
    """With attenuation on (its drag drawn) and off (only its checkbox)."""
    base = Material(attenuation_distance=attenuation_distance)
    fake, same = draw_layers(monkeypatch, base)
    assert same == base   # drawn without an edit, nothing changes
    reached = {}
    for label, kind in fake.drawn:
        _, edited = draw_layers(monkeypatch, base, edit=label)
        fields = changed_fields(base, edited)
        assert len(fields) == 1, f"the widget '{label}' edits {sorted(fields)}"
        (name,) = fields
        assert fake.tooltips.get(label) == BY_NAME[name].help, f"'{label}': its tooltip is not {name}'s help"
        reached.setdefault(name, []).append((label, kind))
    assert set(reached) == set(LAYER_FIELDS), f"no panel row for {sorted(set(LAYER_FIELDS) - set(reached))}"
    # One widget per field; attenuation_distance two where on (the checkbox and the drag).
    assert all(len(w) == 1 for n, w in reached.items() if n != "attenuation_distance"), reached
    # The colours are colour edits; a section per layer, its extension as the title's tooltip.
    assert {n for n, w in reached.items() if w[0][1] == "color"} == \
        {n for n in LAYER_FIELDS if BY_NAME[n].kind == "color"}
    assert set(fake.sections.values()) == {f.extension for f in FIELDS if f.layer is not None}


def test_a_drag_is_clamped_to_the_fields_range(monkeypatch):
    """A drag's open end is clamped by the panel (imgui clamps only finite ranges): a value
    below the low end comes back as the low end."""
    from alight.frontends.editor.layer_rows import SECTIONS

    rows = [r for s in SECTIONS for r in s.rows if r.widget == "drag"]
    assert {r.field for r in rows} >= {"thickness", "iridescence_ior", "dispersion"}
    for row in rows:
        class Below(FakeImgui):
            def drag_float(self, label, v, *_):
                self.drawn.append((label, "drag"))
                return label == row.label, row.low - 5.0

        fake = Below()
        monkeypatch.setitem(sys.modules, "imgui_bundle", types.SimpleNamespace(imgui=fake))
        m = Panel._layers(types.SimpleNamespace(_sections_for=None), types.SimpleNamespace(saved_material=None),
                          Material(attenuation_distance=2.0))
        assert getattr(m, row.field) == row.low, row


def test_every_layer_field_is_a_script_key():
    """``alight edit --script FIELD=VALUE`` takes every registry layer field (a colour as R,G,B)."""
    s = EditorState()
    for name in LAYER_FIELDS:
        f = BY_NAME[name]
        value = "0.5,0.25,0.125" if f.kind == "color" else ("2" if f.low >= 1.0 else "0.5")
        s.apply_edit(f"{name}={value}")
        got = getattr(s.material, name)
        assert got == ((0.5, 0.25, 0.125) if f.kind == "color" else float(value)), (name, got)
