"""What a click starts and finishes without further input is shown when it finishes: run by
tests/test_editor_ui_speed.py in a fresh interpreter (``python tests/editor_x_events_status.py``)
under Xvfb; exits 0 when the status row said 'wrote ...' after a real click on 'screenshot
(F12)' with the pointer then kept still, 1 with a line saying what happened.

A new user clicked the button and kept the mouse still: the file was written, but the row seemed
to keep the previous screenshot's name: the message began with the whole folder, and the row, cut
at the panel's edge, showed the same 'wrote /folder/alight-screenshot-' both times. The message
now leads with the file's name. The loop is the editor's own (``EditorWindow.tick``)."""

from __future__ import annotations

import os
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, click_at, open_editor, place_window, record_rects, settle  # noqa: E402

LABEL = "screenshot (F12)"
WAIT_S = 3.0    # the pointer kept still this long after the click


def click(win, pointer, x0: int, y0: int, rect) -> None:
    """A real click at the middle of ``rect`` (window coordinates; the window at x0, y0)."""
    left, top, right, bottom = rect
    click_at(win, pointer, x0 + int((left + right) / 2), y0 + int((top + bottom) / 2))


def main() -> int:
    pointer = XTest()
    rects = record_rects("button", (LABEL,))
    headers = record_rects("collapsing_header", ("Display & camera", "Material"))
    win = open_editor((900, 1000))
    folder = tempfile.mkdtemp(prefix="alightshot")
    os.chdir(folder)   # (the button writes alight-screenshot-N.png in the working folder)
    try:
        x0, y0 = place_window(win)
        settle(win)
        for name in ("Material", "Display & camera"):   # the button's section opened, Material closed
            click(win, pointer, x0, y0, headers[name])
            for _ in range(4):
                win.tick()
        if LABEL not in rects:
            print(f"'{LABEL}' was not drawn")
            return 1
        for attempt in range(2):   # a second screenshot: the row held the first one's name
            for _ in range(3):
                win.tick()
            before = win.panel.shown_status
            click(win, pointer, x0, y0, rects[LABEL])
            end = time.monotonic() + WAIT_S
            while time.monotonic() < end:
                win.tick()
            written = [n for n in os.listdir(folder) if n.endswith(".png")]
            shown = win.panel.shown_status
            if len(written) != attempt + 1:
                print(f"click {attempt + 1}: files written {written}")
                return 1
            newest = max((os.path.join(folder, n) for n in written), key=os.path.getmtime)
            if not shown.startswith(f"wrote {os.path.basename(newest)} ("):   # (the name first: the row is cut)
                print(f"click {attempt + 1}: {newest} written, the row still shows {shown!r} "
                      f"(before the click: {before!r})")
                return 1
        print(f"ok: the row shows {shown!r}")
        return 0
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main())
