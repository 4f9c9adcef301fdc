"""The panel's fields through its real UI: `alight edit --ui-test` runs
tests/editor_ui_checks_fields.py with the Dear ImGui Test Engine against a 1280x720 window under
Xvfb (Enter in the env, mesh, map and texture-set fields; a long tooltip's width)."""

from __future__ import annotations

import re
from pathlib import Path

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_fields.py"


def test_every_field_check_passes(display, tmp_path):
    result = ui_test(tmp_path, CHECKS, "--new", size="1280x720")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout


def test_every_tooltip_goes_through_the_wrapping_helper():
    """imgui's set_tooltip never wraps: the editor's tooltips all go through widgets.tooltip."""
    calls = [f"{path.relative_to(REPO)}:{n}" for path in (REPO / "app").rglob("*.py")
             for n, line in enumerate(path.read_text().splitlines(), 1)
             if re.search(r"\bset_tooltip\(|\bset_item_tooltip\(", line)]
    assert not calls, calls
