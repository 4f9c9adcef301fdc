"""Keys as the keyboard's layout labels them, for imgui's shortcuts (Ctrl+A, Ctrl+Z ...).

glfw reports a key by its position on a US keyboard (GLFW_KEY_Q is the key left of W whatever
it prints), and imgui-bundle's Python glfw backend hands that on: on an AZERTY keyboard the key
that prints 'a' reached imgui as Q, and Ctrl+A did not select a text field. Dear ImGui's own C++
glfw backend (the one the --ui-test runner uses) translates printable keys by the character the
layout gives them (ImGui_ImplGlfw_TranslateUntranslatedKey); ``translate_key`` does the same for
the editor's own loop. Pure: the glfw key codes are those of glfw.h.
"""

from __future__ import annotations

KEY_0, KEY_A, KEY_KP_0, KEY_KP_EQUAL = 48, 65, 320, 336
# glfw.h's codes of the punctuation keys, by the character they print on a US layout.
_PUNCTUATION = {"`": 96, "-": 45, "=": 61, "[": 91, "]": 93, "\\": 92, ",": 44, ";": 59, "'": 39, ".": 46, "/": 47}


def translate_key(key: int, name: str | None) -> int:
    """The glfw key code of the character ``name`` (glfw.get_key_name of the key: what the
    layout prints on it) where it is one letter, digit or punctuation mark; else ``key``. The
    keypad keeps its codes."""
    if KEY_KP_0 <= key <= KEY_KP_EQUAL or not name or len(name) != 1:
        return key
    c = name.lower()
    if "a" <= c <= "z":
        return KEY_A + ord(c) - ord("a")
    if "0" <= c <= "9":
        return KEY_0 + ord(c) - ord("0")
    return _PUNCTUATION.get(c, key)


# glfw.h's modifier keys: left/right shift, control, alt, super.
MODIFIER_KEYS = frozenset((340, 341, 342, 343, 344, 345, 346, 347))
PRESS, RELEASE = 1, 0


class KeyEvents:
    """glfw's key and character events, handed to imgui a frame's worth at a time.

    imgui applies every queued event of a frame before the widgets read them (its trickling
    splits a frame only where one key changes twice), so a chord released as a keyboard or
    xdotool releases it, Ctrl up before A up, reached it as "A down, Ctrl up" in one frame when
    both came in one poll (a slow frame): the text field saw a plain 'a' and Ctrl+A did nothing
    (1 in 4 tries under Xvfb). Here a modifier that changes after a key went down in the same
    frame waits for the next frame, so the key is seen with the modifiers it was pressed with.
    Every input event goes through this one queue, in the order glfw gave it: keys, characters,
    mouse buttons, cursor motions and the wheel. (With only the keys queued, a fast Ctrl+click
    reached imgui as a click before the Ctrl: a plain click that set the slider, 2 in 6 tries
    under heavy frames.) A mouse press counts as a press: a modifier that changes after it waits
    too. Pure: each event is ``("key", key, scancode, action, mods)``, ``("char", codepoint)``,
    ``("button", button, action, mods)``, ``("cursor", x, y)`` or ``("scroll", dx, dy)``.
    """

    def __init__(self):
        self.pending: list[tuple] = []

    def key(self, key: int, scancode: int, action: int, mods: int) -> None:
        self.pending.append(("key", key, scancode, action, mods))

    def char(self, codepoint: int) -> None:
        self.pending.append(("char", codepoint))

    def button(self, button: int, action: int, mods: int) -> None:
        self.pending.append(("button", button, action, mods))

    def cursor(self, x: float, y: float) -> None:
        self.pending.append(("cursor", x, y))

    def scroll(self, dx: float, dy: float) -> None:
        self.pending.append(("scroll", dx, dy))

    def take_frame(self) -> list[tuple]:
        """The events for this frame: all pending ones up to a modifier change that follows a
        non-modifier key's or a mouse button's press among them; the rest stay for the next frame."""
        pressed = False
        for i, event in enumerate(self.pending):
            if event[0] == "button":
                pressed = pressed or event[2] == PRESS
                continue
            if event[0] != "key":
                continue
            if event[1] in MODIFIER_KEYS:
                if pressed:
                    taken, self.pending = self.pending[:i], self.pending[i:]
                    return taken
            elif event[3] != RELEASE:   # a press or its repeat
                pressed = True
        taken, self.pending = self.pending, []
        return taken
