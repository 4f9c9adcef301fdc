"""A removed light's place closes up without moving what the scrolled panel shows: run by
tests/test_editor_ui_guards.py in a fresh interpreter (``python tests/editor_x_events_lights_scroll.py``)
under Xvfb; exits 0 when it held, 1 with a line saying what moved.

With real X input in the editor's own loop (``EditorWindow.frame``): lights added with the
panel's 'add point', the panel scrolled by the wheel, a light's 'remove' clicked. Its place
stays (a 'restore' row) while the pointer is in the list; then

- the wheel scrolls the place above the panel's top with the pointer still: the place stays
  (the list closed up under the pointer as the scroll carried the list away from it), and once
  the pointer moves into the view the rows in sight stay where they were (they all jumped up by
  the light's height: imgui keeps the scroll, and the content above them had shrunk);
- a place in sight is filled by the next light's row, which takes the removed one's place.

Each step waits for its effect a frame at a time, never a fixed sleep."""

from __future__ import annotations

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # run by path
from x_events import XTest, open_editor, place_window, record_rects, settle  # noqa: E402

SIZE = (640, 720)
FRAMES = 400   # frames to wait for one step's effect (a loaded machine draws 2-20 a second)
TOLERANCE_PX = 1.5


class SmallButtons:
    """Where imgui drew each ``small_button`` in the frame drawn last, in order: light i's
    'remove' is the i-th 'remove', a kept place's is a 'restore'."""

    def __init__(self):
        from imgui_bundle import imgui

        self.frame: list = []
        self.last: list = []
        original = imgui.small_button

        def recording(label, *args, **kwargs):
            result = original(label, *args, **kwargs)
            lo, hi = imgui.get_item_rect_min(), imgui.get_item_rect_max()
            self.frame.append((label, (lo.x, lo.y, hi.x, hi.y)))
            return result

        imgui.small_button = recording

    def draw(self, win) -> None:
        self.frame = []
        win.frame()
        self.last = self.frame

    def rects(self, label: str) -> list:
        return [rect for name, rect in self.last if name == label]


def main() -> int:
    pointer = XTest()
    headers = record_rects("collapsing_header", ("Material", "Lights", "Display & camera"))
    buttons = record_rects("button", ("add point",))
    small = SmallButtons()
    win = open_editor(SIZE)
    panel = win.panel

    def until(done, what: str) -> None:
        for _ in range(FRAMES):
            small.draw(win)
            if done():
                return
        raise AssertionError(f"{what}: not seen after {FRAMES} frames")

    def click(rect, what: str, done) -> None:
        left, top, right, bottom = rect
        pointer.move(x0 + int((left + right) / 2), y0 + int((top + bottom) / 2))
        pointer.sync()
        for _ in range(3):   # the pointer's place seen before the press (the panel's press guard)
            small.draw(win)
        pointer.button(True)
        pointer.sync()
        small.draw(win)
        pointer.button(False)
        pointer.sync()
        until(done, what)
        for _ in range(2):   # the layout the effect made, drawn (the rects recorded are its)
            small.draw(win)

    def wheel(notches: int) -> None:
        """Wheel notches over the panel where the pointer is (down for > 0), then the scroll settled."""
        for _ in range(abs(notches)):
            pointer.button(True, 5 if notches > 0 else 4)
            pointer.button(False, 5 if notches > 0 else 4)
        pointer.sync()
        last = None
        for _ in range(FRAMES):   # until two frames show the same scroll
            small.draw(win)
            if panel.layout is not None and panel.layout.scroll == last:
                return
            last = panel.layout.scroll if panel.layout is not None else None

    def to_view() -> None:
        pointer.move(x0 + 100, y0 + SIZE[1] // 2)
        pointer.sync()

    try:
        x0, y0 = place_window(win)
        settle(win)
        small.draw(win)
        # Material closed, Lights and Display & camera open: panel content below the lights, so
        # the scroll is not at its end (where imgui's clamp would hide the jump).
        for name in ("Material", "Lights", "Display & camera"):
            click(headers[name], f"a click on '{name}'", lambda: True)
        if "add point" not in buttons:
            print("the Lights section's 'add point' was not drawn")
            return 1
        while len(win.state.lights) < 5:
            n = len(win.state.lights)
            click(buttons["add point"], "a light added by 'add point'", lambda: len(win.state.lights) > n)
        panel_x = x0 + SIZE[0] - win.panel_width() // 2
        # --- a place scrolled above the panel's top ---
        pointer.move(panel_x, y0 + 200)
        pointer.sync()
        for _ in range(40):   # scroll until light 1's 'remove' is in the panel's upper part
            if small.rects("remove") and 60 < small.rects("remove")[1][1] < 200:
                break
            wheel(1)
        removes = small.rects("remove")
        if not 60 < removes[1][1] < 200:
            print(f"light 1's 'remove' did not come to the panel's upper part: {removes}")
            return 1
        click(removes[1], "light 1 removed", lambda: len(win.state.lights) == 4 and small.rects("restore"))
        height = panel._removed[0][2]   # the place's height: the removed light's

        def above() -> bool:
            kept = small.rects("restore")
            return bool(kept) and kept[0][1] + height < 0

        for _ in range(40):   # the wheel, the pointer still: the whole place goes above the window's top
            if not small.rects("restore") or above():
                break
            wheel(1)
        if not small.rects("restore"):
            print("the removed light's place closed up as the wheel scrolled it from under the still pointer")
            return 1
        if not above():
            print(f"the removed light's place did not scroll above the panel's top: {small.rects('restore')}")
            return 1
        before = small.rects("remove")[-1][1]   # the last light's row, in sight below the place
        scroll = panel.layout.scroll
        to_view()
        until(lambda: not small.rects("restore"), "the place closed up with the pointer in the view")
        for _ in range(3):
            small.draw(win)
        after = small.rects("remove")[-1][1]
        if abs(after - before) > TOLERANCE_PX:
            print(f"the rows in sight moved when the place above them closed up: the last light's row "
                  f"from y {before:.0f} to {after:.0f} (scroll {scroll} -> {panel.layout.scroll})")
            return 1
        # --- a place in sight: the next light's row takes it ---
        pointer.move(panel_x, y0 + 200)
        pointer.sync()
        for _ in range(40):
            if 60 < small.rects("remove")[0][1] < 300:
                break
            wheel(-1)
        removes = small.rects("remove")
        if not 60 < removes[0][1] < 300:
            print(f"light 0's 'remove' did not come into the panel's middle: {removes}")
            return 1
        place = removes[0][1]
        click(removes[0], "light 0 removed", lambda: len(win.state.lights) == 3 and small.rects("restore"))
        to_view()
        until(lambda: not small.rects("restore"), "the place in sight closed up with the pointer in the view")
        for _ in range(3):
            small.draw(win)
        now = small.rects("remove")[0][1]
        if abs(now - place) > TOLERANCE_PX:
            print(f"the next light's row did not take the removed one's place: y {now:.0f}, the place {place:.0f}")
            return 1
        print(f"ok: rows kept their place (next row y {before:.0f} -> {after:.0f}; in sight {place:.0f} -> {now:.0f})")
        return 0
    except AssertionError as exc:
        print(exc)
        return 1
    finally:
        win.close()


if __name__ == "__main__":
    sys.exit(main())
