"""'open mesh' and 'export glTF' off the UI thread, and the map field keeping a bad path, through
the real UI: `alight edit --ui-test` runs tests/editor_ui_checks_file_jobs.py with the Dear ImGui
Test Engine against a 1280x720 window under Xvfb."""

from __future__ import annotations

import json
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
    # The last check clicked 'export glTF' and the window closed: the export is whole, its
    # temporary file gone, and where it still ran at the close, stderr said it was finished.
    from alight.exchange.gltf_material import read_gltf_json

    export = tmp_path / "closing_export.glb"
    assert export.is_file() and read_gltf_json(str(export))["meshes"], sorted(p.name for p in tmp_path.iterdir())
    assert not [p.name for p in tmp_path.iterdir() if ".tmp" in p.name or p.name.startswith("tmp")]
    if json.loads((tmp_path / "closing_export.json").read_text())["running"]:
        assert f"alight: finishing the export of {export} before closing" in result.stderr, result.stderr[-2000:]
