"""A drag made while the editor's frame is busy, as real X events (XTest) under Xvfb: run by
tests/test_editor_ui_speed.py in a fresh interpreter (``python tests/editor_x_events_speed.py``);
exits 0 when the drag turned the camera, 1 with a line saying what happened.

The events are sent between two frames, as they queue while a long frame (a shader's first draw
on a software GL) runs: a press in the view, motions across it, a release. The next frames must
replay them in order, so the camera turns as far as the hand moved."""

from __future__ import annotations

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, open_editor, place_window  # noqa: E402


def main() -> int:
    pointer = XTest()
    win = open_editor()
    try:
        x0, y0 = place_window(win)
        view_w = win.size[0] - win.panel_width()
        start = (x0 + view_w // 4, y0 + 200)
        pointer.move(start[0], start[1])
        pointer.sync()
        for _ in range(3):
            win.frame()
        yaw = win.orbit.yaw_deg
        # The "long frame": nothing polls while the hand presses, drags 200 pixels and lets go.
        pointer.button(True)
        for step in range(1, 11):
            pointer.move(start[0] + 20 * step, start[1])
        pointer.button(False)
        pointer.sync()
        for _ in range(30):
            win.frame()
        turned = win.orbit.yaw_deg - yaw
        if abs(turned) < 10.0:
            print(f"the drag made during a busy frame turned the camera {turned:.2f} degrees (lost)")
            return 1
        print(f"ok: turned {turned:.1f} degrees")
        return 0
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main())
