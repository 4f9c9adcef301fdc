"""Renders docs/editor_window.png for the README: the whole editor window, panel included.

Run under a display, e.g. ``xvfb-run -a -s "-screen 0 1400x800x24" .venv/bin/python tools/editor_window_image.py``.
"""

import dataclasses
import os
import tempfile
from pathlib import Path

# The picture shows the editor as a new user first sees it: an empty library (not this machine's).
os.environ["ALIGHT_LIBRARY_DIR"] = tempfile.mkdtemp(prefix="alight-library-")

import numpy as np

from alight.exchange.presets import load_preset
from alight.exchange.output import write_image
from alight.frontends.editor.state import EditorState
from alight.frontends.editor.window import EditorWindow

state = EditorState(quality="medium")
state.material = state.saved_material = load_preset("gold")
state.load_mesh("sphere")
state.load_env("studio")
# Two texture maps made here (the repository ships no images): a tiled base colour that darkens
# every other tile, and a greyscale roughness map of stripes, tiled twice.
maps_dir = Path(tempfile.mkdtemp())
i, j = np.indices((256, 256)) // 32
tiles = np.where(((i + j) % 2 == 0)[:, :, None], [255, 255, 255], [150, 110, 90]).astype(np.uint8)
stripes = np.repeat(np.where((i % 2 == 0)[:, :, None], 40, 200).astype(np.uint8), 3, axis=2)
write_image(maps_dir / "tiles_base_colour.png", tiles, linear=False)
write_image(maps_dir / "stripes_roughness.png", stripes, linear=False)
state.set_map("base_color", str(maps_dir / "tiles_base_colour.png"))
state.set_map("roughness", str(maps_dir / "stripes_roughness.png"))
state.texture_maps = dataclasses.replace(state.texture_maps, uv_scale=(2.0, 2.0))
win = EditorWindow(state, (1280, 720))
try:
    win.finish_bake()   # the bake runs across frames; the picture shows its result
    for _ in range(5):
        win.frame()
    # The shader warm-ups and thumbnails finish, so that the status row shows no "compiling shaders".
    for _ in range(2000):
        if not win._background_pending():
            break
        win.frame()
    win.state.message = ""
    for _ in range(3):
        win.frame()
    win.draw()   # one more frame, read back before it would be swapped
    win.ctx.finish()
    w, h = win.size
    pixels = np.frombuffer(win.ctx.screen.read(viewport=(0, 0, w, h), components=3), np.uint8).reshape(h, w, 3)[::-1]
    out = Path(__file__).resolve().parents[1] / "docs" / "editor_window.png"
    write_image(out, pixels, linear=False)
    print(out)
finally:
    win.close()
