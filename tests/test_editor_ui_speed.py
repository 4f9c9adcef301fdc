"""The editor's slow work (the compare view's exact reference, new shader variants) kept away
from its frames, through its real UI: ``alight edit --ui-test tests/editor_ui_checks_speed.py``
under Xvfb (the Dear ImGui Test Engine operates the panel)."""

from __future__ import annotations

from pathlib import Path

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test
from x_events import run_check

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
    result = run_check("editor_x_events_speed.py", display, timeout=300)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok: turned"), result.stdout


def test_an_idle_editor_sleeps_and_wakes_for_a_real_drag(display, tmp_path):
    """The editor's own loop (EditorWindow.tick) left alone draws (almost) no frames over a wait
    once its start-up work is done, and a real drag afterwards still turns the camera
    (tests/editor_x_events_idle.py)."""
    result = run_check("editor_x_events_idle.py", display, ALIGHT_CONFIG_DIR=str(tmp_path / "config"),
                       ALIGHT_CACHE_DIR=str(tmp_path / "cache"))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok: idle"), result.stdout


def test_a_focused_text_field_does_not_keep_the_idle_editor_drawing(display, tmp_path):
    """A real click into the material's 'name' field, then a wait with the field focused: the
    editor's own loop draws (almost) no frames, and keys typed afterwards still reach the field
    (tests/editor_x_events_idle_text.py; frames are counted, not timed)."""
    result = run_check("editor_x_events_idle_text.py", display, ALIGHT_CONFIG_DIR=str(tmp_path / "config"),
                       ALIGHT_CACHE_DIR=str(tmp_path / "cache"))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok: idle"), result.stdout


def test_a_fast_slider_drag_counts_to_its_last_motion(display):
    """Real X events (XTest): the roughness slider dragged from its left end past its right end,
    all between two frames, or with the last motion and the release queued together, ends at
    1.000 (tests/editor_x_events_slider.py)."""
    result = run_check("editor_x_events_slider.py", display, timeout=300)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok:"), result.stdout


def test_the_first_orbit_of_a_material_is_compiled_away_from_the_frames(display, tmp_path):
    """A real drag (XTest) starts the first orbit; its window-drawn variant is the warm-up
    process's job, not the frame's, with an empty Mesa shader cache (tests/editor_x_events_first_orbit.py)."""
    result = run_check("editor_x_events_first_orbit.py", display, MESA_SHADER_CACHE_DIR=str(tmp_path / "mesa"),
                       ALIGHT_CACHE_DIR=str(tmp_path / "cache"))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok:"), result.stdout


def test_the_presets_are_drawn_ahead_so_a_first_click_needs_no_warm_up(display, tmp_path, monkeypatch):
    """tests/editor_ui_checks_prefetch.py through the test engine, with an empty Mesa cache."""
    monkeypatch.setenv("MESA_SHADER_CACHE_DIR", str(tmp_path / "mesa"))
    result = ui_test(tmp_path, REPO / "tests" / "editor_ui_checks_prefetch.py", "--new")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "1 passed, 0 failed" in result.stdout, result.stdout


def test_a_screenshot_clicked_is_named_first_in_the_status_row(display, tmp_path):
    """Real X events: 'Display & camera' opened and 'screenshot (F12)' clicked twice, the pointer
    then kept still; each file is written and the status row starts with its name, where the row
    is not cut (tests/editor_x_events_status.py)."""
    result = run_check("editor_x_events_status.py", display, ALIGHT_CONFIG_DIR=str(tmp_path / "config"),
                       ALIGHT_CACHE_DIR=str(tmp_path / "cache"))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok: the row shows 'wrote alight-screenshot-2.png"), result.stdout


def test_a_file_dropped_while_a_frame_polls_is_drawn_without_input(display, tmp_path):
    """A real XDND drop of an .hdr delivered in a frame's after-draw poll, the pointer still where
    it let go: the editor's loop bakes and draws the new map with no further input (a new user's
    drop said "opened" and the old map stayed until the mouse moved; it stays 0 frames without
    the fix). tests/editor_x_events_drop_in_frame.py."""
    hdr = REPO.parent / "shared" / "data" / "env" / "quarry_01_1k.hdr"
    result = run_check("editor_x_events_drop_in_frame.py", display, args=(str(hdr),), timeout=600,
                       ALIGHT_CONFIG_DIR=str(tmp_path / "config"), ALIGHT_CACHE_DIR=str(tmp_path / "cache"))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok: dropped"), result.stdout


def test_a_slow_clicks_change_is_drawn_without_input(display, tmp_path):
    """'save to library' clicked by real X events, the write slow (a loaded machine), the pointer
    then still: the status row and the library box show the save without further input (they
    stayed as before until the mouse moved). tests/editor_x_events_save_in_frame.py."""
    result = run_check("editor_x_events_save_in_frame.py", display, ALIGHT_CONFIG_DIR=str(tmp_path / "config"),
                       ALIGHT_CACHE_DIR=str(tmp_path / "cache"), ALIGHT_LIBRARY_DIR=str(tmp_path / "library"))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok: the row shows 'saved to the library: "), result.stdout


def test_f12_works_with_a_field_focused_and_a_click_in_the_view_takes_the_keyboard(display, tmp_path):
    """Real X events: 'water' typed into 'library name', the pointer over the view, F12 writes a
    screenshot (it did nothing, silently); a click in the view, then F frames the mesh and types
    nothing into the field. tests/editor_x_events_focus_keys.py."""
    result = run_check("editor_x_events_focus_keys.py", display, ALIGHT_CONFIG_DIR=str(tmp_path / "config"),
                       ALIGHT_CACHE_DIR=str(tmp_path / "cache"), ALIGHT_LIBRARY_DIR=str(tmp_path / "library"))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok: F12 wrote alight-screenshot-1.png"), result.stdout
