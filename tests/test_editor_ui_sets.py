"""Texture sets one after another, the fields that name them, undo's status row and a saved
preset's name, through the real UI: `alight edit --ui-test` runs tests/editor_ui_checks_sets.py
with the Dear ImGui Test Engine under Xvfb (what a fresh artist trial found)."""

from __future__ import annotations

from pathlib import Path

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_sets.py"


def test_set_and_history_checks_pass_through_the_test_engine(display, tmp_path):
    result = ui_test(tmp_path, CHECKS, "--new", size="1280x720")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout
