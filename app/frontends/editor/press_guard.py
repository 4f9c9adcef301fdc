"""Presses aimed at a layout the panel no longer has are not delivered (issue 22).

Frames here take 50-500 ms, so a click aimed at what the screen showed can reach the editor
after the panel's controls moved: a section collapsed, a library entry appeared, the panel
scrolled; it then lands on whatever control moved under the pointer (once it overwrote a library
entry). Each mouse press is stamped with the frame on screen when it arrived (the editor's loop
polls its events once more just before each swap, so a press that came while frame N-1 was shown
is told from one after frame N was), and is handed to imgui only if the controls under the pointer are where they were in that frame on
screen (``moved_under`` on the ``Panel.layout``: the scroll, the section headers above the
pointer and the end of its section) in the last frame built. Otherwise the press and its
release are dropped and the status row says so. Pure: no imgui, no glfw.
"""

from __future__ import annotations

from typing import NamedTuple

from alight.frontends.editor.keys import PRESS, RELEASE

# Frames whose layout is remembered, besides those a queued press is aimed at: a press can wait
# many frames behind typed keys (imgui trickles a burst of typing over a frame per repeated key),
# and a press whose frame was forgotten was refused though nothing had moved (a user's 'open
# env' clicked 0.3-0.5 s after typing the path, 3 in 15 on a busy machine).
KEPT_LAYOUTS = 8


class PanelLayout(NamedTuple):
    """Where the panel's controls are in a frame: its scroll, the top of each section's header
    (window coordinates, top to bottom) and the content's end."""

    scroll: int
    headers: tuple
    end: int


def moved_under(aimed, now, y: float) -> bool:
    """Whether a control at window height ``y`` in layout ``aimed`` may be elsewhere in ``now``.
    PanelLayouts: the scroll, the headers above ``y`` and the end of the section under it (the
    next header, else the content's end); a change below that section moves nothing under the
    pointer (the Performance section's lines came and went under a click far above them).
    Other layouts (tests) by equality; an unknown one (None) moves nothing."""
    if aimed is None or now is None:
        return False
    if not (isinstance(aimed, PanelLayout) and isinstance(now, PanelLayout)):
        return aimed != now
    if aimed.scroll != now.scroll or len(aimed.headers) != len(now.headers):
        return True
    above = sum(1 for top in aimed.headers if top <= y)
    if aimed.headers[:above + 1] != now.headers[:above + 1]:
        return True
    return above >= len(aimed.headers) and aimed.end != now.end


class PressGuard:
    def __init__(self):
        self.layouts: dict[int, object] = {}   # frame number -> the panel's layout in that frame
        self.shown = -1        # the frame on screen now (set after each swap)
        self.aims: dict[int, int] = {}   # id of a queued press event -> the frame on screen when it came
        self._dropping: set[int] = set()   # buttons whose release belongs to a dropped press
        self.dropped = 0       # presses dropped so far
        self.pointer = (-1.0, -1.0)   # the pointer's last position in the events sorted

    def pressed(self, event) -> None:
        """A press event just queued: it is aimed at the frame on screen now."""
        self.aims[id(event)] = self.shown

    def built(self, frame: int, layout) -> None:
        self.layouts[frame] = layout
        oldest = min(self.aims.values(), default=frame)   # a queued press's frame is kept
        for old in [k for k in self.layouts if k <= frame - KEPT_LAYOUTS and k < oldest]:
            del self.layouts[old]

    def sort(self, events: list[tuple], last_built: int, over_panel) -> tuple[list[tuple], list[tuple]]:
        """(the events to hand imgui this frame, the rest: back to the queue's front). One button
        change a frame, with no motion after it, and a release in a frame of its own when motions
        came before it: each motion is then seen with the button as it was then, so a drag counts
        to its last motion (imgui's own trickling would spread them over frames while this queue
        went on feeding it, and a release then joined the last motions in one frame). A press
        must reach imgui in the frame after ``last_built``, whose layout it is checked against. A press over the panel (``over_panel``
        (x, y) -> bool, window coordinates) aimed at a layout other than ``last_built``'s is
        dropped, with its release."""
        out = []
        changed = moved = False
        for i, event in enumerate(events):
            if event[0] == "cursor":
                if changed:   # a motion after the button changed: the widget sees it next frame
                    return out, events[i:]
                self.pointer = (event[1], event[2])
                moved = True
            if event[0] != "button":
                out.append(event)
                continue
            button, action = event[1], event[2]
            if action == RELEASE and button in self._dropping:
                self._dropping.discard(button)
                continue
            # One button change a frame; and a release never in the frame of a motion before it:
            # imgui would apply both before the widgets run, and a slider (any drag) let go
            # without seeing the button down at the last position (the end of a fast drag lost).
            if changed or (moved and action == RELEASE):
                return out, events[i:]
            if action == PRESS:
                aim = self.aims.pop(id(event), self.shown)
                if over_panel(*self.pointer) and \
                        moved_under(self.layouts.get(aim), self.layouts.get(last_built), self.pointer[1]):
                    self._dropping.add(button)
                    self.dropped += 1
                    continue
            out.append(event)
            changed = True
        return out, []
