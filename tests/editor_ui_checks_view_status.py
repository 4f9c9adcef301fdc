"""The view and the status row (faults a fresh trial of the editor found), operated through the panel by the Dear
ImGui Test Engine: run by tests/test_editor_ui_view_status.py as ``alight edit --new --ui-test
tests/editor_ui_checks_view_status.py`` (a real window under Xvfb); not collected by pytest.

MSAA over a transparent background, the turntable's file written while frames go on, a mesh's
warning in the status row, the F0 line with maps, and (in the runner's second editor, reopened
on the session this run saved) the turntable's settings and the anti-aliasing restored."""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

from alight.frontends.editor.state import short_warning
from alight.frontends.editor.ui_test import editor, files_done

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_helpers import capture, checker_levels, type_path, until  # noqa: E402

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")   # where files written by the panel go
BAD = Path(__file__).resolve().parents[2] / "shared" / "data" / "bad"   # ../shared/data/bad
SPIN_FRAMES = 36
LAST_FRAMES, LAST_FILE = 5, "again.webp"   # what the last check leaves for the reopened editor
LAST_PRESET, LAST_GLTF = "kept_preset.json", "kept_export.glb"   # the path fields it leaves


def test_msaa_over_a_transparent_background_shows_the_checkerboard(ctx):
    """With anti-aliasing 'msaa' the window shows the checkerboard's two greys off the ball (it
    showed black: the resolve's tone map made the view opaque), as with 'none'."""
    win = editor()
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    ctx.item_open("**/Environment")
    ctx.combo_click("background/transparent")
    ctx.item_close("**/Environment")
    ctx.item_open("**/Display & camera")
    levels = {}
    for aa in ("none", "msaa"):   # (the editor offers these two)
        ctx.combo_click(f"anti-aliasing/{aa}")
        assert win.state.aa == aa
        ctx.mouse_click_on_void()
        ctx.yield_(3)
        shot = capture(ctx, f"checker_{aa}.png")[:, :, :3]
        levels[aa] = checker_levels(shot[:32, :32])
        w, h = win.view_area()
        middle = shot[h // 2 - 4:h // 2 + 4, w // 2 - 4:w // 2 + 4].astype(np.float64).mean(axis=(0, 1))
        assert middle[0] > middle[2] + 30, (aa, middle)   # the gold ball, opaque over the squares
    for aa, (light, dark) in levels.items():
        assert light > 0.3 and dark > 0.3, levels
    ctx.combo_click("anti-aliasing/none")
    ctx.item_close("**/Display & camera")
    ctx.item_open("**/Environment")
    ctx.combo_click("background/env")
    ctx.item_close("**/Environment")


def test_the_turntable_is_written_while_frames_go_on(ctx):
    """A 36-frame WebP: no frame of the window's takes over 1 s from the button's click to the
    file's arrival (its encoding took one frame of seconds), frames are drawn while it is written,
    the status row says so, and the file has 36 frames; no temporary file is left."""
    from PIL import Image

    win = editor()
    path = os.path.join(OUT, "spin36.webp")
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_open("**/Display & camera")
    ctx.item_input_value("**/turntable frames", SPIN_FRAMES)
    ctx.item_input_value("**/turntable file", path)
    ctx.item_click("**/turntable (T)")
    gaps, writing, statuses = [], 0, set()
    last = time.perf_counter()
    for _ in range(20000):
        ctx.yield_()
        now = time.perf_counter()
        gaps.append(now - last)
        last = now
        job = win.turntable_job
        if job is not None and job.done == SPIN_FRAMES:   # every frame drawn: the file being written
            writing += 1
            statuses.add(win.panel.shown_status)
        if job is None and os.path.isfile(path):
            break
    assert os.path.isfile(path), win.state.error
    print(f"turntable: {len(gaps)} frames, longest {max(gaps):.3f} s, {writing} while writing")
    assert writing >= 2, writing
    assert statuses == {"writing spin36.webp..."}, statuses
    assert max(gaps) < 1.0, sorted(gaps)[-5:]
    assert win.state.message.startswith(f"wrote {os.path.basename(path)} ({SPIN_FRAMES} frames"), \
        (win.state.message, win.state.error)
    with Image.open(path) as im:
        assert im.n_frames == SPIN_FRAMES, im.n_frames
    assert not [n for n in os.listdir(OUT) if ".tmp" in n], os.listdir(OUT)
    ctx.item_close("**/Display & camera")


def test_a_mesh_warning_is_in_the_status_row(ctx):
    """'open mesh' on an OBJ with a NaN vertex colour: the status row shows the warning's text
    (it said '(1 warning on stderr)'); one with two warnings shows both (the tooltip one a line)."""
    from alight.exchange.meshes import load_mesh

    win, s = editor(), editor().state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    for name in ("nancolor.obj", "notenoughindices.obj"):
        path = str(BAD / name)
        expected = [short_warning(w) for w in load_mesh(path).warnings]
        type_path(ctx, "**/mesh", path)
        ctx.item_click("**/open mesh")
        files_done(ctx)
        shown = getattr(win.panel, "shown_status", s.message)   # (a panel that kept none showed the message)
        assert f"opened mesh {path}" in shown, (shown, s.error)   # (after the compile note, if any)
        assert all(w in shown for w in expected) and "on stderr" not in shown, (shown, expected)
        assert "the default material" not in shown, shown
    ctx.combo_click("preview mesh/sphere")
    ctx.item_close("**/Environment")
    assert s.mesh_spec == "sphere", s.mesh_spec


def test_a_cut_status_line_is_shown_whole_when_hovered(ctx):
    """A bad file's error is longer than the panel's row and is cut at its edge; hovering the row
    shows it whole in a tooltip (a new user hovered it and saw nothing)."""
    from imgui_bundle import imgui

    win, s = editor(), editor().state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    path = str(BAD / "empty_nodes.glb")
    type_path(ctx, "**/mesh", path)
    ctx.item_click("**/open mesh")
    files_done(ctx)
    assert s.error and path in s.error, s.error
    panel = imgui.internal.find_window_by_name("alight")
    row = panel.menu_bar_rect()
    ctx.mouse_move_to_pos(imgui.ImVec2(row.min.x + 40.0, (row.min.y + row.max.y) / 2.0))
    ctx.yield_(3)
    tip = imgui.internal.find_window_by_name("##Tooltip_00")
    assert tip is not None and tip.active, "no tooltip over the status row"
    s.error = ""
    ctx.mouse_move("**/Lights")
    ctx.item_close("**/Environment")


def test_the_f0_line_says_it_is_the_factors_with_a_metallic_map(ctx):
    """With a metallic map the F0 line names the factors' F0 and the maps (it read 'F0 = 1.000
    1.000 1.000', which is not what is drawn); cleared, it is the F0 again."""
    import OpenImageIO as oiio

    win = editor()
    path = os.path.join(OUT, "half_metal.png")
    oiio.ImageBuf(np.full((8, 8, 3), 128, np.uint8)).write(path)
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.yield_(2)
    assert win.panel.shown_f0.startswith("F0 = "), win.panel.shown_f0
    ctx.item_click("texture maps/metallic/##armed")
    type_path(ctx, "**/map file", path)
    ctx.item_click("**/load##typed")
    ctx.yield_(2)
    assert win.state.texture_maps.metallic == path, win.state.error
    assert win.panel.shown_f0.startswith("F0 (factors) = ") and win.panel.shown_f0.endswith(" x maps"), \
        win.panel.shown_f0
    ctx.item_click("texture maps/metallic/clear")
    ctx.yield_(2)
    assert win.panel.shown_f0.startswith("F0 = "), win.panel.shown_f0


def test_the_preset_table_fits_a_narrow_panel(ctx):
    """The window made narrow, as the window manager does it (a new user's 700x500 drew the F0
    columns over each other, "0.02 0.02 0.0.15 0.15 0"): the table keeps the columns whose
    digits fit in their cells and drops the others; wide again, all three come back."""
    win = editor()
    glfw = win.glfw
    width, height = glfw.get_window_size(win.window)
    try:
        for size, columns in (((1280, 720), 3), ((700, 500), None), ((520, 400), 1)):
            glfw.set_window_size(win.window, *size)
            ctx.yield_(4)
            shown = (win.panel.preset_columns, round(win.panel.preset_overflow, 1))
            assert win.panel.preset_overflow <= 0.5, (size, shown)
            assert columns is None or win.panel.preset_columns == columns, (size, shown)
            print(f"PRESET_TABLE {size}: {shown[0]} columns, widest F0 text {shown[1]:+.1f} px past its cell")
    finally:
        glfw.set_window_size(win.window, width, height)
        ctx.yield_(4)


def test_leave_turntable_settings_and_msaa_for_the_next_session(ctx):
    """Set through the panel; the runner reopens the editor on the session saved at the end."""
    win = editor()
    ctx.set_ref("alight")
    ctx.item_open("**/Display & camera")
    ctx.item_input_value("**/turntable frames", LAST_FRAMES)
    ctx.item_input_value("**/turntable file", os.path.join(OUT, LAST_FILE))
    ctx.combo_click("anti-aliasing/msaa")
    ctx.item_close("**/Display & camera")
    assert (win.turntable.frames, win.state.aa) == (LAST_FRAMES, "msaa")
    # The path fields (a third trial found both back at their defaults after a reopen).
    ctx.item_input_value("**/preset file", os.path.join(OUT, LAST_PRESET))
    ctx.item_click("**/save preset")
    ctx.item_input_value("**/glTF file", os.path.join(OUT, LAST_GLTF))
    ctx.item_click("**/export glTF")
    files_done(ctx)
    until(ctx, lambda: os.path.isfile(os.path.join(OUT, LAST_PRESET)) and os.path.isfile(os.path.join(OUT, LAST_GLTF)))


def reopened_turntable_and_aa_are_restored(ctx):
    """Run in the editor reopened on that session: the turntable's fields and the anti-aliasing
    are the last session's, and the turntable button writes the restored file with the restored
    count."""
    from PIL import Image

    win = editor()
    path = os.path.join(OUT, LAST_FILE)
    assert (win.turntable.frames, win.turntable.path, win.state.aa) == (LAST_FRAMES, path, "msaa"), \
        (win.turntable, win.state.aa, win.state.error)
    ctx.set_ref("alight")
    ctx.item_open("**/Display & camera")
    ctx.item_click("**/turntable (T)")
    until(ctx, lambda: win.turntable_job is None and os.path.isfile(path))
    with Image.open(path) as im:
        assert im.n_frames == LAST_FRAMES, im.n_frames
    ctx.item_close("**/Display & camera")
    # The path fields are the last session's: their buttons write there without typing.
    for name, button in ((LAST_PRESET, "save preset"), (LAST_GLTF, "export glTF")):
        kept = os.path.join(OUT, name)
        os.remove(kept)
        ctx.item_click(f"**/{button}")
        until(ctx, lambda: os.path.isfile(kept))
        files_done(ctx)
        assert not win.state.error, win.state.error
