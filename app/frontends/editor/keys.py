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
