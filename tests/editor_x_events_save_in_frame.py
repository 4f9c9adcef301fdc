"""What a slow click changes is drawn without further input: run by tests/test_editor_ui_speed.py
in a fresh interpreter (``python tests/editor_x_events_save_in_frame.py``) under Xvfb, with an
empty library; exits 0 with an 'ok' line, 1 with a line saying what happened.

A new artist clicked 'save to library' (the first save, into an empty library) and kept the
mouse still: the status row, the library box and the name field stayed as they were for 11 s
and more, until the mouse moved. The panel draws the status row and the library box before the
button that changes them, so a click's change is seen in the frame after; the loop drew frames
for IDLE_AFTER_S from the start of the click's frame, and a frame that wrote a file on a loaded
machine took longer than that, so the loop went to wait for input before the next one. Here the
write is made slow (a sleep in library.save_entry: a loaded machine, set up, not the control under
test) and the button is clicked by real X events; the editor's own loop then turns with no input."""

from __future__ import annotations

import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, open_editor, place_window, record_rects, settle  # noqa: E402

LABEL = "save to library"
SLOW_S = 1.0    # the write's time: longer than the loop's IDLE_AFTER_S
WAIT_S = 4.0    # the pointer kept still this long after the click


def main() -> int:
    from imgui_bundle import imgui

    from alight.frontends.editor import library

    pointer = XTest()
    rects = record_rects("button", (LABEL,))
    entries = []   # the library box's rows drawn (selectables labelled NAME##library)
    selectable = imgui.selectable

    def noting(label, *args, **kwargs):
        if label.endswith("##library"):
            entries.append(label)
        return selectable(label, *args, **kwargs)

    imgui.selectable = noting
    save_entry = library.save_entry

    def slow_save(*args, **kwargs):
        time.sleep(SLOW_S)
        return save_entry(*args, **kwargs)

    library.save_entry = slow_save
    win = open_editor((900, 1000))
    try:
        x0, y0 = place_window(win)
        settle(win)
        if LABEL not in rects or rects[LABEL][3] > win.size[1]:
            print(f"'{LABEL}' was not drawn in the window: {rects.get(LABEL)}")
            return 1
        if win.panel.library.entries:
            print(f"the library is not empty: {win.panel.library.entries}")
            return 1
        left, top, right, bottom = rects[LABEL]
        # The press with the move (as tests/editor_x_events_idle_text.py clicks): a frame between
        # them drew the pointer's hover, and the press guard refused the click at times.
        pointer.move(x0 + int((left + right) / 2), y0 + int((top + bottom) / 2))
        pointer.button(True)
        pointer.sync()
        for _ in range(3):
            win.tick()
        pointer.button(False)
        pointer.sync()
        win.tick()
        # The click's frame may have come in either tick: the save is done once the release is taken.
        end = time.monotonic() + WAIT_S
        while not win.panel.library.entries and time.monotonic() < end:
            win.tick()
        if not win.panel.library.entries:
            print(f"the click saved nothing (status row: {win.state.error or win.state.message!r})")
            return 1
        entries.clear()
        # The frame that shows the save follows the save's frame without a wait for events: a
        # child's answer that happened to end a wait (a warm-up's, on some screens) drew it by luck.
        waits, frames, end = win.idle_waits, 0, time.monotonic() + WAIT_S
        while time.monotonic() < end:   # the editor's own loop, the pointer still
            frames += win.tick()
            if win.panel.shown_status.startswith("saved to the library: "):
                break
        waited = win.idle_waits - waits
        shown = win.panel.shown_status
        if not shown.startswith("saved to the library: "):
            print(f"saved, but the status row still shows {shown!r} after {frames} frames in "
                  f"{WAIT_S:.0f} s without input")
            return 1
        if waited:
            print(f"the save was shown only after {waited} waits for events ({frames} frames)")
            return 1
        if not entries:
            print(f"saved, but the library box did not draw the entry ({frames} frames without input)")
            return 1
        print(f"ok: the row shows {shown!r}, the box {entries[-1]!r}, {frames} frames without a wait")
        return 0
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main())
