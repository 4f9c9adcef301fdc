"""The view's keys with a text field focused: run by tests/test_editor_ui_speed.py in a fresh
interpreter (``python tests/editor_x_events_focus_keys.py``) under Xvfb; exits 0 with an 'ok'
line, 1 with a line saying what happened.

A new artist typed into a panel field, then, the pointer over the view, pressed F12: no
screenshot and no word; a click in the view and F typed 'f' into the field ('waterf'). Real X
events into the editor's own loop (EditorWindow.tick): F12 (never text) writes the screenshot
whatever field has the keyboard, and a click in the view takes the keyboard from the field, so
F frames the mesh and the field's text stays."""

from __future__ import annotations

import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, click_at, frames_over, open_editor, place_window, press_key, record_rects, settle  # noqa: E402

FIELD = "library name"


def main() -> int:
    from imgui_bundle import imgui

    pointer = XTest()
    rects = record_rects("input_text", (FIELD,))
    win = open_editor((900, 1000))
    folder = tempfile.mkdtemp(prefix="alightfocus")
    os.chdir(folder)   # (F12 writes alight-screenshot-N.png in the working folder)
    try:
        x0, y0 = place_window(win)
        settle(win)
        if FIELD not in rects or rects[FIELD][3] > win.size[1]:
            print(f"'{FIELD}' was not drawn in the window: {rects.get(FIELD)}")
            return 1
        left, top, right, bottom = rects[FIELD]
        # The press with the move, as tests/editor_x_events_idle_text.py focuses its field (a frame
        # between them drew the pointer's hover, and the press guard refused the click at times).
        pointer.move(int(x0 + (left + right) / 2), int(y0 + (top + bottom) / 2))
        pointer.button(True)
        pointer.sync()
        for _ in range(3):
            win.tick()
        pointer.button(False)
        pointer.sync()
        for _ in range(200):
            win.tick()
            if imgui.get_io().want_text_input and not win._needs_full_rate():
                break
        pointer.type("water")
        pointer.sync()
        frames_over(win, 1.0)
        typed = win.panel.library.name
        if "water" not in typed or not imgui.get_io().want_text_input:
            print(f"the field did not take the typing: {typed!r} (text input {imgui.get_io().want_text_input}, "
                  f"rect {rects[FIELD]}, window at {x0, y0}, status row: {win.state.error or win.state.message!r})")
            return 1
        view_w, view_h = win.view_area()
        vx, vy = x0 + view_w // 3, y0 + view_h // 2
        pointer.move(vx, vy)   # over the view, no click: the field keeps the keyboard
        pointer.sync()
        frames_over(win, 0.3)
        press_key(win, pointer, "F12")
        frames_over(win, 3.0)
        shots = [n for n in os.listdir(folder) if n.endswith(".png")]
        if not shots:
            print(f"F12 with '{FIELD}' focused wrote no screenshot (status row: "
                  f"{win.state.error or win.state.message!r})")
            return 1
        if win.panel.library.name != typed:
            print(f"F12 changed the field: {win.panel.library.name!r}")
            return 1
        win.orbit.zoom(-6.0)   # (the camera backed away: F's frame_mesh is seen to act)
        turned = win.orbit.render_flags(win.view_area())
        click_at(win, pointer, vx, vy)
        frames_over(win, 0.3)
        if imgui.get_io().want_text_input:
            print("a click in the view left the keyboard with the field")
            return 1
        press_key(win, pointer, "f")
        frames_over(win, 0.5)
        if win.panel.library.name != typed:
            print(f"F after a click in the view typed into the field: {win.panel.library.name!r}")
            return 1
        if win.orbit.render_flags(win.view_area()) == turned:
            print("F after a click in the view did not frame the mesh")
            return 1
        print(f"ok: F12 wrote {shots[0]} with the field focused; a click in the view, then F framed the mesh")
        return 0
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main())
