"""The editor's panel through its real UI: `alight edit --ui-test` runs test functions with the
Dear ImGui Test Engine against the real window under Xvfb (tests/editor_ui_checks.py clicks,
types, drags and presses keys; none goes through --script)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from test_editor import display  # noqa: F401  (the Xvfb fixture)

REPO = Path(__file__).resolve().parents[1]


def ui_test(tmp_path: Path, file: Path, *args: str, size: str = "640x400") -> subprocess.CompletedProcess:
    env = dict(os.environ, ALIGHT_CONFIG_DIR=str(tmp_path / "config"), ALIGHT_CACHE_DIR=str(tmp_path / "cache"),
               ALIGHT_DATA_DIR=str(tmp_path / "data"), ALIGHT_UI_TEST_OUT=str(tmp_path))
    return subprocess.run([sys.executable, "-m", "alight", "edit", "--size", size, *args, "--ui-test", str(file)],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=1200)


def test_every_panel_check_passes_through_the_test_engine(display, tmp_path):
    result = ui_test(tmp_path, REPO / "tests" / "editor_ui_checks.py", "--new")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in (REPO / "tests" / "editor_ui_checks.py").read_text().splitlines()
              if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout
    # Files the panel's buttons and F12 wrote, in the run's folder.
    assert (tmp_path / "from_panel.json").is_file() and (tmp_path / "from_panel.gltf").is_file()
    assert list(tmp_path.glob("alight-screenshot-*.png"))
    # The session is saved at the end, as after a normal close: the last material clicked.
    session = json.loads((tmp_path / "config" / "editor-session.json").read_text())
    # The last material: the error-line check's gold, saved as before_error.json (named after it).
    assert session["material"]["name"] == "before_error" and session["material"]["roughness"] == 0.5, session


def test_failures_exit_1_with_their_message_and_the_view_is_the_editors(display, tmp_path):
    """A failed check and an item the engine cannot find each give a line and exit 1; the other
    tests still run. The window under the runner draws the view `alight edit --screenshot` draws."""
    file = tmp_path / "mine.py"
    file.write_text(
        "import numpy as np\n"
        "from alight.frontends.editor.ui_test import editor, view\n"
        "def test_copper(ctx):\n"
        "    ctx.set_ref('alight')\n"
        "    ctx.item_click('**/copper')\n"
        "    assert editor().state.material.name == 'copper'\n"
        "    np.save('view.npy', view(ctx))\n"
        "def test_wrong(ctx):\n"
        "    assert 1 + 1 == 3, 'arithmetic is broken'\n"
        "def test_missing_item(ctx):\n"
        "    ctx.set_ref('alight')\n"
        "    ctx.item_click('**/no such button')\n")
    result = ui_test(tmp_path, file, "--new", size="320x240")
    assert result.returncode == 1, result.stdout + result.stderr
    assert "ok   test_copper" in result.stdout and "1 passed, 2 failed" in result.stdout
    failures = [line for line in result.stderr.splitlines() if line.startswith("alight: ui test")]
    assert len(failures) == 2, result.stderr
    assert "test_wrong failed: AssertionError: arithmetic is broken (line 9)" in failures[0]
    assert "test_missing_item failed:" in failures[1] and "Unable to locate item" in failures[1]
    # The same scene through the editor's own loop: the same pixels.
    import OpenImageIO as oiio

    shot = tmp_path / "copper.png"
    own = subprocess.run([sys.executable, "-m", "alight", "edit", "--size", "320x240", "--preset", "copper",
                          "--screenshot", str(shot), "--frames", "3"], cwd=tmp_path, capture_output=True, text=True,
                         timeout=120, env=dict(os.environ, ALIGHT_CONFIG_DIR=str(tmp_path / "config2")))
    assert own.returncode == 0, own.stderr
    hosted = np.load(tmp_path / "view.npy").astype(np.int32)
    drawn = oiio.ImageBuf(str(shot)).get_pixels(oiio.UINT8).astype(np.int32)
    assert hosted.shape == drawn.shape == (240, 320, 3)
    assert np.abs(hosted - drawn).max() <= 1, np.abs(hosted - drawn).max()


def test_bad_ui_test_files_are_one_line(display, tmp_path):
    missing = ui_test(tmp_path, tmp_path / "absent.py", "--new")
    assert missing.returncode == 2 and missing.stderr.count("\n") == 1 and "absent.py" in missing.stderr
    broken = tmp_path / "broken.py"
    broken.write_text("def test_x(ctx):\n    pass\nraise ValueError('oops')\n")
    result = ui_test(tmp_path, broken, "--new")
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "broken.py: line 3:" in result.stderr and "oops" in result.stderr
    empty = tmp_path / "empty.py"
    empty.write_text("x = 1\n")
    result = ui_test(tmp_path, empty, "--new")
    assert result.returncode == 2 and "no test_*(ctx) function" in result.stderr
    both = ui_test(tmp_path, empty, "--new", "--script", "roughness=0.5")
    assert both.returncode == 2 and both.stderr.count("\n") == 1


FIRST_RUN = """
import numpy as np
from alight.frontends.editor.ui_test import editor, view
def test_set_the_view(ctx):
    ctx.set_ref('alight')
    ctx.item_click('**/silver')
    assert editor().state.material.name == 'silver', editor().state.material.name
    ctx.item_open('**/Environment')
    ctx.item_input_value('**/rotation', 75.0)
    ctx.item_input_value('**/intensity', 1.5)
    ctx.combo_click('background/color')
    ctx.item_close('**/Environment')
    ctx.item_open('**/Display & camera')
    ctx.combo_click('tone map/neutral')
    ctx.item_input_value('**/exposure (EV)', -0.5)
    ctx.item_close('**/Display & camera')
    ctx.item_open('**/Lights')
    ctx.item_click('**/add directional')
    ctx.item_close('**/Lights')
    # The split view: A a snapshot of silver, B silver made rougher, the divider at 0.3.
    ctx.set_ref('alight')
    ctx.item_open('**/Compare')
    ctx.combo_click('compare/material')
    ctx.item_click('**/snapshot A')
    ctx.item_input_value('**/divider', 0.3)
    ctx.item_close('**/Compare')
    ctx.item_input_value('**/roughness', 0.7)
    s = editor().state
    assert (s.env_rotation_deg, s.display.tonemap, s.display.background) == (75.0, 'neutral', 'color')
    assert s.material.name == 'silver', s.material.name
    assert s.compare.active and abs(s.compare.divider - 0.3) < 1e-6, s.compare
    assert abs(s.material.roughness - 0.7) < 1e-6 and s.compare.a_material.roughness != s.material.roughness
    np.save('first.npy', view(ctx))
"""

SECOND_RUN = """
import numpy as np
from alight.frontends.editor.ui_test import editor, view
def test_reopened(ctx):
    s = editor().state
    assert (s.env_rotation_deg, s.env_intensity) == (75.0, 1.5), (s.env_rotation_deg, s.env_intensity)
    assert (s.display.tonemap, s.display.exposure, s.display.background) == ('neutral', -0.5, 'color'), s.display
    assert len(s.lights) == 4 and s.lights[-1].kind == 'directional', s.lights
    assert s.material.name == 'silver', s.material.name
    c = s.compare
    assert (c.mode, c.a_label, c.active) == ('material', 'snapshot of silver', True) and abs(c.divider - 0.3) < 1e-6, c
    assert c.a_material.name == 'silver' and abs(s.material.roughness - 0.7) < 1e-6, c
    assert abs(c.a_material.roughness - s.material.roughness) > 0.1, c   # A the snapshot, B edited since
    np.save('second.npy', view(ctx))
"""


def test_view_settings_survive_close_and_reopen(display, tmp_path):
    """Environment rotation and intensity, tone map, exposure, background, lights and the compare
    split (on, its divider, A's snapshot) set through the panel come back when the editor is
    opened again, and the view is the same picture (split as it was)."""
    (tmp_path / "first.py").write_text(FIRST_RUN)
    (tmp_path / "second.py").write_text(SECOND_RUN)
    first = ui_test(tmp_path, tmp_path / "first.py", "--new", size="320x240")
    assert first.returncode == 0, first.stdout + first.stderr
    second = ui_test(tmp_path, tmp_path / "second.py", size="320x240")   # the last session reopens
    assert second.returncode == 0, second.stdout + second.stderr
    a, b = (np.load(tmp_path / f"{n}.npy").astype(np.int32) for n in ("first", "second"))
    assert np.abs(a - b).max() <= 1
    fresh = ui_test(tmp_path, tmp_path / "second.py", "--new", size="320x240")   # --new: none of it
    assert fresh.returncode == 1 and "test_reopened failed" in fresh.stderr


def test_a_bad_setting_in_the_session_file_is_one_warning(tmp_path, monkeypatch):
    """A session file edited by hand (a tone map that does not exist) restores the material and
    camera and says which setting it left out, in one line."""
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import restore_session, save_session, session_path
    from alight.frontends.editor.state import EditorState

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path))
    state = EditorState()
    state.env_rotation_deg = 30.0
    save_session(state, OrbitCamera())
    data = json.loads(session_path().read_text())
    data["settings"]["display"]["tonemap"] = "sepia"
    session_path().write_text(json.dumps(data))
    fresh = EditorState()
    warning = restore_session(fresh, OrbitCamera())
    assert "tonemap 'sepia'" in warning and "\n" not in warning
    assert fresh.env_rotation_deg == 0.0 and fresh.display.tonemap == "aces"   # the settings left as they were


def test_the_preset_file_field_follows_the_material_until_typed_in(display, tmp_path):
    """A new user clicked 'save preset' with the field left at material.json: the aluminium saved
    was renamed 'material' and the library asked to replace its 'material'. The field now shows
    the material's name (aluminium.json) until the artist types in it; a save keeps the name."""
    file = tmp_path / "preset_field.py"
    file.write_text(
        "import os\n"
        "from alight.frontends.editor.ui_test import editor\n"
        "def test_field(ctx):\n"
        "    panel, s = editor().panel, editor().state\n"
        "    ctx.set_ref('alight')\n"
        "    ctx.item_click('**/aluminium')\n"
        "    ctx.yield_(2)\n"
        "    assert panel.preset_path == 'aluminium.json', panel.preset_path\n"
        "    ctx.item_click('**/save preset')\n"
        "    ctx.yield_(2)\n"
        "    assert os.path.isfile('aluminium.json') and s.material.name == 'aluminium', (s.message, s.error)\n"
        "    ctx.item_click('**/gold')\n"
        "    ctx.yield_(2)\n"
        "    assert panel.preset_path == 'gold.json', panel.preset_path\n"
        "    ctx.item_input_value('**/preset file', 'mine.json')\n"
        "    ctx.item_click('**/copper')\n"
        "    ctx.yield_(2)\n"
        "    assert panel.preset_path == 'mine.json', panel.preset_path\n")
    result = ui_test(tmp_path, file, "--new")
    assert result.returncode == 0 and "1 passed, 0 failed" in result.stdout, result.stdout[-3000:] + result.stderr[-3000:]
    assert (tmp_path / "aluminium.json").is_file() and not (tmp_path / "material.json").exists()


def test_the_preset_file_field_follows_a_set_dropped_while_the_field_is_in_use(display, tmp_path):
    """A new user's first run (no session): the 'preset file' field clicked (nothing typed),
    then DamagedHelmet's maps dropped as a set. The field in use handed imgui's copy of
    material.json back over the set's name and never followed again: 'save preset' wrote
    material.json and a library 'material', and the gold preset later still said material.json.
    It follows the set's name (Default.json), a save keeps it, and the next preset's too."""
    helmet = REPO.parent / "shared" / "data" / "models" / "DamagedHelmet"
    file = tmp_path / "preset_field_drop.py"
    file.write_text(
        "import os\n"
        "from alight.frontends.editor.ui_test import editor\n"
        "def test_field(ctx):\n"
        "    w = editor()\n"
        "    panel, s = w.panel, w.state\n"
        "    ctx.set_ref('alight')\n"
        "    ctx.item_click('**/preset file')\n"
        f"    helmet = {str(helmet)!r}\n"
        "    w.drop([os.path.join(helmet, f) for f in sorted(os.listdir(helmet)) if f.endswith('.jpg')])\n"
        "    ctx.yield_(3)\n"
        "    assert s.material.name == 'Default' and panel.preset_path == 'Default.json', panel.preset_path\n"
        "    ctx.item_click('**/save preset')\n"
        "    ctx.yield_(2)\n"
        "    assert os.path.isfile('Default.json') and not s.error, (s.message, s.error)\n"
        "    ctx.item_click('**/gold')\n"
        "    ctx.yield_(2)\n"
        "    assert panel.preset_path == 'gold.json', panel.preset_path\n")
    result = ui_test(tmp_path, file)   # (no --new: a first run, no session in the fresh config folder)
    assert result.returncode == 0 and "1 passed, 0 failed" in result.stdout, result.stdout[-3000:] + result.stderr[-3000:]
    assert not (tmp_path / "material.json").exists()
    assert not list((tmp_path / "data").rglob("material.glb")), list((tmp_path / "data").rglob("*.glb"))
