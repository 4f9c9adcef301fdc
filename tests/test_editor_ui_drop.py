"""Drag and drop through real X events (issue 22): tests/editor_x_drop.py is an XDND source
(python-xlib) that drops file:// URIs on `alight edit`'s own glfw window under Xvfb as a file
manager does; glfw's XDND code turns them into the window's drop callback. An HDR changes the
environment, a mesh file loads, five maps dropped together become one texture set, one image
fills the armed slot, a .json preset becomes the material, a folder is a texture set."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from test_editor import display  # noqa: F401  (the Xvfb fixture)

REPO = Path(__file__).resolve().parents[1]
DROP = REPO / "tests" / "editor_x_drop.py"
HDR = REPO.parent / "shared" / "data" / "env" / "royal_esplanade_1k.hdr"


def test_files_dropped_through_xdnd_reach_the_editor(display, tmp_path):
    pytest.importorskip("Xlib", reason="python-xlib is in the test extras (pip install -e '.[test]')")
    if shutil.which("xdotool") is None:
        pytest.skip("xdotool is not installed (tools/setup.sh installs it)")   # finds the window
    env = dict(os.environ, ALIGHT_CONFIG_DIR=str(tmp_path / "config"), ALIGHT_CACHE_DIR=str(tmp_path / "cache"),
               ALIGHT_DATA_DIR=str(tmp_path / "data"))
    result = subprocess.run([sys.executable, str(DROP), "checks", str(HDR)], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "x drop: 0 failures in 6 drops" in result.stdout, result.stdout
    assert "texture set: 5 maps in their slots" in result.stdout, result.stdout
    assert "armed slot: smooth_patch.png is the roughness map" in result.stdout, result.stdout
    assert "preset: copper.json is the material" in result.stdout, result.stdout
    assert "folder: 5 maps in their slots" in result.stdout, result.stdout


def test_a_uri_list_is_what_file_managers_send():
    sys.path.insert(0, str(DROP.parent))
    from editor_x_drop import uri_list

    assert uri_list(["/a b/c%d.png", "/x.hdr"]) == b"file:///a%20b/c%25d.png\r\nfile:///x.hdr\r\n"
