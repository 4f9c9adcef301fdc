"""Renders docs/presets.png for the README: a row of preset balls in the built-in studio."""

from pathlib import Path

import numpy as np

from alight.exchange.presets import load_preset
from alight.core.mesh import sphere
from alight.core.scene import Scene
from alight.exchange.output import write_image
from alight.ibl.environment import studio_environment
from alight.render.renderer import ForwardRenderer

PRESETS = ["gold", "copper", "silver", "iron", "plastic_high", "plastic_glass_low", "water", "glass_high_ruby", "diamond"]
SIZE = 256

with ForwardRenderer() as renderer:
    maps = renderer.bake(studio_environment(), "high")
    ball = sphere()
    tiles = [renderer.render(Scene(mesh=ball, material=load_preset(name)), maps, SIZE, SIZE,
                             read_linear=False).srgb[:, :, :3] for name in PRESETS]
out = Path(__file__).resolve().parents[1] / "docs" / "presets.png"
write_image(out, np.concatenate(tiles, axis=1), linear=False)
print(out)
