"""Renders docs/presets.png for the README: a row of preset balls in the built-in studio."""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from app.environment import studio_environment  # noqa: E402
from app.material import load_preset  # noqa: E402
from app.mesh import sphere  # noqa: E402
from app.output import write_image  # noqa: E402
from app.renderer import Renderer  # noqa: E402
from app.scene import Scene  # noqa: E402

PRESETS = ["gold", "copper", "silver", "iron", "plastic_glass_low", "plastic_high", "water"]
SIZE = 256

with Renderer() as renderer:
    maps = renderer.bake(studio_environment(), "high")
    ball = sphere()
    tiles = [renderer.render(Scene(mesh=ball, material=load_preset(name)), maps, SIZE, SIZE,
                             read_linear=False).srgb[:, :, :3] for name in PRESETS]
out = Path(__file__).resolve().parents[1] / "docs" / "presets.png"
write_image(out, np.concatenate(tiles, axis=1), linear=False)
print(out)
