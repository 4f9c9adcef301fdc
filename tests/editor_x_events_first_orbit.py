"""The first orbit of a material, as real X events (XTest) under Xvfb: run by
tests/test_editor_ui_speed.py in a fresh interpreter with an empty Mesa shader cache; exits 0
when it passes, 1 with a line saying what happened.

An orbiting view is drawn straight into the window, with another program and (llvmpipe) other
fragment code than the still view's. Its first orbit must not compile that in the editor's
frames: the warm-up process draws it into a hidden window like the editor's
(variant_warmup.py, gl_window.py) while the view shows the last picture, and the editor's own
compile comes after, a read of the shader cache."""

from __future__ import annotations

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, open_editor, place_window  # noqa: E402


def main() -> int:
    pointer = XTest()
    win = open_editor()
    warm, shaders = win.variant_warmup, win.renderer.shaders
    try:
        if win.direct_target()[0] is None:
            print("ok: skipped (the window has no depth buffer: orbits are drawn into the view image)")
            return 0
        x0, y0 = place_window(win, frames=0)
        # The view settles first, as before an artist's drag: the opening camera's ease-in done,
        # the still view's programs compiled (the warm-up's jobs where gated), its image drawn.
        for _ in range(600):
            win.frame()
            if (not warm.pending and not warm.showing_old and win._drawn_targets is not None
                    and win.orbit.camera() == win._last_camera):
                break
        start = (x0 + (win.size[0] - win.panel_width()) // 4, y0 + 200)
        pointer.move(start[0], start[1])
        pointer.sync()
        for _ in range(3):
            win.frame()
        before, jobs = set(shaders.compiled_keys()), warm.jobs
        pointer.button(True)
        pointer.sync()
        compiled_in_frame, frames, step, settled = [], 0, 0, False
        # The hand keeps dragging, a motion a frame, until the view is drawn into the window.
        while frames < 600:
            step += 1
            pointer.move(start[0] + (step % 40) * 4, start[1])
            pointer.sync()
            win.frame()
            frames += 1
            new = set(shaders.compiled_keys()) - before
            # Every program the orbit compiles in a frame was drawn by the warm-up process first.
            compiled_in_frame.extend(sorted(str(k) for k in new - warm.drawn_by_child))
            before |= new
            settled = warm.jobs > jobs and not warm.pending and not warm.showing_old
            if settled:
                break
        pointer.button(False)
        pointer.sync()
        win.frame()
        if warm.jobs == jobs:
            print("the first orbit asked the warm-up process for nothing (its program was compiled in the frame, "
                  "or the view was not drawn into the window)")
            return 1
        if compiled_in_frame:
            print(f"a program the warm-up process had not drawn was compiled in the editor's frame: {compiled_in_frame[0]}")
            return 1
        if not settled:
            print(f"the orbit still waited for the warm-up after {frames} frames")
            return 1
        print(f"ok: {warm.jobs - jobs} warm-up job(s), the orbit drawn into the window after {frames} frames")
        return 0
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main())
