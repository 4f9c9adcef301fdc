"""The panel's widgets as artists use them (issue 22): Escape on the colour picker, the Lights
labels, the sliders' digits, turntables, lights turning with the environment. Run by
tests/test_editor_ui_widgets.py as ``alight edit --new --ui-test tests/editor_ui_checks_widgets.py``
(the Dear ImGui Test Engine against the real window under Xvfb); not collected by pytest.

Run as a script (``python tests/editor_ui_checks_widgets.py xdotool``, DISPLAY set), it drives
the editor's own glfw loop, which the engine cannot reach (the engine runs under hello_imgui's
runner and its C++ glfw backend), with real X events from xdotool: Ctrl+A in a text field, 20
times, and Escape on the colour picker.
"""

from __future__ import annotations

import math
import os
import sys
import time

import numpy as np


sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_helpers import screenshot, until  # noqa: E402
OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")   # where files written by the panel go


def _panel_pixels(ctx) -> np.ndarray:
    """The last frame's imgui drawing (the panel) over black, as the window shows it: uint8
    (h, w, 3), top row first. Drawn again from imgui's draw data into a framebuffer of ours on
    the main thread (the window's own back buffer is gone after the swap)."""
    from alight.frontends.editor.ui_test import editor, on_main_thread

    def draw():
        from imgui_bundle import imgui

        win = editor()
        w, h = win.size
        fbo = win.ctx.simple_framebuffer((w, h), components=4)
        try:
            fbo.use()
            fbo.clear(0.0, 0.0, 0.0, 1.0)
            imgui.backends.opengl3_render_draw_data(imgui.get_draw_data())
            pixels = np.frombuffer(fbo.read(components=3), np.uint8).reshape(h, w, 3)[::-1].copy()
        finally:
            win.ctx.screen.use()
            fbo.release()
        return pixels

    return on_main_thread(ctx, draw)


def _luminance(rgb: np.ndarray) -> np.ndarray:
    """WCAG relative luminance of sRGB uint8 pixels."""
    c = rgb.astype(np.float64) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return lin @ np.array([0.2126, 0.7152, 0.0722])


# --- Escape, labels, sliders -----------------------------------------------------------------------

def test_escape_closes_the_colour_picker(ctx):
    from imgui_bundle import imgui

    every = imgui.PopupFlags_.any_popup_id | imgui.PopupFlags_.any_popup_level
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_click("base colour (sRGB)/##ColorButton")
    ctx.yield_(2)
    assert imgui.is_popup_open("", every), "the swatch's click opened no picker"
    ctx.key_press(imgui.Key.escape)
    ctx.yield_(2)
    assert not imgui.is_popup_open("", every), "Escape left the colour picker open"


def test_light_labels_end_inside_the_panel(ctx):
    """Every row label of the Lights section (the longest: a directional light's 'direction
    (light travels)', a spot's 'direction (spot points)') ends left of the panel's edge."""
    from imgui_bundle import imgui

    from alight.frontends.editor.ui_test import editor

    s = editor().state
    ctx.set_ref("alight")
    ctx.item_open("**/Lights")
    ctx.item_click("**/add spot")
    ctx.item_click("**/add directional")
    ctx.yield_(2)
    edge = imgui.internal.find_window_by_name("alight").inner_clip_rect.max.x
    spacing = imgui.get_style().item_inner_spacing.x
    checked = 0
    for i, light in enumerate(s.lights):
        # The last part of each row (its label follows it), or the row itself (its rect has the label).
        rows = {"position" if light.kind != "directional" else "direction (light travels)": "/$$2",
                "colour": "/##ColorButton", "intensity": ""}
        if light.kind == "spot":
            rows["direction (spot points)"] = "/$$2"
        for label, last in rows.items():
            right = ctx.item_info(f"$${i}/{label}{last}").rect_full.max.x
            if last:
                right += spacing + imgui.calc_text_size(label).x
            assert right <= edge, f"light {i}'s label '{label}' ends at x={right:.0f}, past the panel's edge {edge:.0f}"
            checked += 1
    assert checked >= 14, checked
    n = len(s.lights)
    ctx.item_click(f"$${n - 1}/remove")
    ctx.item_click(f"$${n - 2}/remove")
    ctx.item_close("**/Lights")


def test_slider_values_read_beside_their_handle(ctx):
    """At 0.5 the roughness slider's handle sits under the middle digit: it is at most 6 px wide
    and the digits on it keep a 4.5:1 contrast (WCAG AA) against it."""
    from imgui_bundle import imgui

    from alight.frontends.editor.ui_test import editor

    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_input_value("**/roughness", 0.5)
    ctx.mouse_click_on_void()
    ctx.yield_(3)
    assert editor().state.material.roughness == 0.5
    r = ctx.item_info("**/roughness").rect_full
    pixels = _panel_pixels(ctx)
    from PIL import Image

    Image.fromarray(pixels).save(os.path.join(OUT, "panel_sliders.png"))   # to look at
    # The frame only (the label right of it is outside): the slider is the item's left part.
    frame_w = r.max.x - r.min.x - imgui.get_style().item_inner_spacing.x - imgui.calc_text_size("roughness").x
    box = pixels[int(r.min.y):int(r.max.y), int(r.min.x) + 2:int(r.min.x + frame_w) - 2].astype(np.int32)
    # The handle: the columns that differ from the frame's colour in the rows above the digits
    # (the handle spans the frame's height; the digits its middle). Any theme's colours.
    top = box[2:5]
    background = np.median(top.reshape(-1, 3), axis=0)
    cols = np.flatnonzero((np.abs(top - background).max(axis=2) > 8).any(axis=0))
    assert cols.size, f"no handle found in the roughness slider at {r.min.x:.0f},{r.min.y:.0f}"
    width = cols.max() - cols.min() + 1
    assert width <= 6, f"the handle is {width} px wide over the digits"
    handle = _luminance(top[:, cols].reshape(-1, 3)).mean()
    on_handle = box[:, cols.min():cols.max() + 1].reshape(-1, 3)
    text = _luminance(on_handle).max()   # the digits' pixels where they cross the handle
    assert text > handle, "no digit drawn across the handle"
    contrast = (text + 0.05) / (handle + 0.05)
    assert contrast >= 4.5, f"digits on the handle: contrast {contrast:.1f}:1"


# --- lights turning with the environment -----------------------------------------------------------

def _azimuths(lights) -> list[float]:
    """Each light's angle about +Y (of its direction or position), degrees, right-handed: +X at 0,
    -Z at +90 (the environment's rotation turns +X toward -Z)."""
    return [math.degrees(math.atan2(-light.vector[2], light.vector[0])) for light in lights]


def _turned(after: float, before: float) -> float:
    d = (after - before) % 360.0
    return d - 360.0 if d > 180.0 else d


def _shift_right_drag(ctx, dx: float) -> None:
    from imgui_bundle import imgui

    ctx.mouse_click_on_void()
    w, h = imgui.get_io().display_size.x, imgui.get_io().display_size.y
    ctx.mouse_move_to_pos(imgui.ImVec2(w * 0.2, h * 0.5))
    ctx.key_down(imgui.Key.left_shift)
    ctx.mouse_drag_with_delta(imgui.ImVec2(dx, 0), imgui.MouseButton_.right)
    ctx.key_up(imgui.Key.left_shift)
    ctx.yield_(2)


def test_lights_turn_with_the_environment_when_the_box_is_on(ctx):
    from alight.frontends.editor.ui_test import editor, view

    s = editor().state
    ctx.set_ref("alight")
    # Off (the default): the drag turns the environment only.
    lights, rotation = list(s.lights), s.env_rotation_deg
    _shift_right_drag(ctx, 60)
    assert s.env_rotation_deg != rotation
    assert s.lights == lights, "the lights turned with the box off"
    # On: the drag turns every light by the environment's angle, about the vertical axis.
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.item_check("**/lights turn with the environment")
    assert s.lights_follow_env
    before, rotation, heights = _azimuths(s.lights), s.env_rotation_deg, [lt.vector[1] for lt in s.lights]
    shot = view(ctx).astype(np.float64)
    _shift_right_drag(ctx, 80)
    turned = _turned(s.env_rotation_deg, rotation)
    assert abs(turned) > 5.0, turned
    for a, b in zip(_azimuths(s.lights), before):
        assert abs(_turned(a, b) - turned) < 1e-3, (a, b, turned)
    assert [lt.vector[1] for lt in s.lights] == heights
    assert np.abs(view(ctx).astype(np.float64) - shot).mean() > 0.5   # the picture changed
    # The slider too.
    before, rotation = _azimuths(s.lights), s.env_rotation_deg
    ctx.set_ref("alight")
    ctx.item_input_value("**/rotation", 30.0)
    turned = _turned(30.0, rotation)
    for a, b in zip(_azimuths(s.lights), before):
        assert abs(_turned(a, b) - turned) < 1e-3, (a, b, turned)
    # Off again: the slider leaves them.
    ctx.item_uncheck("**/lights turn with the environment")
    lights = list(s.lights)
    ctx.item_input_value("**/rotation", -20.0)
    assert s.lights == lights
    ctx.item_check("**/lights turn with the environment")   # left on: the runner reads the session
    ctx.item_close("**/Environment")


# --- turntables ------------------------------------------------------------------------------------

def test_turntable_button_writes_an_animated_webp(ctx):
    """The button writes N frames at the view's size; frame 0 is the screenshot of the view;
    the frames differ (the camera orbits); the panel says where."""
    from PIL import Image

    from alight.frontends.editor.ui_test import editor

    win = editor()
    path = os.path.join(OUT, "spin.webp")
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_open("**/Display & camera")
    ctx.item_input_value("**/turntable frames", 6)
    ctx.item_input_value("**/turntable file", path)
    still = screenshot(ctx)
    ctx.item_click("**/turntable (T)")
    until(ctx, lambda: win.turntable_job is None and os.path.isfile(path))
    assert win.state.message.startswith(f"wrote {os.path.basename(path)} (6 frames"), (win.state.message, win.state.error)
    with Image.open(path) as im:
        assert im.n_frames == 6, im.n_frames
        frames = []
        for i in range(im.n_frames):
            im.seek(i)
            frames.append(np.asarray(im.convert("RGB")))
    w, h = win.view_area()
    assert frames[0].shape == (h, w, 3) == still.shape, (frames[0].shape, still.shape)
    assert np.abs(frames[0].astype(np.int32) - still).max() <= 1
    for a, b in zip(frames, frames[1:]):
        assert np.abs(a.astype(np.float64) - b).mean() > 0.5
    assert not [n for n in os.listdir(OUT) if ".tmp" in n], os.listdir(OUT)
    ctx.item_close("**/Display & camera")


def test_turntable_key_writes_numbered_pngs(ctx):
    import OpenImageIO as oiio
    from imgui_bundle import imgui

    from alight.frontends.editor.ui_test import editor

    win = editor()
    ctx.set_ref("alight")
    ctx.item_open("**/Display & camera")
    ctx.item_input_value("**/turntable frames", 4)
    ctx.item_input_value("**/turntable file", os.path.join(OUT, "spin.png"))
    ctx.item_close("**/Display & camera")
    ctx.mouse_click_on_void()
    ctx.key_press(imgui.Key.t)
    ctx.yield_(2)
    until(ctx, lambda: win.turntable_job is None)
    names = sorted(n for n in os.listdir(OUT) if n.startswith("spin_"))
    assert names == [f"spin_{i:03d}.png" for i in range(4)], (names, win.state.error)
    frames = [oiio.ImageBuf(os.path.join(OUT, n)).get_pixels(oiio.UINT8).astype(np.float64) for n in names]
    w, h = win.view_area()
    assert frames[0].shape == (h, w, 3)
    assert all(np.abs(a - b).mean() > 0.5 for a, b in zip(frames, frames[1:]))
    assert not [n for n in os.listdir(OUT) if ".tmp" in n], os.listdir(OUT)


# --- real X events in the editor's own loop (run as a script) --------------------------------------

def _own_loop_checks(tries: int = 20) -> int:
    """Ctrl+A in the 'library name' field, ``tries`` times, and Escape on the colour picker,
    with xdotool's key and mouse events, in `alight edit`'s own window. Prints one line per
    failure; returns the number of failures."""
    import subprocess

    from imgui_bundle import imgui

    from alight.frontends.editor.state import EditorState
    from alight.frontends.editor.window import EditorWindow

    rects = {}
    # Where the widgets are, read as imgui lays them out (an observer: the call is passed on as is).
    for name in ("input_text", "color_edit3", "slider_float"):
        def spy(label, *args, _f=getattr(imgui, name), **kwargs):
            result = _f(label, *args, **kwargs)
            rects[label] = (imgui.get_item_rect_min().x, imgui.get_item_rect_min().y,
                            imgui.get_item_rect_max().x, imgui.get_item_rect_max().y)
            return result
        setattr(imgui, name, spy)
    state = EditorState()
    state.load_mesh("sphere")
    state.load_env("studio")
    win = EditorWindow(state, (1280, 1000))   # (tall: the base colour row in view below the F0 table and the library box)
    for _ in range(3):
        win.frame()
    win.finish_bake()
    for _ in range(10):   # the layout settled (the bake's progress row, the thumbnails)
        win.frame()

    def xdo(*args):
        """An xdotool command while the editor runs its frames; then frames until imgui has
        taken every queued event (it takes a slow frame's keys over several frames)."""
        proc = subprocess.Popen(["xdotool", *args])
        while proc.poll() is None:
            win.frame()
        n = 0
        while n < 3 or imgui.get_current_context().input_events_queue.size() \
                or getattr(win, "key_events", None) and win.key_events.pending:
            win.frame()
            n += 1

    def field_pixels(rect):
        win.draw()   # the frame drawn, read before the swap
        w, h = win.size
        pixels = np.frombuffer(win.ctx.screen.read(components=3), np.uint8).reshape(h, w, 3)[::-1]
        win.glfw.swap_buffers(win.window)
        win.after_swap()
        return pixels[int(rect[1]):int(rect[3]), int(rect[0]):int(rect[2])].astype(np.int32)

    # The window by this process's id, mapped (glfw has an unmapped helper window too).
    window_id = subprocess.run(["xdotool", "search", "--onlyvisible", "--pid", str(os.getpid())], capture_output=True,
                               text=True, check=True).stdout.split()[0]

    last_click = [0.0]

    def click_at(x, y):
        """The pointer to the window's (x, y), then a left click: a single one. (A click within
        imgui's double-click time of the last, at the same place, selects a word, and the
        highlight is there before Ctrl+A: on a quiet machine the tries came that fast.)"""
        import time

        while time.monotonic() - last_click[0] < 1.5 * imgui.get_io().mouse_double_click_time:
            win.frame()
        xdo("mousemove", "--window", window_id, str(int(x)), str(int(y)), "click", "1")
        last_click[0] = time.monotonic()

    failures = 0
    panel = win.panel.library
    for i in range(tries):
        panel.name = "some_long_name"
        win.frame()
        x0, y0, x1, y1 = rects["library name"]   # as laid out now (the library's rows come and go)
        click_at(x0 + 40, (y0 + y1) / 2)
        before = field_pixels(rects["library name"])
        xdo("key", "ctrl+a")
        after = field_pixels(rects["library name"])
        # The selection's highlight: imgui's TextSelectedBg (blue) behind the text.
        highlighted = ((after[..., 2] - after[..., 0]) > 40).sum() - ((before[..., 2] - before[..., 0]) > 40).sum()
        xdo("type", "material")
        xdo("key", "Return")
        if panel.name != "material":
            failures += 1
            print(f"ctrl+a try {i}: the field reads '{panel.name}', not 'material'")
        elif highlighted < 100:
            failures += 1
            print(f"ctrl+a try {i}: no selection drawn ({highlighted} highlighted pixels)")
    # Escape on the colour picker.
    every = imgui.PopupFlags_.any_popup_id | imgui.PopupFlags_.any_popup_level
    cx0, cy0, cx1, cy1 = rects["base colour (sRGB)"]
    swatch_x = cx1 - imgui.calc_text_size("base colour (sRGB)").x - 4 - (cy1 - cy0) / 2
    click_at(swatch_x, (cy0 + cy1) / 2)
    opened = imgui.is_popup_open("", every)
    xdo("key", "Escape")
    if not opened:
        failures += 1
        print("escape: a click on the swatch opened no picker")
    elif imgui.is_popup_open("", every):
        failures += 1
        print("escape: the colour picker is still open")
    # A fast Ctrl+click on the roughness slider (Ctrl down, click, Ctrl up in one xdotool call):
    # the slider opens for typing and keeps its value; a plain click would set it where it landed.
    import dataclasses

    for i in range(6):
        state.material = dataclasses.replace(state.material, roughness=0.3)   # (the scene set up)
        win.frame()
        rx0, ry0, rx1, ry1 = rects["roughness"]
        while time.monotonic() - last_click[0] < 1.5 * imgui.get_io().mouse_double_click_time:
            win.frame()
        xdo("mousemove", "--window", window_id, str(int(rx0 + 0.85 * (rx1 - rx0))), str(int((ry0 + ry1) / 2)),
            "keydown", "ctrl", "click", "1", "keyup", "ctrl")
        last_click[0] = time.monotonic()
        if abs(state.material.roughness - 0.3) > 1e-6:
            failures += 1
            print(f"ctrl+click try {i}: the slider took the click (roughness {state.material.roughness:.3f})")
        xdo("key", "Escape")
    win.close()
    print(f"own loop: {failures} failures in {tries} Ctrl+A tries, 1 Escape and 6 Ctrl+clicks")
    return failures


if __name__ == "__main__":
    sys.exit(1 if _own_loop_checks(int(sys.argv[2]) if len(sys.argv) > 2 else 20) else 0)
