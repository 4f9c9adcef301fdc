"""Guards and messages of the panel (what a second artist trial found), through its real UI. Run by tests/test_editor_ui_guards.py
as ``alight edit --new --ui-test tests/editor_ui_checks_guards.py`` (the Dear ImGui Test Engine
against the real window under Xvfb); not collected by pytest.

'save preset' to a .json with maps loaded writes the factors and says so; a path that failed to
load, open or save does not stay in its field; the reference compare's errors name the panel's
controls, not the CLI's flags; replacing a library entry asks first.

Run as a script (``python tests/editor_ui_checks_guards.py xdotool``, DISPLAY set), it drives the
editor's own glfw loop with real X clicks from xdotool while each frame takes 0.3 s: a second
click aimed at a light's 'remove' (or at a section header) arriving before the frame that moved
the panel is shown does not land on the control that moved there.
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_helpers import type_path  # noqa: E402

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")


def _png(path: str, rgb) -> str:
    from PIL import Image

    Image.fromarray(np.full((8, 8, 3), rgb, np.uint8)).save(path)
    return path


# --- 2: save preset with maps loaded -------------------------------------------------------------

def test_save_preset_to_json_with_maps_writes_the_factors_and_says_so(ctx):
    from alight.frontends.editor.ui_test import editor

    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_input_value("**/roughness", 0.35)
    type_path(ctx, "**/map file", _png(os.path.join(OUT, "tint_BaseColor.png"), (200, 120, 60)))
    ctx.item_click("**/load##typed")
    assert s.texture_maps.base_color, (s.error, s.message)
    path = os.path.join(OUT, "with_maps.json")
    ctx.item_input_value("**/preset file", path)
    ctx.item_click("**/save preset")
    assert not s.error, s.error
    assert os.path.isfile(path), s.message
    saved = json.loads(open(path, encoding="utf-8").read())
    assert abs(saved["roughness"] - 0.35) < 1e-6 and saved["metallic"] == s.material.metallic, saved
    assert "1 map left out" in s.message and "base_color" in s.message and ".gltf or .glb" in s.message, s.message
    assert s.message.startswith(f"saved {path}"), s.message
    ctx.item_click("**/clear")   # the base colour slot's (the first row's)


def test_save_preset_of_a_texture_set_keeps_its_look_in_the_factors_and_no_maps_in_the_library(ctx):
    """DamagedHelmet's five maps as a set, then 'save preset' and 'load preset': the factors the
    set left at glTF's 1 came back alone as a white, fully metallic, self-lit helmet, and the
    library got a 15 MB .glb of the maps. Now the preset holds the maps' average look (emissive
    from the map's mostly dark median), and the library's copy is what the preset holds."""
    from alight.frontends.editor import library
    from alight.frontends.editor.ui_test import editor

    s = editor().state
    helmet = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "..", "shared", "data",
                          "models", "DamagedHelmet")
    ctx.set_ref("alight")
    s.open_texture_set([os.path.join(helmet, f) for f in sorted(os.listdir(helmet)) if f.endswith(".jpg")])
    assert len(s.texture_maps.paths()) == 5 and s.material.emissive == (1.0, 1.0, 1.0), s.texture_maps
    ctx.yield_(2)
    path = os.path.join(OUT, "helmet_look.json")
    ctx.item_input_value("**/preset file", path)
    ctx.item_click("**/save preset")
    assert not s.error, s.error
    assert "5 maps left out" in s.message and "average look" in s.message, s.message
    entry = library.library_dir() / f"helmet_look{library.LIBRARY_SUFFIX}"
    assert entry.is_file() and entry.stat().st_size < 20_000, (entry, s.message)   # factors, no images
    ctx.item_click("**/load preset")
    assert not s.error and not s.texture_maps.paths(), (s.error, s.texture_maps)
    m = s.material
    assert max(m.emissive) < 0.05, m.emissive            # the visor's glow does not light the whole helmet
    assert max(m.base_color) < 0.6 and m.metallic < 0.9, (m.base_color, m.metallic)
    assert 0.2 < m.roughness < 0.95, m.roughness


def test_export_gltf_with_the_files_own_materials_shown_keeps_them_and_says_what_it_left_out(ctx):
    """With a textured file's own materials in the view, the export keeps them (the Duck's
    material and its texture) and the status row says in one line what the file brought that
    did not go out (its camera); with them off, the panel's material on every part, no note."""
    from alight.exchange.gltf_material import read_gltf_json
    from alight.frontends.editor.ui_test import editor, files_done

    s = editor().state
    shared = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "..", "shared", "data")
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    type_path(ctx, "**/mesh", os.path.join(shared, "models", "Duck.glb"))
    ctx.item_click("**/open mesh")
    files_done(ctx)
    assert s.use_file_materials, (s.error, s.message)
    path = os.path.join(OUT, "duck_export.glb")
    ctx.item_input_value("**/glTF file", path)
    ctx.item_click("**/export glTF")
    files_done(ctx)
    assert not s.error, s.error
    assert os.path.isfile(path), s.message
    assert s.message == f"exported {path} (the mesh file's 1 camera left out)", s.message
    doc = read_gltf_json(path)
    assert len(doc["materials"]) == 1 and len(doc["images"]) == 1, doc["materials"]
    assert doc["materials"][0]["name"] != s.material.name, doc["materials"]
    ctx.item_uncheck("**/mesh file's own materials and maps")   # the view shows what is written
    ctx.item_click("**/export glTF")
    files_done(ctx)
    assert s.message == f"exported {path}", s.message
    assert read_gltf_json(path)["materials"][0]["name"] == s.material.name
    ctx.combo_click("preview mesh/sphere")
    ctx.item_close("**/Environment")


# --- 3: a path that failed does not stay in its field ----------------------------------------------

def test_a_failed_path_leaves_the_loaded_one_in_its_field(ctx):
    """mesh, env file, texture set, map file, preset file (load and save), glTF file and library
    name: after a failure the field shows what it showed when it last worked, and the status
    row names the path that failed."""
    import trimesh

    from alight.frontends.editor.ui_test import editor, files_done

    win = editor()
    s, panel = win.state, win.panel
    good_mesh = os.path.join(OUT, "good_box.obj")
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(good_mesh)
    bad = os.path.join(OUT, "no_such_dir", "broken")
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    type_path(ctx, "**/mesh", good_mesh)
    ctx.item_click("**/open mesh")
    files_done(ctx)
    assert s.mesh_spec == good_mesh, s.error
    for field, button, typed in (("mesh", "open mesh", bad + ".obj"), ("env file", "open env", bad + ".hdr")):
        type_path(ctx, f"**/{field}", typed)
        ctx.item_click(f"**/{button}")
        files_done(ctx)
        assert typed in s.error, (field, s.error)
        shown = {"mesh": panel.mesh_path, "env file": panel.env_path}[field]
        assert shown != typed, f"the {field} field still shows the path that failed: {shown}"
    assert panel.mesh_path == s.mesh_spec == good_mesh, (panel.mesh_path, s.mesh_spec)
    assert panel.env_path == "", panel.env_path   # the studio is loaded: no file
    ctx.combo_click("preview mesh/shader_ball")   # a built-in: the field shows it, not the last file
    assert s.mesh_spec == "shader_ball", s.error
    assert panel.mesh_path == "shader_ball", f"the mesh field shows {panel.mesh_path!r} with the shader ball loaded"
    ctx.combo_click("preview mesh/sphere")   # back to the ball the next checks look at
    assert panel.mesh_path == "sphere", panel.mesh_path
    ctx.item_close("**/Environment")
    # (The map file field keeps what was typed: test_a_bad_map_path_stays_typed_in_its_field.)
    checks = (("texture set", "load set", bad, lambda: panel.set_path),
              ("preset file", "load preset", bad + ".json", lambda: panel.preset_path),
              ("preset file", "save preset", bad + ".json", lambda: panel.preset_path),
              ("glTF file", "export glTF", bad + ".gltf", lambda: panel.gltf_path))
    for field, button, typed, shown in checks:
        before = shown()
        type_path(ctx, f"**/{field}", typed)
        ctx.item_click(f"**/{button}")
        files_done(ctx)
        assert s.error, (field, button, s.message)
        assert shown() == before, f"{field} after a failed '{button}' shows {shown()!r}, not {before!r}"
    ctx.item_input_value("**/library name", "///")
    ctx.item_click("**/save to library")
    assert "not a library name" in s.error, s.error
    assert panel.library.name == "", panel.library.name   # the field follows the material's name again


# --- 4: messages name the editor's controls ----------------------------------------------------------

def test_reference_compare_errors_name_the_panels_controls(ctx):
    from alight.frontends.editor.ui_test import editor, view

    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_open("**/Compare")
    ctx.combo_click("compare/reference")
    ctx.item_input_value("**/roughness", 0.02)
    view(ctx)
    assert "reference compare:" in s.error and "'roughness' (Material)" in s.error, s.error
    assert "--" not in s.error, s.error
    ctx.item_input_value("**/roughness", 0.5)
    ctx.item_open("**/###layer_clearcoat")
    ctx.item_input_value("**/clearcoat", 1.0)
    ctx.item_input_value("**/clearcoat roughness", 0.02)
    view(ctx)
    assert "'clearcoat roughness' (Material, Clearcoat)" in s.error and "--" not in s.error, s.error
    ctx.item_input_value("**/clearcoat", 0.0)
    ctx.item_close("**/###layer_clearcoat")
    ctx.combo_click("compare/off")
    ctx.item_close("**/Compare")


def test_a_material_files_warning_names_the_editors_controls(ctx):
    """A glTF material whose clearcoat has a texture, opened through 'load preset': the warning
    (on stderr, counted in the panel) points to the editor's mesh field, not to --mesh (the
    runner reads stderr)."""
    from alight.frontends.editor.ui_test import editor

    s = editor().state
    _png(os.path.join(OUT, "coat.png"), (128, 128, 128))
    doc = {"asset": {"version": "2.0"}, "images": [{"uri": "coat.png"}], "textures": [{"source": 0}],
           "materials": [{"name": "coated", "extensions": {"KHR_materials_clearcoat": {
               "clearcoatFactor": 1.0, "clearcoatTexture": {"index": 0}}}}],
           "extensionsUsed": ["KHR_materials_clearcoat"]}
    path = os.path.join(OUT, "coated.gltf")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f)
    ctx.set_ref("alight")
    ctx.item_input_value("**/preset file", path)
    ctx.item_click("**/load preset")
    assert s.material.name == "coated" and not s.error, (s.material.name, s.error)
    ctx.item_click("**/plastic_high")


# --- 1: replacing a library entry asks ---------------------------------------------------------------

def test_replacing_a_library_entry_asks_first(ctx):
    from alight.exchange.material_files import load_material_file
    from alight.frontends.editor.library import library_dir
    from alight.frontends.editor.ui_test import editor

    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    ctx.item_input_value("**/library name", "keepsake")
    ctx.item_click("**/save to library")
    path = library_dir() / "keepsake.glb"
    assert path.is_file(), (s.error, s.message)
    original = path.read_bytes()
    ctx.yield_(2)
    ctx.item_click("**/silver")
    ctx.item_input_value("**/library name", "keepsake")
    ctx.item_click("**/save to library")
    ctx.yield_(2)
    assert path.read_bytes() == original, "the entry was replaced without a question"
    assert "replace it?" in s.message, s.message
    ctx.set_ref("//replace library entry")
    ctx.item_click("keep the old one")
    assert path.read_bytes() == original
    ctx.set_ref("alight")
    ctx.item_input_value("**/library name", "keepsake")
    ctx.item_click("**/save to library")
    ctx.yield_(2)
    ctx.set_ref("//replace library entry")
    ctx.item_click("replace keepsake")
    ctx.set_ref("alight")
    assert path.read_bytes() != original
    saved = load_material_file(str(path))[0]   # silver, named as the entry it was saved as
    assert saved.name == "keepsake" and saved.base_color == s.material.base_color, (saved, s.message)
    # The same material saved again under its name asks nothing.
    ctx.yield_(2)
    ctx.item_click("**/keepsake##library")
    ctx.item_input_value("**/library name", "keepsake")
    ctx.item_click("**/save to library")
    assert s.message.startswith("saved to the library"), s.message
    # A preset saved twice, unchanged, asks nothing either (its F0 of 0.04 comes back from the
    # entry's ior as 0.04000000000000001: an exact comparison asked to replace it).
    ctx.item_click("**/plastic_glass_low")
    for _ in range(2):
        ctx.item_input_value("**/library name", "twice")
        ctx.item_click("**/save to library")
        ctx.yield_(2)
        assert s.message.startswith("saved to the library"), s.message


# --- 1: real X clicks while frames are slow (run as a script) ----------------------------------------

def _own_loop_checks() -> int:
    """xdotool's clicks in `alight edit`'s own window, each frame made 0.3 s longer (as frames
    are here under load): two quick clicks on light 0's 'remove' remove one light, not two; a
    click on the Environment header closing it, and a second 0.1 s later where its 'open env'
    button was, do not land on the section that moved up there. Prints one line per failure;
    returns their number."""
    import subprocess
    import time

    from imgui_bundle import imgui

    from alight.frontends.editor.state import EditorState
    from alight.frontends.editor.window import EditorWindow

    rects: dict[str, list] = {}
    # Where the widgets are, as imgui lays them out (an observer: each call is passed on as is).
    for name in ("small_button", "button", "collapsing_header", "slider_float"):
        def spy(label, *args, _f=getattr(imgui, name), **kwargs):
            result = _f(label, *args, **kwargs)
            lo, hi = imgui.get_item_rect_min(), imgui.get_item_rect_max()
            rects.setdefault(label, []).append((lo.x, lo.y, hi.x, hi.y))
            return result
        setattr(imgui, name, spy)
    state = EditorState()
    state.load_mesh("sphere")
    state.load_env("studio")
    win = EditorWindow(state, (1280, 720))
    for _ in range(3):
        win.frame()
    win.finish_bake()
    win.wait_for_thumbnails(120.0)
    window_id = subprocess.run(["xdotool", "search", "--onlyvisible", "--pid", str(os.getpid())], capture_output=True,
                               text=True, check=True).stdout.split()[0]

    def settle(n: int = 4) -> None:
        for _ in range(n):
            rects.clear()
            win.frame()

    def centre(label: str) -> tuple[str, str]:
        x0, y0, x1, y1 = min(rects[label], key=lambda r: r[1])
        return str(int(x0 + min(30.0, (x1 - x0) / 2))), str(int((y0 + y1) / 2))

    def headers() -> dict[str, float]:
        """Each section header's height in the last frame."""
        return {label: min(r[1] for r in rects[label]) for label in
                ("Material", "Environment", "Lights", "Display & camera", "Compare", "Performance", "Accuracy chart")}

    render = win.render_scene

    def slow_render():   # the scene set up as drawn on a loaded machine
        render()
        time.sleep(0.3)

    def xdo(*args: str) -> None:
        """xdotool while the window runs slow frames, then frames until every event is in."""
        time.sleep(1.0)   # past imgui's double-click time since the last click
        win.render_scene = slow_render
        proc = subprocess.Popen(["xdotool", *args])
        while proc.poll() is None:
            win.frame()
        for _ in range(4):
            win.frame()
        win.render_scene = render

    def move_click(label: str, *then: str) -> None:
        xdo("mousemove", "--window", window_id, *centre(label), "click", "1", *then)

    failures = 0
    settle()
    move_click("Material")    # closed: the sections below are in view
    settle()
    move_click("Lights")
    settle()
    n = len(state.lights)
    if "add point" not in rects or n < 2:
        print(f"setup: the Lights section did not open ({n} lights)")
        return 1
    move_click("remove", "sleep", "0.45", "click", "1")
    if len(state.lights) != n - 1:
        failures += 1
        print(f"remove: two clicks on light 0's 'remove' left {len(state.lights)} of {n} lights, not {n - 1}")
    xdo("mousemove", "--window", window_id, "200", "300")   # away: the list closes up
    settle()
    move_click("Lights")      # closed again
    settle()
    closed = headers()   # where the headers are with every section but Performance closed
    move_click("Environment")
    settle()
    if "open env" not in rects:
        print("setup: the Environment section did not open")
        return failures + 1
    ex, ey = centre("open env")
    hx, hy = centre("Environment")
    xdo("mousemove", "--window", window_id, hx, hy, "click", "1", "sleep", "0.1",
        "mousemove", "--window", window_id, ex, ey, "click", "1")
    settle()
    if headers() != closed:
        failures += 1
        toggled = [label for label, mark in (("Environment", "open env"), ("Lights", "add point"),
                                             ("Display & camera", "exposure (EV)"), ("Material", "metallic"))
                   if mark in rects]
        print(f"collapse: after closing Environment, a click aimed at its 'open env' toggled a section that "
              f"moved there (open now: {toggled or 'none'}; headers at {headers()} against {closed})")
    dropped = getattr(getattr(win, "press_guard", None), "dropped", 0)
    win.close()
    print(f"own loop: {failures} failures in the remove and collapse clicks ({dropped} presses dropped)")
    return failures


if __name__ == "__main__":
    sys.exit(1 if _own_loop_checks() else 0)


def _wait_for_mesh(ctx, s, spec: str) -> None:
    for _ in range(600):
        if s.mesh_spec and os.path.basename(str(s.mesh_spec)) == os.path.basename(spec):
            break
        ctx.yield_(1)
    ctx.yield_(2)


def test_a_mesh_without_its_material_says_it_is_drawn_with_the_panels_material(ctx):
    """singlevn.obj's .mtl is missing: the editor draws it with the panel's material (the view
    showed copper) while the status row said "drawn with the default material" (alight render's
    words, where no --preset means the default). The reader now says "the current material",
    true in every front end."""
    from alight.frontends.editor.ui_test import editor

    w = editor()
    s = w.state
    shared = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "..", "shared", "data")
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    path = os.path.abspath(os.path.join(shared, "bad", "singlevn.obj"))
    w.drop([path])   # (the scene: a dropped file, as the trial did)
    _wait_for_mesh(ctx, s, path)
    shown = w.panel.shown_status
    assert "surface.mtl" in shown and "drawn with the current material" in shown, shown
    assert "default material" not in shown, shown


def test_front_view_brings_back_a_one_sided_sheet_seen_from_behind(ctx):
    """A flat glTF sheet (single-sided: its back is culled) opened after an orbit behind the
    last mesh was invisible, and F framed it from the same direction. Opened now it is seen
    from in front; orbited behind it, the panel's 'front view' frames it from its face."""
    import trimesh

    from alight.frontends.editor.ui_test import editor

    w = editor()
    s = w.state
    sheet = os.path.join(OUT, "sheet.glb")
    trimesh.Trimesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]]).export(sheet)
    ctx.set_ref("alight")
    w.orbit.yaw_deg, w.orbit.pitch_deg = 160.0, 10.0   # (the scene: an orbit behind the last mesh)
    w.drop([sheet])
    _wait_for_mesh(ctx, s, sheet)
    assert float(w.orbit.direction() @ np.array([0.0, 0.0, 1.0])) > 0.5, (w.orbit.yaw_deg, w.orbit.pitch_deg)
    w.orbit.yaw_deg, w.orbit.pitch_deg = 200.0, -20.0   # orbited behind it again
    ctx.item_open("**/Environment")
    ctx.item_click("**/front view")
    ctx.yield_(2)
    assert abs(w.orbit.yaw_deg) < 1e-6 and abs(w.orbit.pitch_deg) < 1e-6, (w.orbit.yaw_deg, w.orbit.pitch_deg)
    assert float(w.orbit.direction()[2]) > 0.999


def test_collapsing_a_section_at_the_bottom_of_the_scrolled_panel_moves_nothing_above_it(ctx):
    """The panel scrolled to its end, a click closes Performance near the bottom: the content
    lost the section's height, imgui clamped the scroll and every control above (the clicked
    header too) moved down ~160 px under the pointer; the trial's next click, 2.5 s later,
    opened the wrong dropdown. The header and the sections above stay where they were."""
    ctx.set_ref("alight")
    for name in ("Environment", "Lights", "Display & camera", "Compare"):
        ctx.item_open(f"**/{name}")
    ctx.item_open("**/Performance")
    ctx.scroll_to_bottom("//alight")
    ctx.yield_(3)
    window = ctx.get_window_by_ref("//alight")
    assert window.scroll.y > 0, window.scroll.y
    before = {name: ctx.item_info(f"**/{name}").rect_full.min.y for name in ("Display & camera", "Performance")}
    ctx.item_click("**/Performance")
    ctx.yield_(4)
    after = {name: ctx.item_info(f"**/{name}").rect_full.min.y for name in ("Display & camera", "Performance")}
    assert all(abs(after[k] - before[k]) < 1.0 for k in before), (before, after)
    # Scrolled up, the space left at the end goes: the panel's end is its content again.
    ctx.scroll_to_top("//alight")
    ctx.yield_(3)
    from alight.frontends.editor.ui_test import editor

    assert editor().panel._slack == 0.0, editor().panel._slack
    ctx.item_open("**/Performance")
