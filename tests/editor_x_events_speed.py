"""A drag made while the editor's frame is busy, as real X events (XTest) under Xvfb: run by
tests/test_editor_ui_speed.py in a fresh interpreter (``python tests/editor_x_events_speed.py``);
exits 0 when the drag turned the camera, 1 with a line saying what happened.

The events are sent between two frames, as they queue while a long frame (a shader's first draw
on a software GL) runs: a press in the view, motions across it, a release. The next frames must
replay them in order, so the camera turns as far as the hand moved."""

from __future__ import annotations

import ctypes
import ctypes.util
import sys


def main() -> int:
    from alight.frontends.editor.state import EditorState
    from alight.frontends.editor.window import EditorWindow

    x11 = ctypes.CDLL(ctypes.util.find_library("X11"))
    xtst = ctypes.CDLL(ctypes.util.find_library("Xtst") or "libXtst.so.6")
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XFlush.argtypes = x11.XSync.argtypes = [ctypes.c_void_p]
    x11.XSync.argtypes = [ctypes.c_void_p, ctypes.c_int]
    xtst.XTestFakeMotionEvent.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_ulong]
    xtst.XTestFakeButtonEvent.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_ulong]
    display = x11.XOpenDisplay(None)

    state = EditorState()
    state.load_mesh("sphere")
    state.load_env("studio")
    win = EditorWindow(state, (640, 400))
    try:
        glfw = win.glfw
        glfw.set_window_pos(win.window, 0, 0)
        glfw.focus_window(win.window)
        for _ in range(5):
            win.frame()
        x0, y0 = glfw.get_window_pos(win.window)
        view_w = win.size[0] - win.panel_width()
        start = (x0 + view_w // 4, y0 + 200)
        xtst.XTestFakeMotionEvent(display, -1, start[0], start[1], 0)
        x11.XSync(display, 0)
        for _ in range(3):
            win.frame()
        yaw = win.orbit.yaw_deg
        # The "long frame": nothing polls while the hand presses, drags 200 pixels and lets go.
        xtst.XTestFakeButtonEvent(display, 1, 1, 0)
        for step in range(1, 11):
            xtst.XTestFakeMotionEvent(display, -1, start[0] + 20 * step, start[1], 0)
        xtst.XTestFakeButtonEvent(display, 1, 0, 0)
        x11.XSync(display, 0)
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
