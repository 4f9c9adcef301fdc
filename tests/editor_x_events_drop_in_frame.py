"""A file dropped while a frame polls its events is drawn without further input: run by
tests/test_editor_ui_speed.py in a fresh interpreter (``python tests/editor_x_events_drop_in_frame.py
ENV.hdr``) under Xvfb; exits 0 with an 'ok' line, 1 with a line saying what happened.

A new user dropped an .hdr on the editor: the status row said "opened", and the old map stayed on
screen for 30 s, until the mouse moved. The frame polls events once more after drawing (those that
came while it drew); a drop delivered there set the loop's wake flag, and the next turn of the
loop (``EditorWindow.tick``) cleared it before waiting, so nothing drew the new map until input.
Here a real XDND drop (tests/editor_x_drop.py's source process) is delivered in exactly that poll:
the frame's after-draw poll runs glfw's event polling until the drop arrives; then the editor's
own loop turns with no input, and the new environment must be baked and drawn."""

from __future__ import annotations

import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, open_editor, place_window, settle  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
WAIT_S = 120.0   # for the drop to arrive, and for the loop to bake and draw it (llvmpipe, loaded)


def main(env_file: str) -> int:
    pointer = XTest()
    win = open_editor()
    try:
        x0, y0 = place_window(win)
        w, h = win.view_area()
        # The pointer where the file is dropped (the user let go of it there): the drop's
        # positions move nothing, so no pointer event brings frames of its own.
        pointer.move(x0 + w // 2, y0 + h // 2)
        pointer.sync()
        if not settle(win):
            print("the editor never went idle (background work pending after 20000 turns)")
            return 1
        import glfw

        window_id = subprocess.run(["xdotool", "search", "--onlyvisible", "--pid", str(os.getpid())],
                                   capture_output=True, text=True, check=True).stdout.split()[0]
        seen = {"after_draw": False, "dropped": False, "source": None}
        drop, draw = win.drop, win.draw

        def noting_drop(paths):
            seen["dropped"] = True
            return drop(paths)

        def noting_draw():
            draw()
            seen["after_draw"] = True

        class AfterDrawPoll:
            """glfw, whose poll after the armed frame's drawing waits there for the real drop."""
            def __getattr__(self, name):
                return getattr(glfw, name)

            def poll_events(self):
                if seen["after_draw"] and seen["source"] is None:
                    seen["source"] = subprocess.Popen(
                        [sys.executable, os.path.join(HERE, "editor_x_drop.py"), "source", window_id,
                         str(w // 2), str(h // 2), env_file], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                    end = time.monotonic() + WAIT_S
                    while not seen["dropped"] and time.monotonic() < end:
                        glfw.poll_events()
                        time.sleep(0.005)
                else:
                    glfw.poll_events()
                seen["after_draw"] = False

        win.drop, win.draw, win.glfw = noting_drop, noting_draw, AfterDrawPoll()
        win.frame()   # a frame (as input brings one): the drop comes in its after-draw poll
        win.draw, win.glfw = draw, glfw
        if not seen["dropped"]:
            print("the drop did not arrive while the frame polled its events")
            return 1
        frames, end = 0, time.monotonic() + WAIT_S
        while time.monotonic() < end:   # the editor's own loop, no input
            frames += win.tick()
            maps_key = win._maps_key
            if maps_key is not None and maps_key[0] == id(win.state.env) and win._bake_job is None \
                    and frames >= 2 and not win.tick():
                break
        source = seen["source"]
        source.wait(timeout=60)
        state = win.state
        if state.env_spec != os.path.abspath(env_file):
            print(f"the environment is {state.env_spec!r} after the drop ({state.error or state.message})")
            return 1
        if win._maps_key is None or win._maps_key[0] != id(state.env):
            print(f"the dropped map was not drawn without input: {frames} frames in {WAIT_S:.0f} s "
                  f"(status row: {state.message!r})")
            return 1
        print(f"ok: dropped during a frame's poll, drawn in {frames} frames without input")
        return 0
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
