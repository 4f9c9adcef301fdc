"""The panel's state as an artist meets it (issue 22's artist trial), operated through the Dear
ImGui Test Engine: run by tests/test_editor_ui_state.py as ``alight edit --new --ui-test
tests/editor_ui_checks_state.py`` (a real window under Xvfb); not collected by pytest.

The controls stay put while thumbnails arrive; a preset click replaces the maps; the status row
stays in view whatever the scroll and tells an error from a success by colour; a success
replaces an old error; a texture set names the material; the 'texture set' row takes a folder
or several files; 'open mesh' confirms, and the mesh field shows the mesh restored from the
last session (``reopened_mesh_field_shows_the_path``, run by the runner in a second editor).
The last check leaves a mesh file open for that."""

from __future__ import annotations

import json
import os
import sys

import numpy as np

from alight.frontends.editor.ui_test import editor, files_done, on_main_thread, view

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_helpers import ball, type_path  # noqa: E402

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")   # where the files these checks write go
ERROR_RGB = (255, 89, 77)      # panel.ERROR_RGBA in 8 bits
MESSAGE_RGB = (115, 217, 115)  # panel.MESSAGE_RGBA in 8 bits


def key(name: str):
    from imgui_bundle import imgui

    return getattr(imgui.Key, name)


def undo(ctx) -> None:
    """Ctrl+Z over the view (a click on the void first: the panel lets go of the keyboard)."""
    ctx.mouse_click_on_void()
    ctx.key_press(key("mod_ctrl") | key("z"))


def write_png(path: str, rgb: np.ndarray) -> str:
    import OpenImageIO as oiio

    assert oiio.ImageBuf(np.ascontiguousarray(rgb)).write(path), path
    return path


def wood_set(folder: str, stem: str = "wood") -> dict[str, str]:
    """A texture set in Substance's names: brown base colour, mid roughness, a bumpy normal map."""
    os.makedirs(folder, exist_ok=True)
    rng = np.random.default_rng(7)
    brown = np.zeros((32, 32, 3), np.uint8)
    brown[...] = (120, 70, 30)
    rough = np.full((32, 32, 3), 170, np.uint8)
    n = rng.normal(0.0, 0.5, (32, 32, 3))
    n[..., 2] = 1.0
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    normal = np.round((n * 0.5 + 0.5) * 255).astype(np.uint8)
    return {slot: write_png(os.path.join(folder, f"{stem}_{suffix}.png"), pixels)
            for slot, suffix, pixels in (("base_color", "BaseColor", brown), ("roughness", "Roughness", rough),
                                         ("normal", "Normal", normal))}


def capture(ctx, name: str) -> np.ndarray:
    """The whole window as the engine captures it (panel and view, as shown): uint8 (h, w, 4)."""
    import OpenImageIO as oiio
    from imgui_bundle.immapp.testing import capture as engine_capture

    path = os.path.join(OUT, name)
    engine_capture(ctx, path)
    return oiio.ImageBuf(path).get_pixels(oiio.UINT8)


def status_band(ctx, shot: np.ndarray) -> np.ndarray:
    """The panel's top rows as shown, under its title bar: where the status row is to be seen."""
    from imgui_bundle import imgui

    window = ctx.get_window_by_ref("//alight")
    x0, y0 = int(window.pos.x), int(window.pos.y)
    title = imgui.get_font_size() + 2 * imgui.get_style().frame_padding.y
    return shot[y0 + int(title):y0 + int(title + 1.5 * imgui.get_frame_height()), x0:x0 + int(window.size.x), :3]


def content_y(ctx, ref: str) -> float:
    """An item's top in the panel's content (its screen y plus the scroll): moves only when the
    rows above it change height."""
    return ctx.item_info(ref).rect_full.min.y + ctx.get_window_by_ref("//alight").scroll.y


def colour_pixels(band: np.ndarray, rgb) -> int:
    """Pixels within 40 of ``rgb`` in every channel (the glyphs' cores in that colour)."""
    return int((np.abs(band.astype(np.int32) - np.asarray(rgb)).max(axis=2) <= 40).sum())


# --- the controls stay put ---------------------------------------------------------------------------

def test_the_controls_stay_put_while_thumbnails_arrive(ctx):
    """First, with the thumbnail cache empty: each preset's rendered thumbnail replacing its
    swatch leaves every control below the table where it was (a swatch was a framed colour
    button, 3 px taller in its row than the image, so each arrival moved them up)."""
    import time

    thumbs = editor().thumbnails
    ctx.set_ref("alight")
    ctx.yield_(2)
    before = content_y(ctx, "**/export glTF")
    assert thumbs.pending(), "no thumbnail left to arrive: the cache was not empty"
    start = time.monotonic()
    while thumbs.pending():
        assert time.monotonic() - start < 400, thumbs.pending()
        ctx.yield_()
        assert content_y(ctx, "**/export glTF") == before, (content_y(ctx, "**/export glTF"), before)
    ctx.yield_(2)
    assert content_y(ctx, "**/export glTF") == before, (content_y(ctx, "**/export glTF"), before)


# --- 1: a preset is a whole material ----------------------------------------------------------------

def test_a_preset_click_replaces_the_texture_maps(ctx):
    """Silver clicked over a loaded wood set is silver (the ball equals silver's plain render),
    not silver's factors times brown, bumpy maps; Ctrl+Z brings the maps back. A library entry
    clicked brings its own maps; a factor-only preset after it clears them again."""
    s = editor().state
    files = wood_set(os.path.join(OUT, "wood_over_silver"))
    ctx.set_ref("alight")
    ctx.item_click("**/silver")
    plain = ball(view(ctx))
    type_path(ctx, "**/map file", os.path.dirname(files["base_color"]))   # the set, loaded
    ctx.item_click("**/load##typed")
    assert s.texture_maps.paths() == files, (s.texture_maps.paths(), s.error)
    textured = ball(view(ctx))
    assert np.abs(textured - plain).mean() > 10, np.abs(textured - plain).mean()
    ctx.item_click("**/silver")
    assert s.texture_maps.paths() == {}, s.texture_maps.paths()
    assert s.material.name == "silver"
    again = ball(view(ctx))
    assert np.abs(again - plain).max() <= 1, np.abs(again - plain).max()
    undo(ctx)   # one step: the maps and the material before the click
    assert s.texture_maps.paths() == files, s.texture_maps.paths()
    np.testing.assert_allclose(ball(view(ctx)), textured, atol=1)
    # A library entry is a whole material too: its own maps.
    ctx.item_input_value("**/library name", "wood lib")
    ctx.item_click("**/save to library")
    assert "wood_lib.glb" in s.message, (s.message, s.error)
    ctx.yield_(2)
    ctx.item_click("**/copper")
    assert s.texture_maps.paths() == {}, s.texture_maps.paths()
    ctx.item_click("**/wood_lib##library")
    # (The library's .glb packs the roughness map into glTF's metallic-roughness image.)
    assert {"base_color", "normal", "metallic_roughness"} <= set(s.texture_maps.paths()), s.texture_maps.paths()
    np.testing.assert_allclose(ball(view(ctx)).mean(axis=0), textured.mean(axis=0), atol=2)
    ctx.item_click("**/silver")
    assert s.texture_maps.paths() == {} and np.abs(ball(view(ctx)) - plain).max() <= 1


# --- 2 and 5: the status row ------------------------------------------------------------------------

def test_the_status_row_stays_in_view_when_the_panel_is_scrolled(ctx):
    """With every section open and the panel scrolled down to 'export glTF', it says it exported
    in green and an export that fails says so in red, in the row under the panel's title bar;
    the controls stay where they were when the message comes."""
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    for header in ("Environment", "Lights", "Display & camera", "Compare", "Accuracy chart"):
        ctx.item_open(f"**/{header}")
    ctx.item_input_value("**/glTF file", os.path.join(OUT, "scrolled.gltf"))
    ctx.yield_(2)
    before = content_y(ctx, "**/export glTF")
    ctx.item_click("**/export glTF")
    files_done(ctx)
    assert os.path.isfile(os.path.join(OUT, "scrolled.gltf")) and s.message.startswith("exported"), s.message
    assert content_y(ctx, "**/export glTF") == before
    scroll = ctx.get_window_by_ref("//alight").scroll.y
    assert scroll > 100, scroll   # the panel's top is far out of view
    band = status_band(ctx, capture(ctx, "status_scrolled_ok.png"))
    assert colour_pixels(band, MESSAGE_RGB) > 20 and colour_pixels(band, ERROR_RGB) == 0, \
        (colour_pixels(band, MESSAGE_RGB), colour_pixels(band, ERROR_RGB))
    ctx.item_input_value("**/glTF file", os.path.join(OUT, "no_such_folder", "x.gltf"))
    ctx.yield_(2)
    before = content_y(ctx, "**/export glTF")
    ctx.item_click("**/export glTF")
    files_done(ctx)
    assert s.error and not s.message, (s.error, s.message)
    band = status_band(ctx, capture(ctx, "status_scrolled_error.png"))
    assert colour_pixels(band, ERROR_RGB) > 20 and colour_pixels(band, MESSAGE_RGB) == 0, \
        (colour_pixels(band, ERROR_RGB), colour_pixels(band, MESSAGE_RGB))
    assert content_y(ctx, "**/export glTF") == before, (content_y(ctx, "**/export glTF"), before)
    ctx.scroll_to_top("//alight")
    for header in ("Environment", "Lights", "Display & camera", "Compare", "Accuracy chart"):
        ctx.item_close(f"**/{header}")


def test_a_success_replaces_an_old_error(ctx):
    """An error (a preset file that is not there), then a preset click, the studio button and a
    preview mesh picked: each success clears the error, and the row turns from red to green."""
    s = editor().state
    ctx.set_ref("alight")
    ctx.scroll_to_top("//alight")

    def fail() -> None:
        ctx.item_input_value("**/preset file", os.path.join(OUT, "not_there.json"))
        ctx.item_click("**/load preset")
        assert s.error, s.message
        ctx.yield_(2)
        band = status_band(ctx, capture(ctx, "status_error.png"))
        assert colour_pixels(band, ERROR_RGB) > 20, colour_pixels(band, ERROR_RGB)

    fail()
    ctx.item_click("**/copper")
    assert not s.error and s.message == "applied copper", (s.error, s.message)
    assert editor().panel.shown_error == ""
    band = status_band(ctx, capture(ctx, "status_ok.png"))
    assert colour_pixels(band, MESSAGE_RGB) > 20 and colour_pixels(band, ERROR_RGB) == 0
    ctx.item_open("**/Environment")
    fail()
    ctx.item_click("**/studio")
    assert not s.error and s.message == "environment: studio", (s.error, s.message)
    fail()
    ctx.combo_click("preview mesh/cube")
    assert not s.error and s.message == "mesh: cube", (s.error, s.message)
    ctx.combo_click("preview mesh/sphere")
    ctx.item_close("**/Environment")


# --- 3 and 6: texture sets ---------------------------------------------------------------------------

def test_a_texture_set_names_the_material_undoably(ctx):
    """A folder loaded over gold names the material after the folder, in the state, the view's
    material and the exported glTF; Ctrl+Z gives gold back. A name the artist typed is kept."""
    s = editor().state
    folder = os.path.join(OUT, "oak_planks")
    wood_set(folder, "oak")
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    type_path(ctx, "**/map file", folder)   # the older route, a folder typed into 'map file'
    ctx.item_click("**/load##typed")
    assert s.texture_maps.paths(), s.error
    assert s.material.name == "oak_planks", s.material.name
    path = os.path.join(OUT, "oak.gltf")
    ctx.item_input_value("**/glTF file", path)
    ctx.item_click("**/export glTF")
    files_done(ctx)
    data = json.loads(open(path, encoding="utf-8").read())
    assert [m["name"] for m in data["materials"]] == ["oak_planks"], data["materials"]
    undo(ctx)
    assert s.material.name == "gold" and not s.texture_maps.paths(), (s.material.name, s.texture_maps)
    ctx.item_click("**/gold")
    ctx.item_input_value("**/name", "my oak")
    type_path(ctx, "**/texture set", folder)
    ctx.item_click("**/load set")
    assert s.texture_maps.paths() and s.material.name == "my oak", (s.material.name, s.error)


def test_revert_after_an_undone_preset_click_is_the_look_before_it(ctx):
    """Silver clicked over a wood set, then Ctrl+Z: 'revert' after a tweak returns to the wood
    look (factors and maps), not to the silver the artist took back; after a preset click it
    returns to the preset, without maps."""
    s = editor().state
    files = wood_set(os.path.join(OUT, "wood_revert"))
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    type_path(ctx, "**/texture set", os.path.dirname(files["base_color"]))
    ctx.item_click("**/load set")
    start = s.look
    assert start[1].paths() == files, (start, s.error)
    wood = ball(view(ctx))
    ctx.item_click("**/silver")
    undo(ctx)
    assert s.look == start, s.look
    ctx.set_ref("alight")
    ctx.item_input_value("**/roughness", 0.4)
    ctx.item_click("**/revert")
    assert s.look == start, s.look
    np.testing.assert_allclose(ball(view(ctx)), wood, atol=1)
    ctx.item_click("**/silver")
    silver = s.look
    ctx.item_input_value("**/roughness", 0.7)
    ctx.item_click("**/revert")
    assert s.look == silver and not s.texture_maps.paths(), s.look


def _left_of_divider(image: np.ndarray, divider: float) -> np.ndarray:
    from alight.frontends.editor.compare_view import split_column

    return image[:, :split_column(divider, image.shape[1])].astype(np.int32)


def test_compare_a_keeps_the_maps_of_its_snapshot(ctx):
    """'snapshot A' over a wood set keeps the wood maps in A while B changes (a preset click on
    B cleared them from A too); 'A preset' is the preset's factors without maps, even while B
    has maps."""
    s = editor().state
    folder = os.path.dirname(wood_set(os.path.join(OUT, "wood_compare"))["base_color"])
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    gold = view(ctx)
    ctx.item_click("**/silver")
    type_path(ctx, "**/texture set", folder)
    ctx.item_click("**/load set")
    wood = view(ctx)
    ctx.item_open("**/Compare")
    ctx.combo_click("compare/material")
    ctx.item_click("**/snapshot A")
    ctx.item_click("**/silver")             # B: plain silver; A stays the wood snapshot
    assert not s.texture_maps.paths()
    divider = s.compare.divider
    a = _left_of_divider(view(ctx), divider)
    assert np.abs(a - _left_of_divider(wood, divider)).max() <= 1, "A lost its snapshot's maps"
    type_path(ctx, "**/texture set", folder)   # B with maps; A a preset
    ctx.item_click("**/load set")
    ctx.combo_click("A preset/gold")
    a = _left_of_divider(view(ctx), divider)
    assert np.abs(a - _left_of_divider(gold, divider)).max() <= 1, "A preset gold drew B's maps"
    ctx.combo_click("compare/off")
    ctx.item_close("**/Compare")


def test_the_library_name_follows_the_material(ctx):
    """A texture set names the material, and 'save to library' names the entry after it
    (the field showed 'my_material'); a name typed in the field wins."""
    s = editor().state
    folder = os.path.join(OUT, "walnut")
    wood_set(folder, "walnut")
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    type_path(ctx, "**/texture set", folder)
    ctx.item_click("**/load set")
    assert s.material.name == "walnut", s.material.name
    ctx.item_click("**/save to library")
    assert s.message.endswith("walnut.glb"), (s.message, s.error)
    ctx.item_input_value("**/library name", "walnut dark")
    ctx.item_click("**/save to library")
    assert s.message.endswith("walnut_dark.glb"), (s.message, s.error)


def test_the_texture_set_row_takes_a_folder_or_several_files(ctx):
    """The 'texture set' row: a folder, or files separated by ';', each to its slot by its name
    (not all to the armed slot); files with no folder of their own name give their common stem.
    The window's drop callback (what glfw calls for several files dropped together) does the same."""
    s = editor().state
    folder = os.path.join(OUT, "maps_mixed")
    os.makedirs(folder, exist_ok=True)
    red = np.zeros((16, 16, 3), np.uint8)
    red[..., 0] = 230
    color = write_png(os.path.join(folder, "Bricks012_2K_Color.png"), red)
    rough = write_png(os.path.join(folder, "Bricks012_2K_Roughness.png"), np.full((16, 16, 3), 40, np.uint8))
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    white = ball(view(ctx)).mean(axis=0)
    type_path(ctx, "**/texture set", f"{color};{rough}")
    ctx.item_click("**/load set")
    assert s.texture_maps.paths() == {"base_color": color, "roughness": rough}, (s.texture_maps.paths(), s.error)
    assert s.material.name == "Bricks012", s.material.name
    assert s.message.startswith("texture set: ") and "Bricks012_2K_Color.png -> base_color" in s.message, s.message
    mapped = ball(view(ctx)).mean(axis=0)
    assert mapped[0] > 1.5 * mapped[1] and white[0] < 1.3 * white[1], (mapped, white)
    ctx.item_click("**/plastic_high")
    type_path(ctx, "**/texture set", folder)   # the folder: its name
    ctx.item_click("**/load set")
    assert s.texture_maps.paths() == {"base_color": color, "roughness": rough} and s.material.name == "maps_mixed"
    type_path(ctx, "**/texture set", os.path.join(folder, "missing_Normal.png"))
    ctx.item_click("**/load set")
    assert "missing_Normal.png" in s.error and s.texture_maps.paths()["base_color"] == color, s.error
    ctx.item_click("**/plastic_high")
    on_main_thread(ctx, lambda: editor().drop([color, rough]))   # as glfw's drop callback
    assert s.texture_maps.paths() == {"base_color": color, "roughness": rough}, (s.texture_maps.paths(), s.error)
    assert s.material.name == "Bricks012" and not s.error, (s.material.name, s.error)
    ctx.item_click("**/plastic_high")


# --- 4: open mesh (last: it leaves the mesh open for the reopened editor) ----------------------------

def mesh_file() -> str:
    return os.path.join(OUT, "panel_box.obj")


def test_open_mesh_confirms_in_the_message_row(ctx):
    """'open mesh' on a typed OBJ says so in the message row, replacing an error shown before."""
    import trimesh

    s = editor().state
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(mesh_file())
    ctx.set_ref("alight")
    ctx.item_input_value("**/preset file", os.path.join(OUT, "not_there.json"))
    ctx.item_click("**/load preset")
    assert s.error
    ctx.item_open("**/Environment")
    type_path(ctx, "**/mesh", mesh_file())
    ctx.item_click("**/open mesh")
    files_done(ctx)
    assert s.mesh_spec == mesh_file(), (s.mesh_spec, s.error)
    assert not s.error and s.message == f"opened mesh {mesh_file()}", (s.error, s.message)
    ctx.yield_(2)
    band = status_band(ctx, capture(ctx, "status_mesh.png"))
    assert colour_pixels(band, MESSAGE_RGB) > 20 and colour_pixels(band, ERROR_RGB) == 0
    ctx.item_close("**/Environment")


def reopened_mesh_field_shows_the_path(ctx):
    """Run in the editor reopened after this file's run (the runner's second editor): the mesh
    restored from the session is the one in the mesh field, not an empty field."""
    s = editor().state
    assert s.mesh_spec == mesh_file(), s.mesh_spec
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.yield_(2)
    assert editor().panel.mesh_path == mesh_file(), repr(editor().panel.mesh_path)
    # What the field shows is what 'open mesh' opens: pressed now, the same mesh, confirmed.
    ctx.item_click("**/open mesh")
    files_done(ctx)
    assert s.mesh_spec == mesh_file() and s.message == f"opened mesh {mesh_file()}", (s.mesh_spec, s.message, s.error)
    ctx.item_close("**/Environment")
