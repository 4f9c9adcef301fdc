"""The editor's ground and shadows, operated through the panel by the Dear ImGui Test Engine: run
by tests/test_editor_ui_ground.py as ``alight edit --new --light ... --occlusion off
--motion-scale 1 --ui-test tests/editor_ui_checks_ground.py`` (a real window under Xvfb, the
built-in sphere); not collected by pytest.

The 'ground' checkbox: the sphere's shadow appears on the ground below it while frames go on
(its programs are new variants, compiled by the warm-up process); the moving view (drawn anew
each frame while the camera orbits) shows it as the still view does. The 'shadows' combo set
to off takes it away (the ground catches nothing), on brings it back. The last check takes a
screenshot (the panel's button, as F12) and leaves it with its camera in the run's folder, for
the runner to compare with ``alight render --ground`` and with the reopened session."""

from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

from alight.frontends.editor.ui_test import editor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_helpers import OUT, capture, screenshot, until_seconds  # noqa: E402

SETTLE_LIMIT_S = 300.0   # a hang guard only: the warm-up's first compile of the ground's programs
SHADOW_STEP = 3.0        # an 8-bit step that counts as the shadow's darkening


def _settled(win) -> bool:
    """Nothing pending that changes the view: the IBL bake, a shader variant, the occlusion bake."""
    return (win.bake_progress is None and not win.variant_warmup.pending and not win.variant_warmup.showing_old
            and not win.occlusion_bake.status)


def _shown_view(ctx, win, name: str) -> np.ndarray:
    """The view as the window shows it (the area left of the panel): float64 (h, w, 3) sRGB. The
    mouse is moved off the control it clicked first (its tooltip would lie over the view)."""
    ctx.mouse_move("**/Lights")
    ctx.yield_(3)
    w, h = win.view_area()
    return capture(ctx, name)[:h, :w, :3].astype(np.float64)


def _shadow(view: np.ndarray, without: np.ndarray) -> np.ndarray:
    """Where ``view`` is darker than the view ``without`` the ground: (h, w) bool."""
    return view.mean(axis=2) - without.mean(axis=2) < -SHADOW_STEP


def _below_the_centre(mask: np.ndarray) -> float:
    """The share of ``mask``'s pixels in the view's lower half (the sphere is framed at its middle)."""
    ys = np.nonzero(mask)[0]
    return float((ys > mask.shape[0] / 2).mean()) if len(ys) else 0.0


CAMERA = {}   # the first check's camera and ground-less view, for the checks after it


def test_the_ground_checkbox_puts_the_shadow_under_the_model(ctx):
    win = editor()
    assert not win.state.ground and win.state.shadows == "auto"   # 'alight render''s defaults
    until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    off = _shown_view(ctx, win, "ground_off.png")
    assert not win.renderer.shadow_maps.last_active   # the sphere alone: auto draws no shadow
    jobs = win.variant_warmup.jobs
    ctx.item_check("**/ground")
    assert win.state.ground and win.state.scene(win.orbit.camera()).ground
    gaps = []
    last = start = time.perf_counter()
    while not _settled(win):
        assert time.perf_counter() - start < SETTLE_LIMIT_S, "the ground's programs never came"
        ctx.yield_()
        now = time.perf_counter()
        gaps.append(now - last)
        last = now
    gaps = gaps or [0.0]
    print(f"GROUND_SWITCH seconds={time.perf_counter() - start:.2f} warmup_jobs={win.variant_warmup.jobs - jobs} "
          f"frames={len(gaps)} max_gap={max(gaps):.3f} slowest={sorted(gaps)[-5:]}")
    # The ground's programs are new variants: held back by the gate and compiled by the warm-up
    # process (its keys come back from the child), the view kept responding meanwhile: frames
    # came while it compiled (a compile in the frame would be one frame as long as the wait).
    # No absolute time: on shared cores any frame may take a neighbour's second.
    assert win.variant_warmup.jobs > jobs
    assert any("render/ground.frag" in key for key in win.variant_warmup.drawn_by_child), \
        sorted(map(str, win.variant_warmup.drawn_by_child))[:5]
    assert len(gaps) >= 3, sorted(gaps)[-5:]
    on = _shown_view(ctx, win, "ground_on.png")
    assert win.renderer.shadow_maps.last_active   # with a ground, auto draws the shadow it catches
    shadow = _shadow(on, off)
    lighter = (on.mean(axis=2) - off.mean(axis=2) > 1.0).sum()
    print(f"GROUND_PIXELS shadow={shadow.sum()} below={_below_the_centre(shadow):.3f} lighter={lighter}")
    # Pixels below the sphere went from the background to the ground's shadow; nothing lightened
    # (the ground is a shadow catcher: elsewhere it shows the background).
    assert shadow.sum() > 300 and _below_the_centre(shadow) > 0.9, (shadow.sum(), _below_the_centre(shadow))
    assert lighter == 0, lighter
    o = win.orbit
    CAMERA.update(yaw=o.yaw_deg, pitch=o.pitch_deg, off=off, on=on)


def test_the_moving_view_shows_the_ground(ctx):
    """While the camera orbits, each frame is drawn at the view's full size (--motion-scale 1): the
    frames read back as drawn show the ground's shadow, and the last of them equals the still
    view the next frames draw of the same camera."""
    win = editor()
    moving_frames = []
    original = win.render_view

    def render_view(*args, **kwargs):
        targets = original(*args, **kwargs)
        if win._was_moving and not kwargs.get("full"):
            w, h = win.view_area()
            data = win.ctx.screen.read(viewport=(0, 0, w, h), components=3, dtype="f1")
            moving_frames.append(np.frombuffer(data, np.uint8).reshape(h, w, 3)[::-1].astype(np.float64))
        return targets

    win.render_view = render_view
    try:
        for _ in range(12):   # a side door turns the camera a little each frame, as a drag does
            win.orbit.yaw_deg += 2.0
            ctx.yield_()
        ctx.yield_()
    finally:
        del win.render_view
    assert len(moving_frames) >= 10, len(moving_frames)
    until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)
    still = _shown_view(ctx, win, "ground_still_turned.png")
    moving = moving_frames[-1]
    diff = np.abs(moving - still)
    print(f"GROUND_MOVING frames={len(moving_frames)} vs_still max={diff.max():.0f} mean={diff.mean():.4f}")
    assert diff.max() <= 1.0, (diff.max(), diff.mean())
    # The turned view has its shadow too: against the ground-less view at this camera.
    win.state.ground = False
    until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)
    bare = _shown_view(ctx, win, "ground_off_turned.png")
    win.state.ground = True
    shadow = _shadow(moving, bare)
    print(f"GROUND_MOVING_SHADOW pixels={shadow.sum()} below={_below_the_centre(shadow):.3f}")
    assert shadow.sum() > 300 and _below_the_centre(shadow) > 0.9
    win.orbit.yaw_deg, win.orbit.pitch_deg = CAMERA["yaw"], CAMERA["pitch"]
    until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)


def test_shadows_off_takes_the_shadow_away_and_on_brings_it_back(ctx):
    win = editor()
    ctx.set_ref("alight")
    ctx.combo_click("shadows/off")
    assert win.state.shadows == "off" and win.state.ground
    until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)
    off = _shown_view(ctx, win, "ground_shadows_off.png")
    assert not win.renderer.shadow_maps.last_active
    # The ground catches nothing without shadows: the shadow the ground showed is gone (against
    # the ground with shadows, both drawn the same way) and the picture is the one without a
    # ground but for a few pixels on the sphere's outline (a ground's view is drawn through the
    # HDR path, without the one-pass view's impostor ring).
    gone = _shadow(CAMERA["on"], off)
    diff = np.abs(off - CAMERA["off"]).max(axis=2)
    left = _shadow(off, CAMERA["off"])
    print(f"GROUND_SHADOWS_OFF gone={gone.sum()} below={_below_the_centre(gone):.3f} still_dark={left.sum()} "
          f"over1={(diff > 1).mean():.5f}")
    assert gone.sum() > 300 and _below_the_centre(gone) > 0.9, (gone.sum(), _below_the_centre(gone))
    assert left.sum() < 0.05 * gone.sum() and (diff > 1).mean() < 0.01, (left.sum(), (diff > 1).mean())
    ctx.combo_click("shadows/on")
    until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)
    on = _shown_view(ctx, win, "ground_shadows_on.png")
    assert np.abs(on - CAMERA["on"]).max() <= 1.0, np.abs(on - CAMERA["on"]).max()   # (the sphere: as auto)
    ctx.combo_click("shadows/auto")
    assert win.state.shadows == "auto"


def test_a_ground_that_catches_nothing_says_so_in_the_status_row_once(ctx):
    """The ground with 'shadows' off catches nothing: the status row says so (the renderer's
    warning went to stderr alone, in the command line's words), once: another message replaces
    it and it does not come back while nothing changes; ticking the ground again says it again,
    and a ground that catches the shadow again takes the line away."""
    from imgui_bundle import imgui

    from alight.frontends.editor.window import GROUND_IDLE

    win = editor()
    s, panel = win.state, win.panel
    said = GROUND_IDLE["shadows off"]
    ctx.set_ref("alight")
    assert s.ground and s.shadows == "auto"
    ctx.combo_click("shadows/off")
    until_seconds(ctx, lambda: _settled(win) and panel.shown_status.startswith(said), SETTLE_LIMIT_S)
    assert "'shadows' is off (Environment)" in said and "--" not in said   # the panel's names, not the flags
    ctx.mouse_click_on_void()
    ctx.key_press(imgui.Key.mod_ctrl | imgui.Key.z)   # (--new: nothing to undo; the scene stays)
    ctx.yield_(2)
    assert panel.shown_status.startswith("nothing to undo"), panel.shown_status
    ctx.yield_(20)
    assert panel.shown_status.startswith("nothing to undo"), panel.shown_status   # not said again each frame
    ctx.set_ref("alight")
    ctx.item_uncheck("**/ground")
    until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)
    assert not panel.shown_status.startswith(said), panel.shown_status
    ctx.item_check("**/ground")
    until_seconds(ctx, lambda: _settled(win) and panel.shown_status.startswith(said), SETTLE_LIMIT_S)
    ctx.combo_click("shadows/auto")
    until_seconds(ctx, lambda: _settled(win) and win.renderer.shadow_maps.last_active, SETTLE_LIMIT_S)
    ctx.yield_(2)
    assert not panel.shown_status.startswith("ground:"), panel.shown_status


def test_the_screenshot_with_the_ground_is_left_for_alight_render(ctx):
    """The panel's screenshot button (F12): the view at its size, with the ground's
    shadow; it and its camera are left for the runner's ``alight render --ground``."""
    win = editor()
    until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)
    ctx.set_ref("alight")
    ctx.item_open("**/Display & camera")   # (the screenshot's button)
    shot = screenshot(ctx)
    h, w = shot.shape[:2]
    assert (w, h) == tuple(win.view_area()), ((w, h), win.view_area())   # ('at the view's size', the default)
    # The camera as a user takes it to the command line: the panel's button, then the clipboard.
    from imgui_bundle import imgui

    ctx.item_click("**/copy camera as flags")
    flags = imgui.get_clipboard_text()
    assert flags.startswith("--orbit ") and f"--size {w}x{h}" in flags, flags
    assert win.state.message == f"copied to the clipboard: {flags}", win.state.message
    with open(os.path.join(OUT, "ground_view.json"), "w") as f:
        json.dump({"size": [w, h], "flags": flags,
                   "file": sorted(n for n in os.listdir(".") if n.startswith("alight-screenshot-"))[-1]}, f)
    assert shot[:, :, :3].astype(np.float64).std() > 5.0
