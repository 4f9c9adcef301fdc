"""A focused text field does not keep the idle editor drawing: run by tests/test_editor_ui_speed.py
in a fresh interpreter (``python tests/editor_x_events_idle_text.py``) under Xvfb; exits 0 when,
after a real click into the material's 'name' field (XTest), the editor drew (almost) no frames
over a wait with the field still focused, and typed keys then reached the field; 1 with a line
saying what happened.

The loop is the editor's own (``EditorWindow.tick``). A new user saw a focused field keep the
idle editor at full rate (imgui counts an active text input as an active item, and its cursor
blinks): frames are counted over the wait, not timed."""

from __future__ import annotations

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, frames_over, open_editor, place_window, record_rects, settle  # noqa: E402

WAIT_S = 2.0   # ~20 idle waits; at full rate the loop draws tens of frames, a blinking cursor 4


def main() -> int:
    pointer = XTest()
    rects = record_rects("input_text", ("name",))   # the material's name field
    win = open_editor((900, 1000))   # the field on screen without scrolling
    try:
        x0, y0 = place_window(win)
        if not settle(win):
            print("the editor never went idle (background work pending after 20000 turns)")
            return 1
        left, top, right, bottom = rects["name"]
        pointer.move(int(x0 + (left + right) / 2), int(y0 + (top + bottom) / 2))
        pointer.button(True)
        pointer.sync()
        for _ in range(3):
            win.tick()
        pointer.button(False)
        pointer.sync()
        for _ in range(200):   # the click's frames, then the loop goes idle again
            win.tick()
            if win.imgui.get_io().want_text_input and not win._needs_full_rate():
                break
        if not win.imgui.get_io().want_text_input:
            print("the click did not focus the 'name' field")
            return 1
        settle(win)
        frames, waits = frames_over(win, WAIT_S)
        focused = win.imgui.get_io().want_text_input
        if not focused:
            print("the 'name' field lost the focus during the wait")
            return 1
        if frames > 2:
            print(f"idle for {WAIT_S} s with the 'name' field focused the editor drew {frames} frames "
                  f"({waits} waits for events)")
            return 1
        # The field still takes keys: typed letters reach the material's name.
        for c in "xy":
            pointer.key(c, True)
            pointer.key(c, False)
        pointer.sync()
        for _ in range(60):
            win.tick()
            if "xy" in win.state.material.name:
                break
        if "xy" not in win.state.material.name:
            print(f"keys typed after the wait did not reach the field (name {win.state.material.name!r})")
            return 1
        print(f"ok: idle {WAIT_S} s with a focused text field: {frames} frames, {waits} waits")
        return 0
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main())
