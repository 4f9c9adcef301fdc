"""The Home key (front view) pressed for real: run by tests/test_editor_ui_guards.py in a fresh
interpreter (``python tests/editor_x_events_home.py``) under Xvfb; exits 0 with an 'ok' line, 1
with a line saying what happened.

A one-sided flat sheet (a glTF without doubleSided: its back is culled) seen from behind shows
nothing; Home, a real X key event into the editor's own loop (EditorWindow.tick), frames it from
its face: the camera looks along its normal, level, and the sheet covers the view's middle."""

from __future__ import annotations

import dataclasses
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, frames_over, place_window, press_key, settle  # noqa: E402


def _sheet(folder: str) -> str:
    """A 2x2 square in the z = 0 plane facing +Z, single-sided, as a glTF file."""
    import trimesh

    path = os.path.join(folder, "sheet.glb")
    trimesh.Trimesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]]).export(path)
    return path


def _middle(image: np.ndarray) -> np.ndarray:
    h, w = image.shape[:2]
    return image[h * 2 // 5:h * 3 // 5, w * 2 // 5:w * 3 // 5].astype(np.float64)


def main() -> int:
    from alight.frontends.editor.state import EditorState
    from alight.frontends.editor.window import EditorWindow

    folder = tempfile.mkdtemp(prefix="alighthome")
    pointer = XTest()
    state = EditorState()
    state.load_mesh(_sheet(folder))
    state.load_env("studio")
    # A black background: the view's middle is black where the sheet is not drawn.
    state.display = dataclasses.replace(state.display, background="color", background_color=(0.0, 0.0, 0.0))
    win = EditorWindow(state, (640, 400))
    try:
        x0, y0 = place_window(win)
        settle(win)
        win.orbit.yaw_deg, win.orbit.pitch_deg = 200.0, -20.0   # (the scene: an orbit behind the sheet)
        frames_over(win, 0.3)
        behind = _middle(win.view_pixels())
        front = win.orbit.direction()[2]
        if front > 0.0:
            print(f"the scene's orbit is not behind the sheet: direction {win.orbit.direction()}")
            return 1
        view_w, view_h = win.view_area()
        pointer.move(x0 + view_w // 2, y0 + view_h // 2)   # over the view, as a hand is before a key
        pointer.sync()
        frames_over(win, 0.3)
        press_key(win, pointer, "Home")
        frames_over(win, 0.5)
        yaw, pitch = win.orbit.yaw_deg, win.orbit.pitch_deg
        if abs(yaw) > 1e-6 or abs(pitch) > 1e-6 or win.orbit.direction()[2] < 0.999:
            print(f"Home did not frame the sheet from its face: yaw {yaw}, pitch {pitch}, "
                  f"direction {win.orbit.direction()} (status row: {state.error or state.message!r})")
            return 1
        shown = win.view_pixels()
        from PIL import Image

        Image.fromarray(shown).save(os.path.join(folder, "home.png"))   # (to look at)
        seen = _middle(shown)
        if behind.mean() > 2.0:
            print(f"the sheet's back was drawn (culled, single-sided): the middle at {behind.mean():.1f} of 255")
            return 1
        if seen.mean() < 20.0:
            print(f"the sheet is not in the view's middle after Home: {seen.mean():.1f} of 255")
            return 1
        print(f"ok: Home framed the sheet from its face (yaw {yaw:g}, pitch {pitch:g}; the view's middle "
              f"{seen.mean():.0f} of 255, {behind.mean():.1f} from behind; {os.path.join(folder, 'home.png')})")
        return 0
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main())
