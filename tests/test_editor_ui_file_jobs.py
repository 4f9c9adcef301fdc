"""'open mesh' and 'export glTF' off the UI thread, and the map field keeping a bad path, through
the real UI: `alight edit --ui-test` runs tests/editor_ui_checks_file_jobs.py with the Dear ImGui
Test Engine against a 1280x720 window under Xvfb."""

from __future__ import annotations

from pathlib import Path

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_file_jobs.py"


def test_every_file_job_check_passes(display, tmp_path):
    result = ui_test(tmp_path, CHECKS, "--new", size="1280x720")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout
