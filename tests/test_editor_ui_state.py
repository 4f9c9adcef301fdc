"""The panel's state as an artist meets it, through its real UI: `alight edit --ui-test` runs
tests/editor_ui_checks_state.py with the Dear ImGui Test Engine against the real window under
Xvfb (preset clicks and maps, the status row, texture-set names and the texture-set row, 'open
mesh'); then a second editor, reopened on the session the first saved, checks the mesh field."""

from __future__ import annotations

import json
from pathlib import Path

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_state.py"

REOPENED = f"""
import sys
sys.path.insert(0, {str(CHECKS.parent)!r})
from editor_ui_checks_state import reopened_mesh_field_shows_the_path as test_reopened_mesh_field
"""


def test_every_state_check_passes_and_the_reopened_mesh_field_shows_the_mesh(display, tmp_path):
    result = ui_test(tmp_path, CHECKS, "--new")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout
    session = json.loads((tmp_path / "config" / "editor-session.json").read_text())
    assert session["mesh"] == str(tmp_path / "panel_box.obj"), session["mesh"]   # the last check's mesh
    (tmp_path / "reopened.py").write_text(REOPENED)
    second = ui_test(tmp_path, tmp_path / "reopened.py")   # no --new: the last session reopens
    assert second.returncode == 0, second.stdout[-3000:] + second.stderr[-3000:]
    assert "1 passed, 0 failed" in second.stdout, second.stdout


def test_a_texture_sets_name():
    """The name a loaded set gives the material: the folder's, else the stem its maps share
    with map names and resolutions dropped, else the files' folder."""
    from alight.exchange.texture_sets import set_name

    assert set_name([], "/maps/oak_planks/") == "oak_planks"
    assert set_name(["/m/Bricks012_2K_Color.png", "/m/Bricks012_2K_NormalGL.png", "/m/Bricks012_2K_Roughness.jpg"]) \
        == "Bricks012"
    rock = ["/m/rock_wall_diff_4k.jpg", "/m/rock_wall_nor_gl_4k.exr", "/m/rock_wall_arm_4k.jpg"]
    assert set_name(rock) == "rock_wall"
    assert set_name(["/m/RockBaseColor.png", "/m/RockNormal.png"]) == "Rock"
    assert set_name(["/sets/tiles/basecolor.png", "/sets/tiles/normal.png"]) == "tiles"   # no stem: the folder
    assert set_name(["/a/x_BaseColor.png", "/b/y_Normal.png"]) == ""   # neither


def test_a_texture_set_on_the_command_line_names_the_material(display, tmp_path):
    """`alight edit --texture-set DIR` names the material after the folder, as the panel's row
    does (it was 'default'); with --preset the preset's name stays."""
    import numpy as np
    from PIL import Image

    folder = tmp_path / "walnut"
    folder.mkdir()
    Image.fromarray(np.full((8, 8, 3), (120, 70, 30), np.uint8)).save(folder / "walnut_BaseColor.png")
    check = tmp_path / "named.py"
    check.write_text("from alight.frontends.editor.ui_test import editor\n"
                     "def test_named(ctx):\n"
                     "    s = editor().state\n"
                     "    assert s.texture_maps.paths(), s.texture_maps\n"
                     "    print('NAME=' + s.material.name)\n")
    for extra, name in (((), "walnut"), (("--preset", "gold"), "gold")):
        result = ui_test(tmp_path, check, "--new", "--texture-set", str(folder), *extra)
        assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
        assert f"NAME={name}" in result.stdout, result.stdout
