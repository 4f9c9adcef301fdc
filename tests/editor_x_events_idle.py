"""An idle editor sleeps, and wakes for real input: run by tests/test_editor_ui_speed.py in a
fresh interpreter (``python tests/editor_x_events_idle.py``) under Xvfb; exits 0 when the still
editor drew (almost) no frames over a wait and a real drag afterwards turned the camera, 1 with a
line saying what happened.

The loop is the editor's own (``EditorWindow.tick``, what ``alight edit``'s ``run`` turns): the
pointer is outside the window, the start-up's background work (the warm-up children, the
thumbnails, the presets' prefetch) is let finish, then frames are counted over a wait."""

from __future__ import annotations

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, frames_over, open_editor, place_window, settle  # noqa: E402

WAIT_S = 2.0   # the wait frames are counted over: ~20 idle waits; the old loop drew ~150 frames


def main() -> int:
    from alight.frontends.editor.window import IDLE_WAIT_S

    pointer = XTest()
    win = open_editor()
    try:
        x0, y0 = place_window(win)
        w, h = win.glfw.get_window_size(win.window)
        pointer.move(x0 + w + 200, y0 + h + 200)   # outside the window
        pointer.sync()
        # The start-up's background work ends (bounded by turns of the loop, not by time).
        if not settle(win):
            print("the editor never went idle (background work pending after 20000 turns)")
            return 1
        frames, waits = frames_over(win, WAIT_S)
        if frames > 2 or waits < 0.25 * WAIT_S / IDLE_WAIT_S:
            print(f"idle for {WAIT_S} s the editor drew {frames} frames ({waits} waits for events)")
            return 1
        # A real drag in the view after the idle stretch turns the camera.
        yaw = win.orbit.yaw_deg
        start = (x0 + (w - win.panel_width()) // 4, y0 + h // 2)
        pointer.move(*start)
        pointer.button(True)
        for step in range(1, 11):
            pointer.move(start[0] + 20 * step, start[1])
        pointer.button(False)
        pointer.sync()
        drawn = 0
        for _ in range(400):   # turns of the loop, each a frame or a wait of at most IDLE_WAIT_S
            drawn += win.tick()
            if abs(win.orbit.yaw_deg - yaw) >= 10.0 and not win._needs_full_rate():
                break
        turned = win.orbit.yaw_deg - yaw
        if abs(turned) < 10.0:
            print(f"a drag after the idle stretch turned the camera {turned:.2f} degrees ({drawn} frames)")
            return 1
        # The Performance plot's frame times (win.frame_times) hold the frames' work, not the
        # idle stretch: a new user read a 20 s wait as a 20 000 ms frame.
        longest = max(win.frame_times)
        if longest >= 0.5 * WAIT_S:
            print(f"a frame time of {longest * 1000:.0f} ms after an idle stretch of {WAIT_S} s (the wait counted)")
            return 1
        print(f"ok: idle {WAIT_S} s: {frames} frames, {waits} waits; the drag turned {turned:.1f} degrees")
        return 0
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main())
