"""A mesh file's own materials and the panel's edits, operated through the panel by the Dear
ImGui Test Engine: run by tests/test_editor_ui_own_materials.py as ``alight edit --new --mesh
Duck.glb --occlusion off --ui-test tests/editor_ui_checks_own_materials.py`` (a real window
under Xvfb); not collected by pytest.

A preset click unticks 'mesh file's own materials'; Ctrl+Z gives the file's materials back
(the box ticked again), Ctrl+Shift+Z the preset. An edit of the panel's material or maps while
the box is ticked (a slider dragged, an F0 channel typed, a layer row, the UV tiling) unticks
it and says so once in the status row, one undo step with the edit. An F0 channel typed alone
sets the ior from the F0's luminance, and the undo row shows numbers as the widgets do."""

from __future__ import annotations

import re

import numpy as np

from alight.frontends.editor.ui_test import editor, view

BOX = "**/mesh file's own materials and maps"
UNTICKED = "the mesh file's own materials unticked"


def _undo(ctx, redo: bool = False) -> None:
    """Ctrl+Z (Ctrl+Shift+Z) over the view: a click on the void first lets the panel go of the keys."""
    from imgui_bundle import imgui

    ctx.mouse_click_on_void()
    keys = imgui.Key.mod_ctrl | imgui.Key.z
    ctx.key_press(keys | imgui.Key.mod_shift if redo else keys)
    ctx.yield_(2)
    ctx.set_ref("alight")


def test_undo_after_a_preset_click_gives_the_files_own_materials_back(ctx):
    s = editor().state
    assert s.mesh_spec.endswith("Duck.glb") and s.use_file_materials, (s.mesh_spec, s.use_file_materials)
    ctx.set_ref("alight")
    duck = view(ctx).astype(np.float64)
    ctx.item_click("**/gold")
    assert not s.use_file_materials and s.message == f"applied gold ({UNTICKED})", s.message
    gold = view(ctx).astype(np.float64)
    assert np.abs(gold - duck).mean() > 3.0
    _undo(ctx)
    assert s.use_file_materials, s.message   # the box ticked again: the textured duck
    assert s.message == "undo: the mesh file's own materials (was gold)", s.message
    assert np.abs(view(ctx).astype(np.float64) - duck).max() <= 1.0
    _undo(ctx, redo=True)
    assert not s.use_file_materials and s.material.name == "gold", (s.use_file_materials, s.material.name)
    assert s.message == "redo: gold (was the mesh file's own materials)", s.message
    _undo(ctx)
    assert s.use_file_materials and s.material.name != "gold"


def _edits(ctx):
    """Each panel edit of the material or its maps, as the artist makes it (the widget itself)."""
    def roughness():   # the slider dragged by the mouse
        from imgui_bundle import imgui

        ctx.item_drag_with_delta("**/roughness", imgui.ImVec2(60.0, 0.0))

    def f0():
        ctx.item_input_value("specular F0/$$1", 0.06)

    def clearcoat():
        ctx.item_open("**/###layer_clearcoat")
        ctx.item_input_value("**/clearcoat", 0.5)
        ctx.item_close("**/###layer_clearcoat")

    def emissive():
        ctx.item_input_value("emissive/$$0", 0.5)

    def metallic():
        ctx.item_input_value("**/metallic", 0.7)

    def tiling():
        ctx.item_open("**/texture maps")
        ctx.item_input_value("texture maps/UV tiling/$$0", 2.0)

    return {"roughness": roughness, "specular F0": f0, "clearcoat": clearcoat, "emissive": emissive, "metallic": metallic,
            "UV tiling": tiling}


def test_a_panel_edit_while_the_files_materials_show_unticks_them_and_says_so(ctx):
    s = editor().state
    ctx.set_ref("alight")
    for name, edit in _edits(ctx).items():
        if not s.use_file_materials:
            ctx.item_check(BOX)
        assert s.use_file_materials
        look = s.look
        duck = view(ctx).astype(np.float64)
        edit()
        ctx.yield_(3)
        assert not s.use_file_materials, f"{name}: the box stayed ticked (the edit drew nothing)"
        assert s.look[:2] != look[:2], f"{name}: no edit"
        assert UNTICKED in s.message and s.message.count(UNTICKED) == 1, (name, s.message)
        # Seen: the panel's material on the duck.
        assert np.abs(view(ctx).astype(np.float64) - duck).mean() > 2.0, name
        said = s.message
        ctx.yield_(10)
        assert s.message == said, (name, s.message)   # said once, not each frame
        # One undo step: the file's materials back, the panel's material as it was.
        _undo(ctx)
        assert s.use_file_materials and s.look == look, (name, s.message)
        assert s.message.startswith("undo: the mesh file's own materials (was "), (name, s.message)


def test_one_f0_channel_sets_the_ior_from_the_luminance_and_undo_rounds_as_the_widgets(ctx):
    from alight.core.material import ior_from_f0

    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    base = s.material
    g = base.specular_f0[0]
    assert base.specular_f0 == (g, g, g) and g < 0.1, base   # a grey F0: the ior's
    ctx.item_input_value("specular F0/$$0", 0.32)
    m = s.material
    assert m.specular_f0 == (0.32, g, g), m.specular_f0   # the tint kept (the specular colour)
    lum = 0.2126 * 0.32 + (0.7152 + 0.0722) * g
    assert abs(m.ior - ior_from_f0(lum)) < 1e-4 and m.ior < 2.0, m.ior   # not the red channel's 3.6
    _undo(ctx)
    assert s.material.specular_f0 == (g, g, g), s.material
    # Numbers as the widgets show them ('%.3f'), not the float's six digits.
    assert s.message == (f"undo: plastic_high (specular f0, ior {round(m.ior, 3):g} -> "
                         f"{round(base.ior, 3):g})"), s.message
    assert not re.search(r"\d\.\d{4}", s.message), s.message
    # The ior dragged keeps the tint, its luminance the ior's F0.
    ctx.item_input_value("specular F0/$$0", 0.32)
    ctx.item_input_value("**/ior", 1.5)
    f0 = s.material.specular_f0
    assert f0[0] > 2 * f0[1] and abs(0.2126 * f0[0] + 0.7152 * f0[1] + 0.0722 * f0[2] - 0.04) < 1e-3, f0


def test_undo_takes_back_the_last_light_edit_before_an_older_material_edit(ctx):
    """A preset click, then a spot light added and its intensity typed: Ctrl+Z takes back the
    intensity, then the light, then the preset (the file's own materials back), in that order;
    Ctrl+Shift+Z brings them back the same way. (The light stayed at 500 and Ctrl+Z reached past
    it to the preset.)"""
    s = editor().state
    ctx.set_ref("alight")
    if not s.use_file_materials:
        ctx.item_check(BOX)
    ctx.item_click("**/gold")
    assert not s.use_file_materials and s.material.name == "gold", s.message
    ctx.item_open("**/Lights")
    n = len(s.lights)
    ctx.item_click("**/add spot")
    ctx.yield_(2)
    assert len(s.lights) == n + 1 and s.lights[n].kind == "spot", s.lights
    added = s.lights[n].intensity
    ctx.item_input_value(f"**/$${n}/intensity", 500.0)
    ctx.yield_(2)
    assert s.lights[n].intensity == 500.0, s.lights[n]
    _undo(ctx)
    assert len(s.lights) == n + 1 and s.lights[n].intensity == added, s.lights
    assert s.material.name == "gold" and not s.use_file_materials, s.message
    assert s.message == f"undo: light {n} intensity 500 -> {added:g}", s.message
    _undo(ctx)
    assert len(s.lights) == n and s.material.name == "gold", (s.lights, s.message)
    assert s.message == f"undo: light {n} (spot) removed", s.message
    _undo(ctx)
    assert s.use_file_materials and len(s.lights) == n, s.message
    assert s.message == "undo: the mesh file's own materials (was gold)", s.message
    for _ in range(3):
        _undo(ctx, redo=True)
    assert s.material.name == "gold" and not s.use_file_materials, s.message
    assert len(s.lights) == n + 1 and s.lights[n].intensity == 500.0, (s.lights, s.message)
    assert s.message == f"redo: light {n} intensity {added:g} -> 500", s.message
    ctx.set_ref("alight")
    ctx.item_close("**/Lights")


def test_undo_after_a_setting_says_the_setting_stayed(ctx):
    """The exposure is no undo step: a Ctrl+Z after it changed takes back the older preset click
    and says the exposure stayed (it reached past it without a word)."""
    s = editor().state
    ctx.set_ref("alight")
    if not s.use_file_materials:
        ctx.item_check(BOX)
    ctx.item_click("**/copper")   # (gold may be the material already: no step)
    ctx.yield_(2)
    ctx.item_open("**/Display & camera")
    ctx.item_input_value("**/exposure (EV)", 1.5)
    ctx.yield_(2)
    assert s.display.exposure == 1.5, s.display
    _undo(ctx)
    assert s.use_file_materials and s.display.exposure == 1.5, s.message
    assert s.message == ("undo: the mesh file's own materials (was copper); not undone: exposure "
                         "(not in the history)"), s.message
    _undo(ctx, redo=True)
    assert s.message == "redo: copper (was the mesh file's own materials)", s.message
    ctx.set_ref("alight")
    ctx.item_close("**/Display & camera")
