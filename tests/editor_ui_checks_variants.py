"""A glTF file's material variants (KHR_materials_variants) in the editor, through the panel's
real 'variant' list: run by tests/test_editor_ui_variants.py as ``alight edit --new --mesh
variants.glb --variant blue --occlusion off --ui-test tests/editor_ui_checks_variants.py`` (the
Dear ImGui Test Engine against the real window under Xvfb); not collected by pytest.

The test writes variants.glb (red and blue variants) and blue.glb (the blue materials set
directly, no extension) into the run's folder (ALIGHT_UI_TEST_OUT). The list is shown only for
a mesh with variants; the blue variant draws as the blue control; a switch keeps the view."""

from __future__ import annotations

import os

import numpy as np

from alight.frontends.editor.ui_test import editor, files_done, view

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")


def _changed(a: np.ndarray, b: np.ndarray) -> float:
    """The share of the view's pixels that differ by more than 8 levels in a channel (the spheres
    cover a small part of the view, so a mean over all of it says little)."""
    return float((np.abs(a.astype(np.float64) - b.astype(np.float64)).max(axis=-1) > 8).mean())


def _open(ctx, name: str) -> None:
    s = editor().state
    ctx.item_input_value("**/mesh", os.path.join(OUT, name))
    files_done(ctx)
    assert s.mesh_spec == os.path.join(OUT, name), (s.mesh_spec, s.error)


def test_variant_list_draws_each_variant_as_its_control(ctx):
    win = editor()
    s = win.state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    assert s.mesh.variants == ["red", "blue"] and s.mesh.variant == "blue", (s.mesh.variants, s.mesh.variant)
    assert ctx.item_exists("variant")
    blue = view(ctx).astype(np.float64)
    angles = (win.orbit.yaw_deg, win.orbit.pitch_deg, win.orbit.distance)
    ctx.combo_click("variant/(each part's own)")
    assert s.mesh.variant is None and s.message == "variant: (each part's own)", s.message
    own = view(ctx).astype(np.float64)
    assert _changed(own, blue) > 0.01, _changed(own, blue)
    ctx.combo_click("variant/red")
    assert s.mesh.variant == "red" and not s.error, s.error
    red = view(ctx).astype(np.float64)
    assert _changed(red, own) > 0.01 and _changed(red, blue) > 0.01, (_changed(red, own), _changed(red, blue))
    ctx.combo_click("variant/blue")
    assert s.mesh.variant == "blue" and s.message == "variant: blue", s.message
    assert (win.orbit.yaw_deg, win.orbit.pitch_deg, win.orbit.distance) == angles   # the view is kept
    assert _changed(view(ctx), blue) == 0.0
    # The control: the blue materials set directly, and no variants, so no list.
    _open(ctx, "blue.glb")
    ctx.yield_(2)
    assert not s.mesh.variants and not ctx.item_exists("variant")
    control = view(ctx).astype(np.float64)
    assert _changed(control, blue) < 1e-3, _changed(control, blue)
    _open(ctx, "variants.glb")
    ctx.yield_(2)
    assert s.mesh.variant is None and ctx.item_exists("variant")   # a file opens with its own materials
    assert _changed(view(ctx), own) < 1e-3, _changed(view(ctx), own)
    ctx.item_close("**/Environment")
