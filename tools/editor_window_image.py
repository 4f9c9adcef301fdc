"""Renders docs/editor_window.png for the README: the whole editor window, panel included.

Run under a display, e.g. ``xvfb-run -a -s "-screen 0 1400x800x24" .venv/bin/python tools/editor_window_image.py``.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from app.editor.state import EditorState  # noqa: E402
from app.editor.window import EditorWindow  # noqa: E402
from app.material import load_preset  # noqa: E402
from app.output import write_image  # noqa: E402

state = EditorState(quality="medium")
state.material = state.saved_material = load_preset("gold")
state.load_mesh("sphere")
state.load_env("studio")
win = EditorWindow(state, (1280, 720))
try:
    win.finish_bake()   # the bake runs across frames; the picture shows its result
    for _ in range(5):
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
