"""Widgets every part of the panel draws the same way.

Tooltips, all through ``tooltip``: wrapped at a readable width that fits the
window (imgui's own ``set_tooltip`` never wraps: the 'ground' checkbox's line was wider than a
1280 px window and cut at its right edge). tests/test_editor_ui_widgets.py checks that no other
code calls ``set_tooltip``.

Fields naming something to open or load (env file, mesh, map file, texture set), all through
``text_field``: Enter in the field does what the button beside it does (users expect it; the
fields ignored it). Fields naming a file to write (preset file, glTF file, turntable file, the
library's name) keep Enter inert: the preset field serves both 'save' and 'load', and a
keystroke should not write over a file.
"""

from __future__ import annotations

# Wrap width in font heights: about 60 characters a line (416 px with imgui's 13 px font).
WRAP_EM = 32.0


def wrap_width(font_size: float, display_width: float, padding: float) -> float:
    """Where a tooltip's text wraps (tooltip-local x): WRAP_EM font heights, less where the
    window is narrower than that with the tooltip's padding on both sides."""
    return max(8.0 * font_size, min(WRAP_EM * font_size, display_width - 4.0 * padding))


def tooltip(text: str) -> None:
    """A tooltip for the item just drawn (call where ``imgui.is_item_hovered()``)."""
    from imgui_bundle import imgui

    imgui.begin_tooltip()
    imgui.push_text_wrap_pos(wrap_width(imgui.get_font_size(), imgui.get_io().display_size.x,
                                        imgui.get_style().window_padding.x))
    imgui.text_unformatted(text)
    imgui.pop_text_wrap_pos()
    imgui.end_tooltip()


def text_field(label: str, value: str) -> tuple[str, bool]:
    """An input field: (its text, whether Enter was pressed in it this frame). The text follows
    each keystroke as imgui.input_text's does; the caller applies the field on Enter as on a
    click of the button beside it."""
    from imgui_bundle import imgui

    entered, value = imgui.input_text(label, value, imgui.InputTextFlags_.enter_returns_true)
    return value, bool(entered)


def note(text: str) -> None:
    """A grey line of help, wrapped at the panel's edge (not cut there in a narrow window: at
    700 px 'zoom: wheel' was past the edge)."""
    from imgui_bundle import imgui

    imgui.push_text_wrap_pos(0.0)
    imgui.text_disabled(text)
    imgui.pop_text_wrap_pos()
