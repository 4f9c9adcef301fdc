"""A fast drag on a panel slider, as real X events (XTest) under Xvfb: run by
tests/test_editor_ui_speed.py in a fresh interpreter (``python tests/editor_x_events_slider.py``);
exits 0 when every drag ended the roughness slider at its right end, 1 with a line per drag
that did not.

The user's report: dragging the roughness slider from its left end quickly past its right end
(moves every 16 ms, the release right after the last move) ended at 0.935, 0.98, 0.832; a
press-move-release burst with no frame between its events changed nothing. Each drag here
starts at the slider's left end with roughness 0 and ends past its right end; what the frames
see of it differs: all of it queued between two frames (a long frame), or motions polled by
frames with the last motion and the release queued together."""

from __future__ import annotations

import dataclasses
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, open_editor, place_window, record_rects  # noqa: E402


def main() -> int:
    pointer = XTest()
    rects = record_rects("slider_float", ("roughness",))   # where the roughness slider is drawn
    win = open_editor((900, 1000))   # the slider on screen without scrolling
    state = win.state
    failures = []
    try:
        x0, y0 = place_window(win)
        left, top, right, bottom = rects["roughness"]
        y = int(y0 + (top + bottom) / 2)
        start_x, end_x = int(x0 + left + 2), int(x0 + right + 40)

        def move(x):
            pointer.move(x, y)

        def button(down):
            pointer.button(down)

        def sync(frames=0):
            pointer.sync()
            for _ in range(frames):
                win.frame()

        steps = [start_x + (end_x - start_x) * i // 10 for i in range(1, 11)]

        def burst():   # everything between two frames
            button(True)
            for x in steps:
                move(x)
            button(False)
            sync()

        def polled():   # frames poll the motions; the last motion and the release come together
            button(True)
            sync(1)
            for x in steps[:-1]:
                move(x)
                sync(1)
            move(steps[-1])
            button(False)
            sync()

        def pressed_then_burst():   # the press polled alone; then the rest at once
            button(True)
            sync(1)
            for x in steps:
                move(x)
            button(False)
            sync()

        def slow():   # frames between every event: the baseline
            button(True)
            sync(2)
            for x in steps:
                move(x)
                sync(2)
            button(False)
            sync(2)

        for name, drag in (("slow", slow), ("burst", burst), ("polled", polled), ("pressed then burst", pressed_then_burst)):
            state.material = dataclasses.replace(state.material, roughness=0.0)
            move(start_x)
            sync(3)
            drag()
            sync(8)
            got = state.material.roughness
            if got < 0.999:
                failures.append(f"{name}: the drag ended at roughness {got:.3f}, not 1.000")
        if failures:
            print("\n".join(failures))
            return 1
        print("ok: every fast drag ended at roughness 1.000")
        return 0
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main())
