"""The editor guide's picture of the 'texture set' row, taken by the Dear ImGui Test Engine inside
the real window (``alight edit --ui-test``), at 1280x720:

    xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/alight edit --new --size 1280x720 \\
        --ui-test tools/editor_texture_set_image.py

A made-up set (brown base colour, a roughness map, a bumpy normal map in Substance's names) is
written to a scratch folder named oak_planks and loaded over plastic_high through the row; writes
docs/editor_texture_set.png: the maps in their slots, the material named after the folder, the
assignment in the status row."""

import os
import tempfile
from pathlib import Path

import numpy as np
from imgui_bundle import imgui
from imgui_bundle.immapp.testing import capture

from alight.frontends.editor.ui_test import editor

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _write_set(folder: str) -> None:
    import OpenImageIO as oiio

    os.makedirs(folder, exist_ok=True)
    y, x = np.mgrid[0:256, 0:256] / 256.0
    grain = 0.5 + 0.5 * np.sin(40.0 * y + 3.0 * np.sin(6.0 * x))        # the planks' rings
    brown = np.stack([0.45 + 0.2 * grain, 0.25 + 0.12 * grain, 0.1 + 0.05 * grain], axis=2)
    rough = np.repeat((0.55 + 0.3 * grain)[:, :, None], 3, axis=2)
    n = np.stack([0.3 * np.cos(40.0 * y), np.zeros_like(x), np.ones_like(x)], axis=2)
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    for name, pixels in (("oak_BaseColor", brown), ("oak_Roughness", rough), ("oak_Normal", n * 0.5 + 0.5)):
        oiio.ImageBuf(np.round(pixels * 255).astype(np.uint8)).write(os.path.join(folder, name + ".png"))


def test_texture_set_picture(ctx):
    folder = os.path.join(tempfile.mkdtemp(), "oak_planks")
    _write_set(folder)
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_input_value("**/texture set", folder)
    ctx.item_click("**/load set")
    state = editor().state
    # The picture is of the set loaded: three slots filled and the material named after the folder.
    assert len(state.texture_maps.paths()) == 3 and state.material.name == "oak_planks", (state.texture_maps, state.error)
    ctx.mouse_move_to_pos(imgui.ImVec2(200, 600))
    ctx.yield_(3)
    capture(ctx, str(DOCS / "editor_texture_set.png"))
