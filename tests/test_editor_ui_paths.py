"""Paths the editor keeps are absolute (but the output fields left at their defaults, which stay
relative to the folder the editor runs in): a session saved by an editor started in one folder
reopens its mesh, environment, maps and file fields in an editor started from another (a fresh
user's report: the session kept '../models/...' relative to the first folder, and the second
editor showed 'no such file' and the built-in sphere). Both editors start as a user starts
them (`alight edit ...`, then `alight edit` with no scene: the real startup restores the
session); the Dear ImGui Test Engine drives the first one's field and reads the second's state."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from test_editor import display  # noqa: F401  (the Xvfb fixture)

SHARED = Path("/work/shared/data")

FIRST = """
from alight.frontends.editor.ui_test import editor, files_done

def test_export_to_a_relative_file(ctx):
    ctx.set_ref("alight")
    ctx.item_input_value("**/glTF file", "exported.glb")
    ctx.item_click("**/export glTF")
    files_done(ctx)
    s = editor().state
    assert not s.error and s.message.startswith("exported"), (s.error, s.message)
"""

SECOND = """
import os
from alight.frontends.editor.ui_test import editor

def test_the_first_folders_files_came_back(ctx):
    win = editor()
    s = win.state
    assert not s.error, s.error
    assert s.mesh_spec == {mesh!r} and s.mesh is not None and len(s.mesh.parts), (s.mesh_spec, s.error)
    assert s.env_spec == {env!r}, s.env_spec
    assert s.texture_maps.base_color == {png!r} and {png!r} in s.map_images, s.texture_maps
    assert win.panel.gltf_path == {glb!r}, win.panel.gltf_path
    # The fields left at their defaults name files in this folder, not in the first one.
    assert (win.panel.preset_path, win.turntable.path) == ("material.json", "turntable.webp"), \
        (win.panel.preset_path, win.turntable.path)
    ctx.set_ref("alight")
    ctx.item_click("**/save preset")
    assert not s.error and os.path.isfile(os.path.join(os.getcwd(), "material.json")), (s.error, s.message)
"""


def _edit(cwd: Path, home: Path, *args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, ALIGHT_CONFIG_DIR=str(home / "config"), ALIGHT_CACHE_DIR=str(home / "cache"),
               ALIGHT_DATA_DIR=str(home / "data"))
    return subprocess.run([sys.executable, "-m", "alight", "edit", "--size", "640x400", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=1200)


def test_a_session_from_one_folder_reopens_its_files_from_another(display, tmp_path):
    import trimesh
    from PIL import Image

    files, first, second = tmp_path / "files", tmp_path / "user" / "main", tmp_path / "elsewhere" / "deeper"
    for folder in (files, first, second):
        folder.mkdir(parents=True)
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(files / "box.obj")
    Image.fromarray(np.full((8, 8, 3), (200, 150, 40), np.uint8)).save(files / "gold_BaseColor.png")
    os.symlink(SHARED / "env" / "quarry_01_1k.hdr", files / "quarry.hdr")
    (tmp_path / "first.py").write_text(FIRST)
    # Every path given relative to the first folder, as the user typed them.
    result = _edit(first, tmp_path, "--mesh", "../../files/box.obj", "--env", "../../files/quarry.hdr",
                   "--map", "base_color=../../files/gold_BaseColor.png", "--ui-test", str(tmp_path / "first.py"))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    session = json.loads((tmp_path / "config" / "editor-session.json").read_text())
    mesh, env = str(files / "box.obj"), str(files / "quarry.hdr")
    png, glb = str(files / "gold_BaseColor.png"), str(first / "exported.glb")
    assert (session["mesh"], session["env"], session["texture_maps"]["base_color"], session["files"]["gltf_path"]) \
        == (mesh, env, png, glb), session
    # Output fields at their defaults stay relative: the folder of the moment, not this one.
    assert session["turntable"]["path"] == "turntable.webp", session["turntable"]
    assert session["files"]["preset_path"] == "material.json", session["files"]
    # From a folder where '../../files' is nothing: the real startup restores the session.
    (tmp_path / "second.py").write_text(SECOND.format(mesh=mesh, env=env, png=png, glb=glb))
    reopened = _edit(second, tmp_path, "--ui-test", str(tmp_path / "second.py"))
    assert reopened.returncode == 0, reopened.stdout[-3000:] + reopened.stderr[-3000:]
    assert "1 passed, 0 failed" in reopened.stdout, reopened.stdout
    assert (second / "material.json").is_file() and not (first / "material.json").exists()
