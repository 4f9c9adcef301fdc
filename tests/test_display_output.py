"""ForwardRenderer.draw_display (the editor's view: tone mapped as it is drawn) gives the pixels that
draw_hdr followed by the tone map pass gives."""

from __future__ import annotations

import numpy as np
import pytest

from alight.core.mesh import sphere
from alight.core.scene import Display, Light, Scene
from alight.exchange.presets import load_preset
from alight.ibl.environment import load_environment
from tests.gpu import renderer


def read(fbo, w, h) -> np.ndarray:
    return np.frombuffer(fbo.read(components=4, dtype="f1"), np.uint8).reshape(h, w, 4).astype(int)


@pytest.mark.parametrize("display", [Display(), Display(tonemap="aces", exposure=1.5, background="blur"),
                                     Display(tonemap="none", exposure=-1.0, background="color")])
@pytest.mark.parametrize("debug_view", [0, 2])
def test_fused_tone_map_equals_the_two_passes(display, debug_view):
    r = renderer()
    maps = r.bake(load_environment("studio"), "low")
    scene = Scene(mesh=sphere(), material=load_preset("gold"), lights=[Light("point", (2.0, 3.0, 4.0))],
                  display=display, debug_view=debug_view)
    w, h = 96, 72
    targets = r._targets_for(w, h, "none", 4)
    r.draw_hdr(scene, maps, targets)
    r.tonemap(targets.radiance, scene.display, targets.display_fbo)
    two_passes = read(targets.display_fbo, w, h)
    targets.display_fbo.clear(0.0, 0.0, 0.0, 0.0)
    r.draw_display(scene, maps, targets)
    fused = read(targets.display_fbo, w, h)
    assert two_passes[:, :, :3].std() > 5.0     # a real picture, not two blank ones
    assert np.abs(fused[:, :, :3] - two_passes[:, :, :3]).max() <= 1
    assert (fused[:, :, 3] == 255).all()
