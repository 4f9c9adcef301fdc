"""The editor's slow work (the compare view's exact reference, new shader variants) kept away
from its frames, through its real UI: ``alight edit --ui-test tests/editor_ui_checks_speed.py``
under Xvfb (the Dear ImGui Test Engine operates the panel)."""

from __future__ import annotations

from pathlib import Path

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_speed.py"


def test_every_speed_check_passes_through_the_test_engine(display, tmp_path):
    result = ui_test(tmp_path, CHECKS, "--new")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout


def test_a_drag_made_during_a_busy_frame_turns_the_camera(display):
    """Real X events (XTest) queued while no frame polls, as during a long frame: the press, the
    motions and the release all count (tests/editor_x_events_speed.py)."""
    import os
    import subprocess
    import sys

    result = subprocess.run([sys.executable, str(REPO / "tests" / "editor_x_events_speed.py")], cwd=REPO,
                            env=dict(os.environ, DISPLAY=display), capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok: turned"), result.stdout


def test_an_idle_editor_sleeps_and_wakes_for_a_real_drag(display, tmp_path):
    """The editor's own loop (EditorWindow.tick) left alone draws (almost) no frames over a wait
    once its start-up work is done, and a real drag afterwards still turns the camera
    (tests/editor_x_events_idle.py)."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, DISPLAY=display, ALIGHT_CONFIG_DIR=str(tmp_path / "config"),
               ALIGHT_CACHE_DIR=str(tmp_path / "cache"))
    result = subprocess.run([sys.executable, str(REPO / "tests" / "editor_x_events_idle.py")], cwd=REPO,
                            env=env, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok: idle"), result.stdout


def test_a_fast_slider_drag_counts_to_its_last_motion(display):
    """Real X events (XTest): the roughness slider dragged from its left end past its right end,
    all between two frames, or with the last motion and the release queued together, ends at
    1.000 (tests/editor_x_events_slider.py)."""
    import os
    import subprocess
    import sys

    result = subprocess.run([sys.executable, str(REPO / "tests" / "editor_x_events_slider.py")], cwd=REPO,
                            env=dict(os.environ, DISPLAY=display), capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok:"), result.stdout


def test_the_first_orbit_of_a_material_is_compiled_away_from_the_frames(display, tmp_path):
    """A real drag (XTest) starts the first orbit; its window-drawn variant is the warm-up
    process's job, not the frame's, with an empty Mesa shader cache (tests/editor_x_events_first_orbit.py)."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, DISPLAY=display, MESA_SHADER_CACHE_DIR=str(tmp_path / "mesa"),
               ALIGHT_CACHE_DIR=str(tmp_path / "cache"))
    result = subprocess.run([sys.executable, str(REPO / "tests" / "editor_x_events_first_orbit.py")], cwd=REPO,
                            env=env, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok:"), result.stdout


def test_the_presets_are_drawn_ahead_so_a_first_click_needs_no_warm_up(display, tmp_path, monkeypatch):
    """tests/editor_ui_checks_prefetch.py through the test engine, with an empty Mesa cache."""
    monkeypatch.setenv("MESA_SHADER_CACHE_DIR", str(tmp_path / "mesa"))
    result = ui_test(tmp_path, REPO / "tests" / "editor_ui_checks_prefetch.py", "--new")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "1 passed, 0 failed" in result.stdout, result.stdout
