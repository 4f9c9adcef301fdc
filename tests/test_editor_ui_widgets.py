"""The panel's widgets through their real UI (issue 22): `alight edit --ui-test` runs
tests/editor_ui_checks_widgets.py with the Dear ImGui Test Engine under Xvfb, and the same file
run as a script drives the editor's own loop with xdotool's real X key events (Ctrl+A, Escape)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_widgets.py"


def test_widget_checks_pass_through_the_test_engine(display, tmp_path):
    result = ui_test(tmp_path, CHECKS, "--new", size="1280x720")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout
    # The box 'lights turn with the environment' is kept in the session, as after a normal close.
    session = json.loads((tmp_path / "config" / "editor-session.json").read_text())
    assert session["settings"]["lights_follow_env"] is True, session["settings"]


def test_ctrl_a_and_escape_with_real_x_key_events(display, tmp_path):
    """xdotool's key events in `alight edit`'s own window (the engine cannot reach its glfw loop):
    Ctrl+A selects the whole field and shows the selection, 20 tries of 20; Escape closes the
    colour picker."""
    if shutil.which("xdotool") is None:
        pytest.skip("xdotool is not installed (tools/setup.sh installs it)")
    env = dict(os.environ, ALIGHT_CONFIG_DIR=str(tmp_path / "config"), ALIGHT_CACHE_DIR=str(tmp_path / "cache"),
               ALIGHT_DATA_DIR=str(tmp_path / "data"))
    result = subprocess.run([sys.executable, str(CHECKS), "xdotool", "20"], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "own loop: 0 failures in 20 Ctrl+A tries, 1 Escape and 6 Ctrl+clicks" in result.stdout, result.stdout


def test_a_ctrl_click_in_one_poll_keeps_its_order_and_its_modifier():
    """keys.KeyEvents takes the mouse's events too: Ctrl down, a press, a release and Ctrl up
    in one poll reach imgui with Ctrl before the press (with only keys queued, the press went
    first: a plain click, which set the slider), and the Ctrl up waits for the next frame;
    motions and the wheel keep their place."""
    import glfw

    from alight.frontends.editor.keys import KeyEvents

    q = KeyEvents()
    q.cursor(10.0, 20.0)
    q.key(glfw.KEY_LEFT_CONTROL, 0, glfw.PRESS, 0)
    q.button(glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, glfw.MOD_CONTROL)
    q.button(glfw.MOUSE_BUTTON_LEFT, glfw.RELEASE, glfw.MOD_CONTROL)
    q.key(glfw.KEY_LEFT_CONTROL, 0, glfw.RELEASE, 0)
    q.scroll(0.0, 1.0)
    first, second = q.take_frame(), q.take_frame()
    assert [e[0] for e in first] == ["cursor", "key", "button", "button"], first
    assert first[1][1] == glfw.KEY_LEFT_CONTROL and first[2][2] == glfw.PRESS
    assert [e[0] for e in second] == ["key", "scroll"] and second[0][3] == glfw.RELEASE, second
    assert q.take_frame() == []


def test_a_chord_released_in_one_poll_keeps_its_modifier():
    """keys.KeyEvents: Ctrl down, A down, Ctrl up, A up arriving in one poll (a slow frame) reach
    imgui as two frames, A pressed with Ctrl held; characters keep their place."""
    import glfw

    from alight.frontends.editor.keys import KeyEvents

    q = KeyEvents()
    for key, action in ((glfw.KEY_LEFT_CONTROL, glfw.PRESS), (glfw.KEY_A, glfw.PRESS),
                        (glfw.KEY_LEFT_CONTROL, glfw.RELEASE), (glfw.KEY_A, glfw.RELEASE)):
        q.key(key, 0, action, 0)
    q.char(ord("m"))
    first, second = q.take_frame(), q.take_frame()
    assert [e[1:4:2] for e in first] == [(glfw.KEY_LEFT_CONTROL, glfw.PRESS), (glfw.KEY_A, glfw.PRESS)]
    assert [e[1:4:2] for e in second[:2]] == [(glfw.KEY_LEFT_CONTROL, glfw.RELEASE), (glfw.KEY_A, glfw.RELEASE)]
    assert second[2] == ("char", ord("m")) and q.take_frame() == []
    # Typing without a modifier is not held back: a frame takes it all.
    for c in "ab":
        q.key(glfw.KEY_A + ord(c) - ord("a"), 0, glfw.PRESS, 0)
        q.char(ord(c))
        q.key(glfw.KEY_A + ord(c) - ord("a"), 0, glfw.RELEASE, 0)
    assert len(q.take_frame()) == 6


def test_lights_turn_as_the_environment_does():
    """env_turn: the environment's rotation is right-handed about +Y (+90 carries +X to -Z,
    docs/conventions.md); a light turned by the same angle follows a feature of the map."""
    import numpy as np

    from alight.core.scene import Light
    from alight.frontends.editor.env_turn import rotate_y, turn_lights, wrapped_delta

    np.testing.assert_allclose(rotate_y((1.0, 0.0, 0.0), 90.0), (0.0, 0.0, -1.0), atol=1e-12)
    np.testing.assert_allclose(rotate_y((0.0, 2.0, 0.0), 37.0), (0.0, 2.0, 0.0), atol=1e-12)
    spot = Light("spot", (0.0, 3.0, 3.0), direction=(0.0, -0.7071, -0.7071))
    turned = turn_lights([spot], 180.0)[0]
    np.testing.assert_allclose(turned.vector, (0.0, 3.0, -3.0), atol=1e-12)
    np.testing.assert_allclose(turned.direction, (0.0, -0.7071, 0.7071), atol=1e-12)
    assert turned.inner_cone_deg == spot.inner_cone_deg and spot.vector == (0.0, 3.0, 3.0)
    assert wrapped_delta(179.0, -179.0) == 2.0 and wrapped_delta(-179.0, 179.0) == -2.0
