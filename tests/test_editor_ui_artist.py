"""Leftovers of an artist's trial, through the real widgets under Xvfb: 'browse mesh'
(tests/editor_ui_checks_artist.py, the Test Engine)."""

from __future__ import annotations

from pathlib import Path

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_artist.py"


def test_artist_checks_pass_through_the_test_engine(display, tmp_path):
    result = ui_test(tmp_path, CHECKS, "--new", size="700x500")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout
