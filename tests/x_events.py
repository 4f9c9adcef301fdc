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


def open_editor(size: tuple[int, int] = (640, 400)):
    """The editor's window as the X-event checks start it: the built-in sphere in the studio."""
    from alight.frontends.editor.state import EditorState
    from alight.frontends.editor.window import EditorWindow

    state = EditorState()
    state.load_mesh("sphere")
    state.load_env("studio")
    return EditorWindow(state, size)


def record_rects(function_name: str, labels) -> dict:
    """Where imgui draws the items of ``labels`` made by ``imgui.<function_name>`` (the editor's
    panel calls it by that name): {label: (x0, y0, x1, y1)}, window coordinates, filled in as
    frames are drawn. Call before the window is opened."""
    from imgui_bundle import imgui

    rects: dict = {}
    original = getattr(imgui, function_name)

    def recording(label, *args, **kwargs):
        result = original(label, *args, **kwargs)
        if label in labels:
            lo, hi = imgui.get_item_rect_min(), imgui.get_item_rect_max()
            rects[label] = (lo.x, lo.y, hi.x, hi.y)
        return result

    setattr(imgui, function_name, recording)
    return rects


def settle(win, turns: int = 20000) -> bool:
    """Turns of the editor's own loop until it waits with no background work left (the
    start-up's warm-up children, thumbnails, the presets' prefetch): whether it got there."""
    for _ in range(turns):
        if not win.tick() and not win._background_pending():
            return True
    return False


def click_at(win, pointer, x: int, y: int) -> None:
    """A real press and release at screen point (x, y), a turn of the editor's loop after the
    move and after each of them (the hover drawn before the press, as a hand's click)."""
    pointer.move(x, y)
    pointer.sync()
    win.tick()
    for down in (True, False):
        pointer.button(down)
        pointer.sync()
        win.tick()


def press_key(win, pointer, keysym: str) -> None:
    """A real key press and release, a turn of the editor's loop after each."""
    for down in (True, False):
        pointer.key(keysym, down)
        pointer.sync()
        win.tick()


def frames_over(win, wait_s: float) -> tuple[int, int]:
    """Turns of the editor's own loop for ``wait_s`` seconds: (frames drawn, waits for events)."""
    import time

    frames, waits = win._frame_no, win.idle_waits
    end = time.monotonic() + wait_s
    while time.monotonic() < end:
        win.tick()
    return win._frame_no - frames, win.idle_waits - waits


def run_check(name: str, display: str, cwd=None, timeout: int = 600, args=(), **env):
    """``python tests/NAME ARGS`` (an X-event check) in a fresh interpreter on ``display``, with
    ``env`` added to the environment: the CompletedProcess (the pytest side of these checks)."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    here = Path(__file__).resolve().parent
    return subprocess.run([sys.executable, str(here / name), *args], cwd=cwd or here.parent,
                          env=dict(os.environ, DISPLAY=display, **env), capture_output=True, text=True,
                          timeout=timeout)
