"""The view and the status row (faults a fresh trial of the editor found), through its real UI: `alight edit
--ui-test` runs tests/editor_ui_checks_view_status.py with the Dear ImGui Test Engine against the real
window under Xvfb; a second editor, reopened on the session the first saved, checks the
turntable's settings and the anti-aliasing. The session's own save and restore are checked
here too, as the other session tests do."""

from __future__ import annotations

import json
import os
from pathlib import Path

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_view_status.py"

REOPENED = f"""
import sys
sys.path.insert(0, {str(CHECKS.parent)!r})
from editor_ui_checks_view_status import reopened_turntable_and_aa_are_restored as test_reopened_turntable_and_aa
"""


def test_every_trial_check_passes_and_the_reopened_editor_has_the_turntable_and_aa(display, tmp_path):
    # 1280x720: the turntable's frames at the view's size (800x720) take the WebP's encoding
    # seconds, which one frame of the old code spent.
    result = ui_test(tmp_path, CHECKS, "--new", size="1280x720")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout
    session = json.loads((tmp_path / "config" / "editor-session.json").read_text())
    assert session["turntable"] == {"frames": 5, "path": str(tmp_path / "again.webp")}, session.get("turntable")
    assert session["settings"]["aa"] == "msaa", session["settings"]
    (tmp_path / "reopened.py").write_text(REOPENED)
    second = ui_test(tmp_path, tmp_path / "reopened.py", size="1280x720")   # no --new: the last session reopens
    assert second.returncode == 0, second.stdout[-3000:] + second.stderr[-3000:]
    assert "1 passed, 0 failed" in second.stdout, second.stdout


def test_the_session_keeps_the_turntable_and_the_anti_aliasing(tmp_path, monkeypatch):
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import restore_session, save_session, session_path
    from alight.frontends.editor.state import EditorState
    from alight.frontends.editor.turntable import TurntableSettings

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path))
    state = EditorState(aa="msaa")
    save_session(state, OrbitCamera(), TurntableSettings(frames=72, path="spin.png"))
    fresh, turntable = EditorState(), TurntableSettings()
    assert restore_session(fresh, OrbitCamera(), turntable) == ""
    # (the file kept absolute: the session reopens it from any folder)
    assert (fresh.aa, turntable.frames, turntable.path) == ("msaa", 72, os.path.abspath("spin.png"))
    # A session from before these were kept: the command line's anti-aliasing and the defaults stay.
    data = json.loads(session_path().read_text())
    del data["turntable"], data["settings"]["aa"]
    session_path().write_text(json.dumps(data))
    fresh, turntable = EditorState(aa="none"), TurntableSettings()
    assert restore_session(fresh, OrbitCamera(), turntable) == ""
    assert (fresh.aa, turntable) == ("none", TurntableSettings())
    # Edited by hand: one line naming what was left out; the rest restored.
    data["turntable"], data["settings"]["aa"] = {"frames": 1, "path": "x.webp"}, "ssaa"
    session_path().write_text(json.dumps(data))
    fresh, turntable = EditorState(aa="msaa"), TurntableSettings()
    warning = restore_session(fresh, OrbitCamera(), turntable)
    assert "frames 1" in warning and "\n" not in warning, warning
    assert turntable == TurntableSettings()
    data["turntable"] = {"frames": 10, "path": "x.webp"}
    session_path().write_text(json.dumps(data))
    warning = restore_session(fresh, OrbitCamera(), turntable)
    assert "aa 'ssaa'" in warning and fresh.aa == "msaa", (warning, fresh.aa)   # (the editor has none and msaa)
    assert turntable.frames == 10


def test_the_session_keeps_the_debug_view(tmp_path, monkeypatch):
    """The debug view sits with the tone map and the anti-aliasing, which the session keeps: an
    artist who left 'roughness' (or the prefiltered radiance at mip 3.5) on finds it on again. It is
    kept by name; a session from before, without it, opens on the shaded view."""
    from alight.core.shader_names import DEBUG_VIEWS
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import restore_session, save_session, session_path
    from alight.frontends.editor.state import EditorState

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path))
    mip_view = DEBUG_VIEWS.index("prefiltered radiance at mip")
    save_session(EditorState(debug_view=mip_view, debug_mip=3.5), OrbitCamera())
    data = json.loads(session_path().read_text())
    assert (data["settings"]["debug_view"], data["settings"]["debug_mip"]) == ("prefiltered radiance at mip", 3.5)
    fresh = EditorState()
    assert restore_session(fresh, OrbitCamera()) == ""
    assert (fresh.debug_view, fresh.debug_mip) == (mip_view, 3.5)
    assert fresh.scene(None).debug_view == mip_view   # (what the view draws)
    # A session from before it was kept: the shaded view, the rest of the settings restored.
    del data["settings"]["debug_view"], data["settings"]["debug_mip"]
    data["settings"]["env_rotation_deg"] = 30.0
    session_path().write_text(json.dumps(data))
    fresh = EditorState()
    assert restore_session(fresh, OrbitCamera()) == ""
    assert (fresh.debug_view, fresh.debug_mip, fresh.env_rotation_deg) == (0, 0.0, 30.0)
    # Edited by hand: one line naming it; the settings left as they were, as for the others.
    data["settings"]["debug_view"] = "wireframe"
    session_path().write_text(json.dumps(data))
    fresh = EditorState()
    warning = restore_session(fresh, OrbitCamera())
    assert "debug_view 'wireframe' is not one of shaded, " in warning and "\n" not in warning, warning
    assert (fresh.debug_view, fresh.env_rotation_deg) == (0, 0.0)


def test_a_warning_of_a_dropped_file_is_in_the_message(tmp_path):
    """A dropped or typed file's warnings (EditorState.open_file: mesh, environment, material
    files) are in the status row's message, one or several."""
    from alight.exchange.meshes import load_mesh
    from alight.frontends.editor.state import EditorState

    path = str(REPO.parent / "shared" / "data" / "bad" / "nancolor.obj")
    state = EditorState()
    assert state.open_file(path)
    (line,) = load_mesh(path).warnings
    # The file by its name (the row already says which): the warning itself stays in view.
    assert line.startswith(path + ": ")
    assert state.message == f"opened nancolor.obj; warning: nancolor.obj: {line[len(path) + 2:]}", state.message
    state.warning_lines = ("a", "b")
    assert state.with_warnings("opened x") == "opened x; 2 warnings: a | b"


def test_a_warning_of_the_mesh_given_at_start_is_in_the_status_row(display, tmp_path):
    """`alight edit --mesh FILE` with a file drawn without something: the status row says what
    from the first frame (only stderr did)."""
    path = REPO.parent / "shared" / "data" / "bad" / "nancolor.obj"
    check = tmp_path / "start.py"
    check.write_text("from alight.frontends.editor.ui_test import editor\n"
                     "def test_status(ctx):\n"
                     "    ctx.yield_(2)\n"
                     "    print('STATUS=' + editor().panel.shown_status)\n")
    result = ui_test(tmp_path, check, "--new", "--mesh", str(path))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    status = next(line for line in result.stdout.splitlines() if line.startswith("STATUS="))
    assert "warning: " in status and "1 vertex colour NaN or Inf (line 7)" in status, status


def test_a_restored_meshs_warning_is_in_the_message(tmp_path, monkeypatch):
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import restore_session, save_session
    from alight.frontends.editor.state import EditorState

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path))
    state = EditorState()
    state.load_mesh(str(REPO.parent / "shared" / "data" / "bad" / "nancolor.obj"))
    save_session(state, OrbitCamera())
    fresh = EditorState()
    assert restore_session(fresh, OrbitCamera()) == ""
    assert fresh.message.startswith("restored the last session; warning: ") and "NaN" in fresh.message, fresh.message


def test_the_session_keeps_the_texture_sets_folder_and_the_armed_slot(tmp_path, monkeypatch):
    """Reopened, the 'texture set' field names the folder the set came from (it read the files'
    list) and a dropped image goes to the slot armed before (it went to base colour)."""
    import numpy as np
    from PIL import Image

    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import restore_session, save_session, session_path
    from alight.frontends.editor.state import EditorState

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path / "config"))
    folder = tmp_path / "moss"
    folder.mkdir()
    for suffix in ("diff", "rough"):
        Image.fromarray(np.full((8, 8, 3), 90, np.uint8)).save(folder / f"moss_{suffix}.png")
    state = EditorState()
    state.open_texture_folder(str(folder))
    state.armed_slot = "roughness"
    assert state.texture_set_text() == str(folder)
    save_session(state, OrbitCamera())
    fresh = EditorState()
    assert restore_session(fresh, OrbitCamera()) == ""
    assert fresh.texture_set_text() == str(folder) and fresh.armed_slot == "roughness", \
        (fresh.texture_set_text(), fresh.armed_slot)
    data = json.loads(session_path().read_text())   # an older session: the files, base colour
    del data["texture_set_folder"], data["armed_slot"]
    session_path().write_text(json.dumps(data))
    fresh = EditorState()
    assert restore_session(fresh, OrbitCamera()) == ""
    assert fresh.texture_set_text() == f"moss_* (2 maps) in {folder}" and fresh.armed_slot == "base_color", \
        fresh.texture_set_text()
