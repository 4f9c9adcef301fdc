"""The presets' variants drawn ahead by a niced child (variant_warmup.PresetPrefetch), operated
through the panel by the Dear ImGui Test Engine: run by tests/test_editor_ui_speed.py as
``alight edit --new --ui-test tests/editor_ui_checks_prefetch.py`` with an empty Mesa shader
cache; not collected by pytest. No timings: the checks count jobs and compare pictures."""

from __future__ import annotations

import os
import sys

import numpy as np

from alight.frontends.editor.ui_test import editor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_checks_speed import ball, shown, wait_frames  # noqa: E402


def test_a_layered_presets_first_click_needs_no_warm_up(ctx):
    """Once the view has settled the presets are drawn ahead; a layered preset's first click
    (velvet: sheen) then shows its picture at once, with no warm-up job and no held frame."""
    win = editor()
    warm, prefetch = win.variant_warmup, win.preset_prefetch
    ctx.set_ref("alight")
    wait_frames(ctx, lambda: prefetch.done)
    assert prefetch.keys, "the prefetch compiled nothing"
    ctx.yield_(3)
    old, jobs, held = shown(ctx), warm.jobs, warm.held
    ctx.item_click("**/velvet")
    ctx.yield_(2)
    assert (warm.jobs, warm.held) == (jobs, held) and not warm.pending, (warm.jobs, jobs, warm.held, held)
    assert np.abs(ball(shown(ctx)).astype(float) - ball(old)).mean() > 2.0, "the view still shows the old preset"
