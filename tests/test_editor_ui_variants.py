"""A glTF file's material variants in the editor: `alight edit --variant` and the panel's
'variant' list, run through the Dear ImGui Test Engine under Xvfb (tests/editor_ui_checks_variants.py)
against files this test writes; and `alight edit --variant` refused in one line where the file has
no such variant."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_variants.py"


def test_variant_checks_pass_through_the_test_engine(display, tmp_path):
    from tests.test_gltf_variants import variants_glb

    variants = variants_glb(tmp_path / "variants.glb")
    variants_glb(tmp_path / "blue.glb", "blue")
    result = ui_test(tmp_path, CHECKS, "--new", "--mesh", str(variants), "--variant", "blue", "--occlusion", "off",
                     size="1280x720")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout[-3000:]


def test_edit_refuses_an_unknown_variant_in_one_line(display, tmp_path):
    from tests.test_gltf_variants import variants_glb

    variants = variants_glb(tmp_path / "variants.glb")
    env = dict(os.environ, ALIGHT_CONFIG_DIR=str(tmp_path / "config"), ALIGHT_CACHE_DIR=str(tmp_path / "cache"))
    proc = subprocess.run([sys.executable, "-m", "alight", "edit", "--new", "--mesh", str(variants), "--variant",
                           "green", "--screenshot", str(tmp_path / "x.png")], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    (line,) = proc.stderr.strip().splitlines()
    assert line.startswith("alight: error: --variant green:") and "'red', 'blue'" in line, line
    assert not (tmp_path / "x.png").exists()
