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
    assert "own loop: 0 failures in 20 Ctrl+A tries and 1 Escape" in result.stdout, result.stdout
