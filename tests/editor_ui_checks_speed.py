"""The editor's slow work away from its frames, operated through the panel by the Dear ImGui
Test Engine: run by tests/test_editor_ui_speed.py as ``alight edit --new --ui-test
tests/editor_ui_checks_speed.py``; not collected by pytest. No timings: the checks count jobs and
frames and compare the pictures the window shows.

``shown(ctx)`` reads the picture the window shows now (the view's image as last drawn, or the
compare split as last put together) without drawing anything; ``view(ctx)`` draws the view anew
at the window's size (and waits for a reference sum, and compiles what it needs)."""

from __future__ import annotations

import os
import sys

import numpy as np

from alight.frontends.editor.ui_test import editor, on_main_thread

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_helpers import ball  # noqa: E402

FRAMES = 6000   # frames a check waits for the child process at most (minutes on a loaded llvmpipe)


def shown(ctx) -> np.ndarray:
    def read():
        win = editor()
        if win.state.compare.active:
            tex = win.compare_view._out[0]
        else:
            tex = win._drawn_targets.display
        w, h = tex.size
        return np.frombuffer(tex.read(), np.uint8).reshape(h, w, -1)[::-1, :, :3].copy()

    return on_main_thread(ctx, read)


def same(a: np.ndarray, b: np.ndarray) -> int:
    assert a.shape == b.shape, (a.shape, b.shape)
    return int(np.abs(a.astype(np.int32) - b.astype(np.int32)).max())


def wait_frames(ctx, until) -> int:
    """Frames yielded until ``until()`` holds (at most FRAMES); their count."""
    for n in range(FRAMES):
        if until():
            return n
        ctx.yield_()
    raise AssertionError(f"still waiting after {FRAMES} frames")


def test_a_new_variant_keeps_the_old_picture_until_it_is_compiled(ctx):
    s, warm = editor().state, editor().variant_warmup
    # (No presets drawn ahead in this session: the checks below count the warm-up's jobs;
    # the prefetch has its own check, tests/editor_ui_checks_prefetch.py.)
    editor().preset_prefetch.cancel()
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    # (copper's roughness may need a variant of its own, STRETCHED_SPAN: the view settles first)
    wait_frames(ctx, lambda: not warm.pending)
    ctx.yield_(3)
    old = shown(ctx)
    jobs = warm.jobs
    ctx.item_open("**/###layer_iridescence")
    ctx.item_input_value("**/iridescence", 1.0)
    assert s.material.iridescence == 1.0, s.material
    # The new variant is compiled by the warm-up process; the view keeps the last picture meanwhile.
    assert warm.pending and warm.jobs == jobs + 1, (warm.pending, warm.jobs, jobs)
    held = shown(ctx)
    assert same(held, old) <= 1, "the view changed before the new variant was ready"
    frames = wait_frames(ctx, lambda: not warm.pending)
    assert frames > 0
    ctx.yield_(3)
    new = shown(ctx)
    assert np.abs(ball(new) - ball(old)).mean() > 2.0, "the view still shows the old picture"
    # Compiled now: switching the layer off and on again changes the picture at once, no new job.
    ctx.item_input_value("**/iridescence", 0.0)
    ctx.yield_(2)
    assert same(shown(ctx), old) <= 1
    ctx.item_input_value("**/iridescence", 1.0)
    ctx.yield_(2)
    assert same(shown(ctx), new) <= 1 and warm.jobs == jobs + 1 and not warm.pending
    ctx.item_input_value("**/iridescence", 0.0)
    ctx.item_close("**/###layer_iridescence")


def test_the_reference_fills_in_while_frames_go_on_and_reopening_reuses_it(ctx):
    s, cv = editor().state, editor().compare_view
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_input_value("**/roughness", 0.5)
    live = shown(ctx)
    jobs = cv.reference_jobs
    ctx.item_open("**/Compare")
    ctx.combo_click("compare/reference")
    ctx.item_input_value("**/reference scale", 0.15)
    # The sum runs in its own process: the window's frames go on, and A's half shows the rows
    # summed so far before the last.
    partial = []

    def done():
        if cv.a_ready and cv.reference_progress is not None and 0.0 < cv.reference_progress < 1.0:
            partial.append(cv.reference_progress)
        return cv.a_ready and cv.reference_progress is None

    frames = wait_frames(ctx, done)
    assert frames > 10 and partial, (frames, partial, s.error)
    assert not s.error, s.error
    first = shown(ctx)
    assert cv.reference_jobs >= jobs + 1
    jobs, hits = cv.reference_jobs, cv.reference_cache_hits
    h, w = first.shape[:2]
    left = first[:, : w // 2 - 2]
    assert same(left, live[:, : w // 2 - 2]) > 2, "A's half is the live view"
    # Closed and opened again: the cached sum at once, no new job.
    ctx.combo_click("compare/off")
    ctx.yield_(3)
    off = shown(ctx)
    assert same(off, live) <= 1, (same(off, live), np.abs(off.astype(int) - live).mean())
    ctx.combo_click("compare/reference")
    ctx.yield_(2)
    assert cv.a_ready and cv.reference_progress is None, (cv.a_ready, cv.reference_progress)
    assert cv.reference_jobs == jobs, (cv.reference_jobs, jobs)
    assert same(shown(ctx), first) <= 1
    # Another roughness starts another sum; going back to the one summed shows it from the cache.
    ctx.item_input_value("**/roughness", 0.6)
    ctx.yield_(2)
    assert cv.reference_jobs == jobs + 1
    ctx.item_input_value("**/roughness", 0.5)
    ctx.yield_(2)
    assert cv.a_ready and cv.reference_progress is None, (cv.a_ready, cv.reference_progress)
    counts = (cv.reference_jobs, cv.reference_cache_hits)
    assert counts == (jobs + 1, hits + 1), counts
    assert same(shown(ctx), first) <= 1
    ctx.combo_click("compare/off")
    ctx.item_close("**/Compare")


def test_a_new_mesh_waiting_for_its_variant_keeps_the_last_picture_as_it_was(ctx):
    """A preview mesh whose program is not compiled yet: the view keeps the last picture as it
    was, not the old mesh seen from the new mesh's camera (a fresh trial saw the helmet turned to
    the shader ball's 3/4 view for seconds), and the status row says it waits; then the new mesh."""
    s, warm = editor().state, editor().variant_warmup
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.combo_click("preview mesh/sphere")
    ctx.yield_(3)
    wait_frames(ctx, lambda: not warm.pending)
    ctx.yield_(3)
    old = shown(ctx)
    jobs = warm.jobs
    ctx.combo_click("preview mesh/shader_ball")
    assert s.mesh_spec == "shader_ball", s.mesh_spec
    assert warm.pending and warm.jobs == jobs + 1, (warm.pending, warm.jobs, jobs)
    ctx.yield_(2)
    assert same(shown(ctx), old) <= 1, "the old mesh was redrawn from the new mesh's camera"
    status = editor().panel.shown_status
    assert "compiling" in status, status   # the held picture does not pass for the new one
    wait_frames(ctx, lambda: not warm.pending)
    ctx.yield_(3)
    assert np.abs(shown(ctx).astype(np.float64) - old).mean() > 2.0, "the view still shows the old mesh"
    ctx.combo_click("preview mesh/sphere")
    ctx.item_close("**/Environment")
