"""An artist's trial's leftovers, operated by the Dear ImGui Test Engine in a 700 px wide window
(a 350 px panel). Run by tests/test_editor_ui_artist.py as ``alight edit --new --size 700x500
--ui-test tests/editor_ui_checks_artist.py`` under Xvfb; not collected by pytest. The one setting
made directly is the file browser's kind (the built-in one: a native dialog is another program).

- 'browse mesh': the built-in browser lists the mesh files alight reads, a row's click opens the
  file as 'open mesh' does (on the file-jobs thread);
- the status row: an error naming a long path is drawn with "..." for its middle (not cut silently at the
  panel's edge), hovering it shows it whole;
- the Compare section's 'A preset' combo names A from its first frame ('pick a preset', the
  snapshot, the preset), never an empty box;
- at this width the rows' labels end inside the panel.
"""

from __future__ import annotations

import os
import sys

import numpy as np

from alight.frontends.editor.ui_test import editor, files_done, view

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_helpers import capture  # noqa: E402

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")   # the run's folder (the editor's cwd too)
BROWSER = "###file browser"   # the built-in browser's window (its title changes, its ID does not)


def _panel_right(ctx) -> float:
    """The panel's inner right edge (where its rows are clipped), window coordinates."""
    return ctx.get_window_by_ref("//alight").inner_clip_rect.max.x


def test_browse_mesh_opens_the_picked_file(ctx):
    import trimesh

    win = editor()
    s, panel = win.state, win.panel
    panel.browser.native = False   # the built-in browser (a native dialog is another program)
    folder = os.path.join(OUT, "browse_mesh", "meshes")
    os.makedirs(folder, exist_ok=True)
    cube = os.path.join(folder, "box.obj")
    trimesh.creation.box((1.2, 1.2, 1.2)).export(cube)
    with open(os.path.join(folder, "notes.txt"), "w") as f:   # not a mesh: not listed
        f.write("not a mesh\n")
    ctx.set_ref("alight")
    sphere = view(ctx).astype(np.float64)
    ctx.item_open("**/Environment")
    ctx.item_click("**/browse mesh")
    browser = panel.browser
    assert browser.visible and set(browser.suffixes) == {".gltf", ".glb", ".obj", ".ply", ".stl"}, browser.suffixes
    ctx.set_ref(BROWSER)
    try:
        ctx.item_input_value("path", os.path.join(OUT, "browse_mesh"))   # a folder: the browser goes there
        ctx.item_click("**/[meshes]")
        assert browser.entries()[1] == ["box.obj"], browser.entries()
        ctx.item_click("**/box.obj")
    finally:   # a failure here must not leave the browser open for the next checks
        if browser.visible:
            ctx.item_click("cancel")
    assert not browser.visible
    files_done(ctx)
    assert s.mesh_spec == cube and panel.mesh_path == cube, (s.mesh_spec, panel.mesh_path, s.error)
    assert panel.shown_status.startswith(f"opened mesh {cube}"), panel.shown_status
    boxed = view(ctx).astype(np.float64)
    assert np.abs(boxed - sphere).mean() > 1.0   # the box, not the sphere
    # Browsing again starts in the open mesh's folder (it stayed wherever the browser was last:
    # at first the working directory, four clicks from a user's models).
    from pathlib import Path

    browser.directory = Path(OUT)   # (the browser elsewhere, as after another row's pick)
    ctx.set_ref("alight")
    ctx.item_click("**/browse mesh")
    try:
        assert browser.visible and browser.directory == Path(folder).resolve(), browser.directory
    finally:
        if browser.visible:
            ctx.set_ref(BROWSER)
            ctx.item_click("cancel")
    ctx.set_ref("alight")
    ctx.combo_click("preview mesh/sphere")
    assert s.mesh_spec == "sphere", s.error
    ctx.item_close("**/Environment")


def test_a_long_error_is_cut_with_dots_and_shown_whole_on_hover(ctx):
    win = editor()
    s, panel = win.state, win.panel
    missing = os.path.join(OUT, "a folder with a rather long name", "and another one below it",
                           "studio_lighting_for_the_product_shots_final_v3.hdr")
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.item_input_value("**/env file", missing)   # Enter opens it
    ctx.yield_(2)
    assert s.error and missing in s.error, s.error
    whole = panel.shown_status
    assert whole == f"error: {s.error}", whole
    row = panel.shown_row
    assert row.startswith("error: ") and "..." in row and len(row) < len(whole), row
    assert row.endswith("no such file"), row   # the problem stays in view, the path's middle goes
    head, tail = row.split("...", 1)
    assert whole.startswith(head) and whole.endswith(tail), (row, whole)
    capture(ctx, "long_error.png")   # (to look at: the path's middle '...', the row inside the panel)
    # Hovering the row shows it whole.
    bar = ctx.get_window_by_ref("//alight").menu_bar_rect()
    ctx.mouse_move_to_pos(imgui_vec(bar.min.x + 40.0, 0.5 * (bar.min.y + bar.max.y)))
    ctx.yield_(3)
    assert panel.status_tooltip == whole, (panel.status_tooltip, whole)
    capture(ctx, "long_error_hovered.png")
    ctx.item_click("**/studio")
    assert not s.error, s.error
    ctx.item_close("**/Environment")


def imgui_vec(x: float, y: float):
    from imgui_bundle import imgui

    return imgui.ImVec2(x, y)


def test_compare_a_preset_names_a_from_its_first_frame(ctx):
    win = editor()
    s, panel = win.state, win.panel
    ctx.set_ref("alight")
    ctx.item_open("**/Compare")
    ctx.combo_click("compare/material")
    ctx.yield_(1)
    assert s.compare.a_material is None
    assert panel.shown_a_preview == "pick a preset", panel.shown_a_preview
    ctx.item_click("**/copper")
    ctx.item_input_value("**/roughness", 0.45)   # no preset now
    ctx.item_click("**/snapshot A")
    ctx.yield_(1)
    assert panel.shown_a_preview == "snapshot of copper", panel.shown_a_preview
    ctx.combo_click("A preset/gold")
    ctx.yield_(1)
    assert s.compare.a_label == "preset gold" and panel.shown_a_preview == "gold", panel.shown_a_preview
    ctx.combo_click("compare/off")
    ctx.item_close("**/Compare")


def test_labels_end_inside_the_panel_at_700_px(ctx):
    """Each row's label ends left of the panel's right edge (at imgui's default widths, 65% of
    the panel, 'scale while moving' and 'turntable frames' ran past it)."""
    from imgui_bundle import imgui
    from imgui_bundle.imgui import test_engine as te

    style = imgui.get_style()

    win = editor()
    assert win.panel_width() == 350, win.panel_width()
    ctx.set_ref("alight")
    # A row's last item, where the label is not one (a colour's swatch, a number's '+' button).
    last = {"base colour (sRGB)": "base colour (sRGB)/##ColorButton", "turntable frames": "turntable frames/+"}
    rows = {"Material": ("base colour (sRGB)", "preset file", "glTF file", "name", "metallic", "roughness", "ior"),
            "Environment": ("env file", "mesh", "preview mesh", "rotation", "intensity", "background",
                            "IBL model", "occlusion", "shadows", "bake quality"),
            "Display & camera": ("tone map", "exposure (EV)", "debug view", "anti-aliasing", "render scale",
                                 "field of view", "turntable frames", "turntable file")}
    for section, labels in rows.items():
        ctx.item_open(f"**/{section}")
        if section == "Display & camera" and win.state.adaptive_motion:
            ctx.item_click("**/###adaptive_motion")   # 'scale while moving' shows when it is off
            labels = labels + ("scale while moving",)
        ctx.yield_(2)
        right = _panel_right(ctx)
        for label in labels:
            ref = last.get(label, label)
            ctx.scroll_to_item_y(ref)   # (the rows are the panel's own, no '**/' search)
            info = ctx.item_info(ref, te.TestOpFlags_.no_error)
            assert info.id_ != 0, f"no row '{label}' in {section}"
            # (The engine's rect is the widget's frame; its label follows it, inner spacing apart.)
            end = info.rect_full.max.x + style.item_inner_spacing.x + imgui.calc_text_size(label).x
            assert end <= right + 0.5, (label, end, right)
        capture(ctx, f"labels_{section.split()[0].lower()}.png")
        if section == "Display & camera":
            ctx.item_click("**/###adaptive_motion")
        if section != "Material":
            ctx.item_close(f"**/{section}")
