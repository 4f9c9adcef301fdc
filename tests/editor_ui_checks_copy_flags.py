"""'copy camera as flags' with the editor's own lights and settings, operated through the panel by
the Dear ImGui Test Engine: run by tests/test_editor_ui_ground.py as ``alight edit --new --ground
--occlusion off --motion-scale 1 --ui-test tests/editor_ui_checks_copy_flags.py`` (the editor's
three default lights, the built-in sphere on the ground); not collected by pytest.

The environment turned and the exposure raised in the panel; the screenshot (the panel's button)
and the copied flags are left in the run's folder, for the runner to paste into ``alight render``
alone (no --light of its own) and compare."""

from __future__ import annotations

import json
import os
import sys

from alight.frontends.editor.ui_test import editor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_checks_ground import SETTLE_LIMIT_S, _settled  # noqa: E402
from editor_ui_helpers import OUT, screenshot, until_seconds  # noqa: E402


def test_the_copied_flags_carry_the_lights_and_the_views_settings(ctx):
    from imgui_bundle import imgui

    win = editor()
    s = win.state
    assert len(s.lights) == 3 and s.ground, (s.lights, s.ground)   # the editor's default lights
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.item_input_value("**/rotation", 40.0)
    ctx.item_close("**/Environment")
    ctx.item_open("**/Display & camera")
    ctx.item_input_value("**/exposure (EV)", 0.5)
    assert (s.env_rotation_deg, s.display.exposure) == (40.0, 0.5), (s.env_rotation_deg, s.display.exposure)
    until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)
    shot = screenshot(ctx)
    h, w = shot.shape[:2]
    ctx.item_click("**/copy camera as flags")
    flags = imgui.get_clipboard_text()
    assert flags.count("--light ") == 3 and "--ground" in flags, flags
    assert "--env-rotation 40" in flags and "--exposure 0.5" in flags and "--occlusion off" in flags, flags
    assert f"--size {w}x{h}" in flags and win.state.message == f"copied to the clipboard: {flags}", flags
    with open(os.path.join(OUT, "copy_flags_view.json"), "w") as f:
        json.dump({"size": [w, h], "flags": flags,
                   "file": sorted(n for n in os.listdir(".") if n.startswith("alight-screenshot-"))[-1]}, f)
