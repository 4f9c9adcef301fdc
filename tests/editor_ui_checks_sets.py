"""Texture sets one after another, the path fields that name them, undo's status row and a saved
preset's name (what a fresh artist trial found), operated by the Dear ImGui Test Engine. Run by
tests/test_editor_ui_sets.py as ``alight edit --new --ui-test tests/editor_ui_checks_sets.py`` (a
real window under Xvfb); not collected by pytest. Each check operates the panel's controls and
looks at the view's pixels, the fields the panel shows or the file written.

- a texture set loaded after another is the new set alone: the same pixels as loading it over
  the same preset, no map of the first left in a slot the second leaves empty;
- the 'texture set' field names the set loaded, and both map fields are empty after a preset
  click;
- several files loaded as a set: the field names their shared name, count and folder (it showed
  the first file's path, read as the one map loaded), its tooltip lists each file with its
  slots, and 'load set' on the field as shown loads the same files again;
- Ctrl+Z says in the status row where it went (it kept saying 'applied silver');
- 'save preset' to NAME.json names the material NAME, so the library entry and the file agree,
  and the entry it adds moves no control below the library's list; a name typed into 'name' is
  the one the file holds.
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np
from PIL import Image

from alight.frontends.editor.ui_test import editor, view

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_helpers import type_path  # noqa: E402

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")   # the run's folder (the editor's cwd too)


def _write_set(folder: str, name: str, maps: dict) -> str:
    """Maps named as Substance writes them (NAME_BaseColor.png ...) from {suffix: (h, w, c) uint8}."""
    os.makedirs(folder, exist_ok=True)
    for suffix, pixels in maps.items():
        Image.fromarray(pixels).save(os.path.join(folder, f"{name}_{suffix}.png"))
    return folder


def _sets() -> tuple[str, str]:
    """'wood': base colour, normal, roughness, a white metallic map and an emissive one; 'rock':
    base colour and roughness only (a dielectric set that does not glow)."""
    yy, xx = np.mgrid[0:32, 0:32]
    checker = ((yy // 8 + xx // 8) % 2).astype(np.uint8)
    wood = _write_set(os.path.join(OUT, "sets", "wood"), "wood", {
        "BaseColor": np.dstack([120 + 60 * checker, 70 + 30 * checker, 30 + 0 * checker]).astype(np.uint8),
        "Normal": np.dstack([np.full((32, 32), 128), np.full((32, 32), 128), np.full((32, 32), 255)]).astype(np.uint8),
        "Roughness": np.full((32, 32), 200, np.uint8),
        "Metallic": np.full((32, 32), 255, np.uint8),
        "Emissive": np.full((32, 32, 3), 90, np.uint8),
    })
    rock = _write_set(os.path.join(OUT, "sets", "rock"), "rock", {
        "BaseColor": np.dstack([90 + 90 * checker, 90 + 90 * checker, 100 + 90 * checker]).astype(np.uint8),
        "Roughness": np.full((32, 32), 150, np.uint8),
    })
    return wood, rock


def _load_set(ctx, folder: str) -> None:
    type_path(ctx, "**/texture set", folder)
    ctx.item_click("**/load set")
    ctx.yield_(3)


def test_a_set_loaded_after_another_is_the_new_set_alone(ctx):
    s = editor().state
    wood, rock = _sets()
    ctx.set_ref("alight")
    ctx.item_open("**/texture maps")
    ctx.item_click("**/plastic_high")
    _load_set(ctx, rock)
    assert not s.error, s.error
    alone, alone_maps = view(ctx).astype(np.float64), s.texture_maps.paths()
    ctx.item_click("**/plastic_high")
    _load_set(ctx, wood)
    assert set(s.texture_maps.paths()) == {"base_color", "normal", "roughness", "metallic", "emissive"}, s.texture_maps
    _load_set(ctx, rock)
    assert s.texture_maps.paths() == alone_maps, s.texture_maps.paths()   # wood's metal, normal, glow gone
    after = view(ctx).astype(np.float64)
    assert s.material.metallic == 0.0 and s.material.emissive == (0.0, 0.0, 0.0), s.material
    assert np.abs(after - alone).max() <= 1, np.abs(after - alone).max()
    ctx.item_close("**/texture maps")


def test_the_set_fields_name_what_is_loaded(ctx):
    s, panel = editor().state, editor().panel
    wood, rock = _sets()
    ctx.set_ref("alight")
    ctx.item_open("**/texture maps")
    _load_set(ctx, wood)
    type_path(ctx, "**/map file", rock)   # a folder typed into 'map file' is a set too
    ctx.item_click("**/load##typed")
    ctx.yield_(2)
    assert set(s.texture_maps.paths()) == {"base_color", "roughness"}, s.texture_maps
    assert panel.set_path == rock, panel.set_path
    ctx.item_click("**/copper")   # a preset has no maps: neither field names any
    ctx.yield_(2)
    assert not s.texture_maps.paths() and panel.set_path == "" and panel.map_path == "", \
        (panel.set_path, panel.map_path)
    _ctrl_z(ctx)
    assert panel.set_path == rock and s.texture_maps.paths(), panel.set_path   # undo brings the set back
    ctx.item_close("**/texture maps")


def test_a_set_of_files_is_named_by_its_stem_and_count_with_the_files_in_the_tooltip(ctx):
    import alight.frontends.editor.panel as panel_module

    s, panel = editor().state, editor().panel
    wood, _ = _sets()
    files = [os.path.join(wood, f"wood_{suffix}.png") for suffix in ("BaseColor", "Roughness", "Normal")]
    ctx.set_ref("alight")
    ctx.item_open("**/texture maps")
    _load_set(ctx, ";".join(files))
    assert not s.error and set(s.texture_maps.paths()) == {"base_color", "roughness", "normal"}, \
        (s.error, s.texture_maps)
    assert panel.set_path == f"wood_* (3 maps) in {wood}", panel.set_path
    shown = []
    keep = panel_module.tooltip
    panel_module.tooltip = lambda text: (shown.append(text), keep(text))
    try:
        ctx.mouse_move("**/texture set")
        ctx.yield_(3)
    finally:
        panel_module.tooltip = keep
    assert shown and shown[-1].startswith(f"3 maps in {wood}:\n  wood_BaseColor.png: base colour\n"), shown[-1:]
    assert "  wood_Normal.png: normal (tangent)\n  wood_Roughness.png: roughness (grey)\n\n" in shown[-1], shown[-1]
    s.message = ""
    maps = s.texture_maps
    ctx.item_click("**/load set")   # the field as shown: the same three files again, not an error
    ctx.yield_(2)
    assert not s.error and s.message.startswith("texture set: "), (s.error, s.message)
    assert s.texture_maps == maps and panel.set_path == f"wood_* (3 maps) in {wood}", panel.set_path
    ctx.item_click("**/copper")   # (the next checks start without maps)
    ctx.yield_(2)
    ctx.item_close("**/texture maps")


def _ctrl_z(ctx) -> None:
    """Ctrl+Z in the view (a click on the view first: the panel lets go of the keyboard)."""
    from imgui_bundle import imgui

    ctx.mouse_click_on_void()
    ctx.key_press(imgui.Key.mod_ctrl | imgui.Key.z)
    ctx.yield_(2)


def _message_part(panel) -> str:
    """The status row's message: its first part, before the grey background notes (a shader
    compiling, the occlusion bake) that follow it after ' | '."""
    return panel.shown_status.split(" | ")[0]


def test_undo_says_where_it_went(ctx):
    s, panel = editor().state, editor().panel
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    ctx.item_click("**/silver")
    ctx.yield_(2)
    assert _message_part(panel).endswith("applied silver"), panel.shown_status
    _ctrl_z(ctx)
    assert s.material.name == "gold" and _message_part(panel).endswith("undo: gold (was silver)"), panel.shown_status
    ctx.item_click("**/redo")
    ctx.yield_(2)
    assert s.material.name == "silver" and _message_part(panel).endswith("redo: silver (was gold)"), panel.shown_status


def test_ctrl_z_while_compare_splits_the_view_undoes_b_and_says_what(ctx):
    """With the view split, Ctrl+Z undoes the live material's (B's) last edit and the row says
    which edit (two roughness steps read 'undo: copper' twice before, nothing seen to change);
    A's snapshot or preset, A's IBL model and the compare mode stay. In reference mode an undo
    landing below the reference's minimum roughness names the step before the reference's line
    (the line alone replaced it)."""
    s, panel = editor().state, editor().panel
    c = s.compare
    ctx.set_ref("alight")
    for step in (lambda: ctx.item_click("**/gold"), lambda: ctx.item_click("**/copper"),
                 lambda: ctx.item_input_value("**/roughness", 0.4),
                 lambda: ctx.item_input_value("**/roughness", 0.55)):
        step()
        ctx.yield_(2)   # (each its own undo step, as an artist's edits are)
    ctx.item_open("**/Compare")
    ctx.combo_click("compare/material")
    ctx.item_click("**/snapshot A")
    snapshot = c.a_material
    assert snapshot.roughness == 0.55, snapshot
    _ctrl_z(ctx)
    assert s.material.roughness == 0.4 and c.a_material is snapshot and c.mode == "material", (s.material, c)
    assert _message_part(panel) == "undo on B: copper (roughness 0.55 -> 0.4)", panel.shown_status
    ctx.combo_click("A preset/gold")
    _ctrl_z(ctx)
    assert s.material.roughness == 0.3 and c.a_label == "preset gold" and c.mode == "material", (s.material, c)
    assert _message_part(panel) == "undo on B: copper (roughness 0.4 -> 0.3)", panel.shown_status
    ctx.combo_click("compare/ibl model")
    ctx.combo_click("A IBL model/alight")
    _ctrl_z(ctx)
    assert s.material.name == "gold" and (c.mode, c.a_ibl_model) == ("ibl model", "alight"), (s.material, c)
    assert _message_part(panel) == "undo on B: gold (was copper)", panel.shown_status
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("mod_shift") | imgui_key("z"))
    ctx.yield_(2)
    assert s.material.name == "copper" and _message_part(panel) == "redo on B: copper (was gold)", panel.shown_status
    # Reference mode below its minimum roughness: no sum starts, the error line says why.
    ctx.set_ref("alight")
    ctx.item_input_value("**/roughness", 0.05)
    ctx.yield_(2)
    ctx.item_input_value("**/roughness", 0.04)
    ctx.yield_(2)
    ctx.combo_click("compare/reference")
    ctx.yield_(2)
    assert s.error.startswith("reference compare:"), s.error
    _ctrl_z(ctx)
    assert s.material.roughness == 0.05 and c.mode == "reference", (s.material, c)
    assert panel.shown_status.startswith("error: undo on B: copper (roughness 0.04 -> 0.05); reference compare:"), \
        panel.shown_status
    ctx.yield_(4)   # the view's next frames keep the step's line (the reference's check runs again)
    assert panel.shown_status.startswith("error: undo on B: copper (roughness 0.04 -> 0.05)"), panel.shown_status
    ctx.combo_click("compare/off")
    _ctrl_z(ctx)
    assert s.material.roughness == 0.3 and _message_part(panel) == "undo: copper (roughness 0.05 -> 0.3)", \
        panel.shown_status
    ctx.item_close("**/Compare")


def imgui_key(name: str):
    from imgui_bundle import imgui

    return getattr(imgui.Key, name)


def test_a_saved_preset_is_named_after_its_file(ctx):
    from alight.frontends.editor.library import library_dir

    s, lib = editor().state, editor().panel.library
    path = os.path.join(OUT, "myblue.json")
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_input_value("**/roughness", 0.35)
    ctx.item_input_value("**/preset file", path)
    below = ctx.item_info("**/glTF file").rect_full.min.y
    ctx.item_click("**/save preset")
    ctx.yield_(3)
    # The new library entry moves no control below the list (the next click lands where aimed).
    assert ctx.item_info("**/glTF file").rect_full.min.y == below, (below, ctx.item_info("**/glTF file").rect_full.min.y)
    assert json.loads(open(path, encoding="utf-8").read())["name"] == "myblue", open(path).read()
    assert (library_dir() / "myblue.glb").is_file() and s.material.name == "myblue", s.material.name
    ctx.item_click("**/gold")
    ctx.item_click("**/myblue##library")   # the library's entry gives back the same name
    ctx.yield_(2)
    assert s.material.name == "myblue" and abs(s.material.roughness - 0.35) < 1e-6, s.material
    assert lib.name in ("", "myblue"), lib.name


def test_a_typed_name_is_the_saved_materials_name(ctx):
    """The 'name' field's effect is in the files: a name typed there is what a preset saved under
    another file name holds (the file's name is taken only where no name was typed)."""
    s = editor().state
    path = os.path.join(OUT, "named_file.json")
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_input_value("**/name", "my_copper")
    ctx.item_input_value("**/preset file", path)
    ctx.item_click("**/save preset")
    ctx.yield_(3)
    assert json.loads(open(path, encoding="utf-8").read())["name"] == "my_copper", open(path).read()
    assert s.material.name == "my_copper", s.material.name


def test_a_library_name_typed_names_the_entrys_material(ctx):
    """'save to library' under a typed name: the material in the entry is named so, a click on
    the entry names the material so, and the next save goes back to that entry (it offered to
    replace the entry of the name the work began with)."""
    s, lib = editor().state, editor().panel.library
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_input_value("**/roughness", 0.55)
    ctx.item_input_value("**/library name", "crate_lib")
    ctx.item_click("**/save to library")
    ctx.yield_(3)
    assert s.material.name == "crate_lib" and not lib.pending, (s.material.name, lib.pending, s.message)
    ctx.item_click("**/gold")
    ctx.item_click("**/crate_lib##library")
    ctx.yield_(2)
    assert s.material.name == "crate_lib" and abs(s.material.roughness - 0.55) < 1e-6, s.material
    ctx.item_input_value("**/roughness", 0.6)
    ctx.item_click("**/save to library")
    ctx.yield_(3)
    assert lib.pending == "crate_lib", (lib.pending, s.message)   # it asks to replace this entry
    ctx.set_ref("replace library entry")
    ctx.item_click("replace crate_lib")
    ctx.set_ref("alight")
    ctx.yield_(2)
    assert not lib.pending and s.message.startswith("saved to the library"), (lib.pending, s.message)


def test_every_layer_rows_label_fits_the_panel(ctx):
    """Each layer section opened: every row's label ends inside the panel ('clearcoat
    roughness' read 'clearcoat roughne')."""
    from imgui_bundle import imgui

    from alight.frontends.editor.layer_rows import SECTIONS

    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    edge = imgui.internal.find_window_by_name("alight").inner_clip_rect.max.x
    spacing = imgui.get_style().item_inner_spacing.x
    checked = 0
    for section in SECTIONS:
        ctx.item_open(f"**/###layer_{section.layer}")
        ctx.yield_(2)
        for row in section.rows:
            if row.switch:
                continue   # a checkbox's label is beside its box; the drag appears only when on
            ref = f"###layer_{section.layer}/{row.label}"
            if row.widget == "color":   # a group: its last part, the swatch, then the label
                right = ctx.item_info(f"{ref}/##ColorButton").rect_full.max.x + spacing \
                    + imgui.calc_text_size(row.label).x
            else:
                right = ctx.item_info(ref).rect_full.max.x
            assert right <= edge + 0.5, f"'{row.label}' ends at x={right:.0f}, past the panel's edge {edge:.0f}"
            checked += 1
        ctx.item_close(f"**/###layer_{section.layer}")
    assert checked >= 15, checked


def test_adding_a_light_says_so(ctx):
    s, panel = editor().state, editor().panel
    ctx.set_ref("alight")
    ctx.item_open("**/Lights")
    n = len(s.lights)
    ctx.item_click("**/add spot")
    ctx.yield_(2)
    assert len(s.lights) == n + 1 and _message_part(panel).endswith(f"added light {n}: spot"), panel.shown_status
    ctx.item_click(f"**/$${n}/remove")
    ctx.yield_(2)
    assert len(s.lights) == n and f"removed light {n}" in panel.shown_status, panel.shown_status
    ctx.item_close("**/Lights")
