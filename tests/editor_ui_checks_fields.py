"""Checks for `alight edit --ui-test` (run by tests/test_editor_ui_fields.py, window 1280x720):
Enter in a field naming a file to open does what the button beside it does, and a long tooltip
wraps inside the window. Each types and hovers as a user does; none clicks the buttons."""

from __future__ import annotations

import os

import numpy as np

from alight.frontends.editor.ui_test import editor, files_done

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")
SHARED = "/work/shared/data"


def test_enter_in_the_env_file_field_opens_it(ctx):
    s = editor().state
    path = os.path.join(SHARED, "env", "quarry_01_1k.hdr")
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.item_input_value("**/env file", path)   # types the path, then Enter; no click on 'open env'
    ctx.yield_(2)
    assert s.env_spec == path and "as the environment" in s.message, (s.env_spec, s.message, s.error)


def test_enter_in_the_mesh_field_opens_it(ctx):
    import trimesh

    s = editor().state
    path = os.path.join(OUT, "entered_box.obj")
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(path)
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.item_input_value("**/mesh", path)
    files_done(ctx)
    assert s.mesh_spec == path and not s.error, (s.mesh_spec, s.error)
    ctx.item_input_value("**/mesh", "sphere")   # a built-in's name too
    files_done(ctx)
    assert s.mesh_spec == "sphere", (s.mesh_spec, s.error)


def test_enter_in_the_map_and_set_fields_loads_them(ctx):
    from PIL import Image

    s = editor().state
    folder = os.path.join(OUT, "entered_set")
    os.makedirs(folder, exist_ok=True)
    png = os.path.join(folder, "tile_BaseColor.png")
    Image.fromarray(np.full((8, 8, 3), (200, 120, 60), np.uint8)).save(png)
    Image.fromarray(np.full((8, 8, 3), 128, np.uint8)).save(os.path.join(folder, "tile_Roughness.png"))
    ctx.set_ref("alight")
    ctx.item_open("**/texture maps")
    s.armed_slot = "emissive"   # (the slot a typed map goes to: set up, not under test)
    ctx.item_input_value("**/map file", png)
    ctx.yield_(2)
    assert s.texture_maps.emissive == png, (s.texture_maps, s.error)
    ctx.item_input_value("**/texture set", folder)
    ctx.yield_(2)
    assert (s.texture_maps.base_color, s.texture_maps.emissive) == (png, ""), (s.texture_maps, s.error)
    assert s.texture_maps.roughness.endswith("tile_Roughness.png"), s.texture_maps


def test_a_long_tooltip_wraps_inside_the_window(ctx):
    """The 'ground' checkbox's tooltip was one line wider than a 1280 px window, cut at its edge."""
    from imgui_bundle import imgui

    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.mouse_move("**/ground")
    ctx.yield_(3)
    tip = imgui.internal.find_window_by_name("##Tooltip_00")
    assert tip is not None and tip.active, "no tooltip over 'ground'"
    width = imgui.get_io().display_size.x
    left, right = tip.pos.x, tip.pos.x + tip.size.x
    assert 0.0 <= left and right <= width, f"the tooltip spans x {left:.0f}-{right:.0f} of a {width:.0f} px window"
    # imgui clamps the tooltip's window to the screen: the text inside it must fit it too (the
    # unwrapped line was 1540 px of text in a 1274 px window, cut at the right).
    inner = tip.size.x - 2.0 * imgui.get_style().window_padding.x
    assert tip.content_size.x <= inner + 1.0, f"the tooltip's text is {tip.content_size.x:.0f} px in {inner:.0f}"
    assert tip.content_size.y >= 2.0 * imgui.get_font_size(), f"one line ({tip.content_size.y:.0f} px high)"


def test_a_typed_out_of_range_number_is_clamped_and_a_valid_edit_clears_the_error(ctx):
    """Ctrl+click roughness, type -0.3: clamped to 0 as imgui's AlwaysClamp sliders do (it was
    refused with 'panel: field ...' in red). An error shown (a map file that is not there) goes
    with the next valid edit, typed or dragged: a success replaces it (it stayed on screen)."""
    from imgui_bundle import imgui

    s, panel = editor().state, editor().panel
    ctx.set_ref("alight")
    ctx.item_input_value("**/roughness", -0.3)
    ctx.yield_(2)
    assert s.material.roughness == 0.0 and not s.error, (s.material.roughness, s.error)
    ctx.item_open("**/texture maps")
    for edit in (lambda: ctx.item_input_value("**/roughness", 0.6),
                 lambda: ctx.item_drag_with_delta("**/roughness", imgui.ImVec2(-400.0, 0.0))):
        ctx.item_input_value("**/map file", os.path.join(OUT, "no_such_map.png"))
        ctx.yield_(2)
        assert s.error and panel.shown_status.startswith("error: "), panel.shown_status
        assert not s.error.startswith("panel"), s.error
        before = s.material.roughness
        edit()
        ctx.yield_(2)
        assert s.material.roughness != before and not s.error, (s.material.roughness, s.error)
        assert not panel.shown_status.startswith("error"), panel.shown_status
    assert s.material.roughness == 0.0, s.material.roughness
    ctx.item_close("**/texture maps")
