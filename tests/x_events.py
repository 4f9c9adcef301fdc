"""Real X input for the editor's X-event checks (tests/editor_x_events_*.py): XTest's fake
pointer and key events on the display the checks run under (Xvfb), and the window placed where they aim."""

from __future__ import annotations

import ctypes
import ctypes.util


class XTest:
    """The pointer, driven through libXtst. Events queue in the X server until a frame polls."""

    def __init__(self):
        self._x11 = ctypes.CDLL(ctypes.util.find_library("X11"))
        self._xtst = ctypes.CDLL(ctypes.util.find_library("Xtst") or "libXtst.so.6")
        self._x11.XOpenDisplay.restype = ctypes.c_void_p
        self._x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
        self._x11.XSync.argtypes = [ctypes.c_void_p, ctypes.c_int]
        self._xtst.XTestFakeMotionEvent.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int, ctypes.c_int,
                                                    ctypes.c_ulong]
        self._xtst.XTestFakeButtonEvent.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_ulong]
        self._xtst.XTestFakeKeyEvent.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_ulong]
        self._x11.XStringToKeysym.restype = ctypes.c_ulong
        self._x11.XStringToKeysym.argtypes = [ctypes.c_char_p]
        self._x11.XKeysymToKeycode.restype = ctypes.c_ubyte
        self._x11.XKeysymToKeycode.argtypes = [ctypes.c_void_p, ctypes.c_ulong]
        self._display = self._x11.XOpenDisplay(None)

    def move(self, x: int, y: int) -> None:
        self._xtst.XTestFakeMotionEvent(self._display, -1, int(x), int(y), 0)

    def button(self, down: bool, number: int = 1) -> None:
        self._xtst.XTestFakeButtonEvent(self._display, number, 1 if down else 0, 0)

    def key(self, keysym: str, down: bool) -> None:
        """A key by its X keysym name ('a', 'slash', 'Return', 'Shift_L')."""
        code = self._x11.XKeysymToKeycode(self._display, self._x11.XStringToKeysym(keysym.encode()))
        self._xtst.XTestFakeKeyEvent(self._display, code, 1 if down else 0, 0)

    def type(self, text: str) -> None:
        """``text`` typed key by key (letters, digits and / . - _ : what a path here holds)."""
        names = {"/": "slash", ".": "period", "-": "minus", "_": "underscore"}
        for c in text:
            shift = c == "_" or c.isupper()
            if shift:
                self.key("Shift_L", True)
            name = "minus" if c == "_" else names.get(c, c.lower())
            self.key(name, True)
            self.key(name, False)
            if shift:
                self.key("Shift_L", False)

    def sync(self) -> None:
        self._x11.XSync(self._display, 0)


def place_window(win, frames: int = 5) -> tuple[int, int]:
    """The editor's window at the screen's corner, focused, a few frames drawn: its position."""
    glfw = win.glfw
    glfw.set_window_pos(win.window, 0, 0)
    glfw.focus_window(win.window)
    for _ in range(frames):
        win.frame()
    return glfw.get_window_pos(win.window)
