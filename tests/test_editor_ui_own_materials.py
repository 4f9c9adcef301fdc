"""A mesh file's own materials against the panel's edits, and undo, through the real UI:
`alight edit --ui-test` runs tests/editor_ui_checks_own_materials.py with the Dear ImGui Test
Engine under Xvfb on the Duck (a glTF file with a textured material of its own)."""

from __future__ import annotations

from pathlib import Path

import pytest

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_own_materials.py"


def test_own_materials_checks_pass_through_the_test_engine(display, tmp_path, shared_data):
    duck = shared_data / "models" / "Duck.glb"
    if not duck.is_file():
        pytest.skip(f"{duck} is missing")
    result = ui_test(tmp_path, CHECKS, "--new", "--mesh", str(duck), "--occlusion", "off", size="1280x720")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout[-3000:]
