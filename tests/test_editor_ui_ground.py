"""The editor's ground and shadows through its real UI (tests/editor_ui_checks_ground.py under
the Dear ImGui Test Engine, a real window under Xvfb); its screenshot against ``alight render
--ground`` of the same scene, size and camera, and against the session reopened."""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_ground.py"
LIGHT = "dir:dir=-0.3,-1,-0.5:intensity=3"   # one light, given to both (the editor's default is three)
SIZE = "640x400"


def _read(path: Path) -> np.ndarray:
    import OpenImageIO as oiio

    return oiio.ImageBuf(str(path)).get_pixels(oiio.UINT8)[:, :, :3].astype(np.float64)


def test_ground_and_shadows_through_the_panel_and_the_screenshot_equals_alight_render(display, tmp_path):
    result = ui_test(tmp_path, CHECKS, "--new", "--light", LIGHT, "--occlusion", "off", "--motion-scale", "1",
                     size=SIZE)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout
    # The idle ground is said in the status row in the panel's words; stderr had the command
    # line's ("--ground: ... --shadows off") from the renderer.
    assert "--ground" not in result.stderr and "--shadows" not in result.stderr, result.stderr[-3000:]
    for line in result.stdout.splitlines():
        if line.startswith("GROUND_"):
            print(line)
    # The session saved at the end keeps the ground (and shadows' auto).
    session = json.loads((tmp_path / "config" / "editor-session.json").read_text())
    assert session["settings"]["ground"] is True and session["settings"]["shadows"] == "auto", session["settings"]
    view = json.loads((tmp_path / "ground_view.json").read_text())
    w, h = view["size"]
    shot = _read(tmp_path / view["file"])[:h, :w]
    env = dict(os.environ, ALIGHT_CACHE_DIR=str(tmp_path / "cache"), ALIGHT_CONFIG_DIR=str(tmp_path / "config"),
               ALIGHT_DATA_DIR=str(tmp_path / "data"))

    def render(name: str, *leave_out: str) -> np.ndarray:
        out = tmp_path / name
        # The flags the panel's 'copy camera as flags' put on the clipboard, as a user pastes them
        # (its light, --occlusion off and --aa none among them).
        done = subprocess.run([sys.executable, "-m", "alight", "render",
                               *(f for f in shlex.split(view["flags"]) if f not in leave_out), "--out", str(out)],
                              env=env, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr[-3000:]
        return _read(out)

    assert view["flags"].count("--light ") == 1, view["flags"]   # the editor's one light
    assert "--ground" in view["flags"], view["flags"]
    grounded, bare = render("render_ground.png"), render("render_bare.png", "--ground")   # (bare: without it)
    diff = np.abs(shot - grounded)
    print(f"EDITOR_VS_RENDER_GROUND mean={diff.mean():.4f} max={diff.max():.0f}; "
          f"vs render without ground mean={np.abs(shot - bare).mean():.4f} max={np.abs(shot - bare).max():.0f}")
    # The same picture (the editor's anti-aliasing 'none' given to both), and not the ground-less one.
    assert diff.max() <= 1.0, (diff.mean(), diff.max(), (diff.max(axis=2) > 1).mean())
    assert np.abs(shot - bare).max() > 10 and np.abs(shot - bare).mean() > 10 * diff.mean() + 0.05
    # The session reopened (the editor again, interactive, without --new or a scene option; only an
    # interactive start reopens it): the ground is ticked and the panel's screenshot is the same
    # picture, its shadow included.
    reopen = tmp_path / "reopen_checks.py"
    reopen.write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(REPO / 'tests')!r})\n"
        "from alight.frontends.editor.ui_test import editor\n"
        "from editor_ui_checks_ground import _settled, SETTLE_LIMIT_S\n"
        "from editor_ui_helpers import screenshot, until_seconds\n"
        "def test_reopened(ctx):\n"
        "    win = editor()\n"
        "    assert win.state.ground and win.state.shadows == 'auto', (win.state.ground, win.state.shadows)\n"
        "    until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)\n"
        "    ctx.set_ref('alight')\n"
        "    ctx.item_open('**/Display & camera')\n"
        "    screenshot(ctx)\n")
    result = ui_test(tmp_path, reopen, size=SIZE)
    assert result.returncode == 0 and "1 passed, 0 failed" in result.stdout, result.stdout[-3000:] + result.stderr[-3000:]
    again = np.abs(_read(tmp_path / "alight-screenshot-2.png")[:h, :w] - shot)
    print(f"REOPENED_VS_SHOT max={again.max():.0f} mean={again.mean():.4f}")
    assert again.max() <= 1.0, (again.max(), again.mean())


def test_the_copied_flags_alone_draw_the_editors_picture_with_its_default_lights(display, tmp_path):
    """The editor's three default lights, the ground, the environment turned and the exposure
    raised in the panel: `alight render` given only the flags 'copy camera as flags' copied draws
    the screenshot's picture, the lights' shadows on the ground included (the copied flags had
    the camera alone: the command line drew no light and no shadow)."""
    checks = REPO / "tests" / "editor_ui_checks_copy_flags.py"
    result = ui_test(tmp_path, checks, "--new", "--ground", "--occlusion", "off", "--motion-scale", "1", size=SIZE)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "1 passed, 0 failed" in result.stdout, result.stdout[-3000:]
    view = json.loads((tmp_path / "copy_flags_view.json").read_text())
    w, h = view["size"]
    shot = _read(tmp_path / view["file"])[:h, :w]
    env = dict(os.environ, ALIGHT_CACHE_DIR=str(tmp_path / "cache"), ALIGHT_CONFIG_DIR=str(tmp_path / "config"),
               ALIGHT_DATA_DIR=str(tmp_path / "data"))
    out = tmp_path / "pasted.png"
    done = subprocess.run([sys.executable, "-m", "alight", "render", *shlex.split(view["flags"]), "--out", str(out)],
                          env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    diff = np.abs(shot - _read(out))
    print(f"EDITOR_VS_PASTED_FLAGS mean={diff.mean():.4f} max={diff.max():.0f}")
    assert diff.max() <= 1.0, (diff.mean(), diff.max(), (diff.max(axis=2) > 1).mean())


def test_the_ground_and_shadows_are_kept_in_the_session_and_taken_from_the_command_line(tmp_path, monkeypatch):
    """Saved and reopened (an older session without them: 'alight render''s defaults); `alight
    edit --ground --shadows` and `--script ground= shadows=` set them; the scene carries them; a
    bad value is one line."""
    import pytest

    from alight.errors import AlightError
    from alight.frontends.cli import build_parser
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.run import _no_scene_options, build_state
    from alight.frontends.editor.session import restore_session, save_session, session_path
    from alight.frontends.editor.state import EditorState

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path))
    fresh = EditorState()
    assert (fresh.ground, fresh.shadows) == (False, "auto")
    assert (fresh.scene(None).ground, fresh.scene(None).shadows) == (False, "auto")
    state = EditorState(ground=True, shadows="off")
    assert (state.scene(None).ground, state.scene(None).shadows) == (True, "off")
    save_session(state, OrbitCamera())
    fresh = EditorState()
    assert restore_session(fresh, OrbitCamera()) == "" and (fresh.ground, fresh.shadows) == (True, "off")
    data = json.loads(session_path().read_text())
    del data["settings"]["ground"], data["settings"]["shadows"]
    session_path().write_text(json.dumps(data))
    fresh = EditorState(ground=True, shadows="on")
    assert restore_session(fresh, OrbitCamera()) == "" and (fresh.ground, fresh.shadows) == (False, "auto")
    state.apply_edit("shadows=on")
    state.apply_edit("ground=0")
    assert (state.ground, state.shadows) == (False, "on")
    state.apply_edit("ground=1")
    assert state.ground
    with pytest.raises(AlightError, match="shadows 'maybe' is not one of auto, on, off"):
        state.apply_edit("shadows=maybe")
    args = build_parser().parse_args(["edit", "--ground", "--shadows", "on"])
    assert (build_state(args).ground, build_state(args).shadows) == (True, "on") and not _no_scene_options(args)
    args = build_parser().parse_args(["edit", "--shadows", "off"])
    assert not _no_scene_options(args)   # (a scene option: no reopening)
    args = build_parser().parse_args(["edit"])
    assert (build_state(args).ground, build_state(args).shadows) == (False, "auto") and _no_scene_options(args)
    with pytest.raises(SystemExit):
        build_parser().parse_args(["edit", "--shadows", "maybe"])
