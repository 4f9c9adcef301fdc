"""Leftovers of an artist's trial, through the real widgets under Xvfb: 'browse mesh', a long
status row, the Compare section's 'A preset' and the labels at 700 px
(tests/editor_ui_checks_artist.py, the Test Engine); which panel sections are open and the
render, motion and adaptive scales kept across sessions (three runs of the editor: set through
the widgets, reopened, and reopened from a session file of before they were kept); the Home key
as a real X event (tests/editor_x_events_home.py)."""

from __future__ import annotations

import json
from pathlib import Path

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_artist.py"


def test_artist_checks_pass_through_the_test_engine(display, tmp_path):
    result = ui_test(tmp_path, CHECKS, "--new", size="700x500")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout


SET_THEM = """
from alight.frontends.editor.ui_test import editor
def test_set_sections_and_scales(ctx):
    ctx.set_ref('alight')
    ctx.item_close('**/Material')         # open by default
    ctx.item_close('**/Performance')      # open by default
    ctx.item_open('**/Environment')
    ctx.item_open('**/Display & camera')
    ctx.item_input_value('**/render scale', 0.6)
    ctx.item_click('**/###adaptive_motion')   # off: the fixed scale's slider shows
    ctx.item_input_value('**/scale while moving', 0.4)
    ctx.yield_(2)
    s = editor().state
    assert (round(s.render_scale, 6), round(s.motion_scale, 6), s.adaptive_motion) == (0.6, 0.4, False), s
    assert editor().panel.sections_open == OPENED, editor().panel.sections_open
"""

SEE_THEM = """
from alight.frontends.editor.ui_test import editor
def test_reopened(ctx):
    ctx.yield_(2)
    s, panel = editor().state, editor().panel
    assert (round(s.render_scale, 6), round(s.motion_scale, 6), s.adaptive_motion) == (0.6, 0.4, False), s
    assert panel.sections_open == OPENED, panel.sections_open
    ctx.set_ref('alight')
    ctx.item_input_value('**/scale while moving', 0.5)   # drawn: the section is open, adaptive off
    assert round(s.motion_scale, 6) == 0.5
"""

DEFAULTS = """
from alight.frontends.editor.ui_test import editor
def test_defaults(ctx):
    ctx.yield_(2)
    s, panel = editor().state, editor().panel
    assert (s.render_scale, s.adaptive_motion) == (1.0, True), s
    assert panel.sections_open == OPENED, panel.sections_open
    assert s.material.name == 'kept', s.material.name   # the rest of the old session restored
"""

FLAGS_WIN = """
from alight.frontends.editor.ui_test import editor
def test_typed_flags_win(ctx):
    ctx.yield_(2)
    s = editor().state
    got = (s.aa, s.quality, round(s.motion_scale, 6), s.adaptive_motion)
    assert got == ('none', 'low', 0.75, False), got
    assert round(s.render_scale, 6) == 0.6, s.render_scale   # (not on the command line: the session's)
    ctx.set_ref('alight')
    ctx.item_open('**/Display & camera')
    ctx.combo_click('anti-aliasing/msaa')   # what the next plain start reopens
"""

SESSION_AA = """
from alight.frontends.editor.ui_test import editor
def test_session_aa(ctx):
    ctx.yield_(2)
    assert editor().state.aa == 'msaa', editor().state.aa
"""

OPENED = {"Material": False, "Environment": True, "Lights": False, "Display & camera": True,
          "Compare": False, "Performance": False, "Accuracy chart": False}
DEFAULT_OPEN = {"Material": True, "Environment": False, "Lights": False, "Display & camera": False,
                "Compare": False, "Performance": True, "Accuracy chart": False}


def test_sections_and_scales_survive_close_and_reopen(display, tmp_path):
    """Sections opened and closed, render scale, the adaptive box and the fixed motion scale set
    through the panel come back on the next start; a session file without them (written before
    they were kept) opens with the defaults and the rest of it restored."""
    for name, text, opened in (("first", SET_THEM, OPENED), ("second", SEE_THEM, OPENED),
                               ("third", DEFAULTS, DEFAULT_OPEN)):
        (tmp_path / f"{name}.py").write_text(f"OPENED = {opened!r}\n{text}")
    first = ui_test(tmp_path, tmp_path / "first.py", "--new", size="640x400")
    assert first.returncode == 0, first.stdout + first.stderr
    session_file = tmp_path / "config" / "editor-session.json"
    saved = json.loads(session_file.read_text())
    assert saved["sections"] == OPENED, saved["sections"]
    second = ui_test(tmp_path, tmp_path / "second.py", size="640x400")   # the last session reopens
    assert second.returncode == 0, second.stdout + second.stderr
    # An older session file: no sections, no scales (as alight wrote it before they were kept).
    old = json.loads(session_file.read_text())
    del old["sections"]
    for key in ("render_scale", "motion_scale", "adaptive_motion"):
        del old["settings"][key]
    old["material"]["name"] = "kept"
    session_file.write_text(json.dumps(old))
    third = ui_test(tmp_path, tmp_path / "third.py", size="640x400")
    assert third.returncode == 0, third.stdout + third.stderr


def test_view_options_typed_on_the_command_line_win_over_the_last_session(display, tmp_path):
    """The last session reopens only without scene options, and it used to set the anti-aliasing,
    bake quality and motion scale over the ones typed: `alight edit --aa none` after a session
    with msaa opened with msaa. A typed one wins; an option not typed is the session's; a plain
    start reopens what the session kept."""
    (tmp_path / "first.py").write_text(f"OPENED = {OPENED!r}\n{SET_THEM}")
    (tmp_path / "flags.py").write_text(FLAGS_WIN)
    (tmp_path / "plain.py").write_text(SESSION_AA)
    first = ui_test(tmp_path, tmp_path / "first.py", "--new", "--aa", "msaa", "--quality", "high", size="640x400")
    assert first.returncode == 0, first.stdout + first.stderr
    flags = ui_test(tmp_path, tmp_path / "flags.py", "--aa", "none", "--quality", "low", "--motion-scale", "0.75",
                    size="640x400")
    assert flags.returncode == 0, flags.stdout + flags.stderr
    plain = ui_test(tmp_path, tmp_path / "plain.py", size="640x400")
    assert plain.returncode == 0, plain.stdout + plain.stderr


def test_home_frames_a_one_sided_sheet_from_its_face(display, tmp_path):
    """The Home key, a real X key event into the editor's own loop: a single-sided sheet seen
    from behind (nothing drawn) is framed from its face. tests/editor_x_events_home.py."""
    from x_events import run_check

    result = run_check("editor_x_events_home.py", display, ALIGHT_CONFIG_DIR=str(tmp_path / "config"),
                       ALIGHT_CACHE_DIR=str(tmp_path / "cache"))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert result.stdout.startswith("ok: Home framed the sheet from its face"), result.stdout
