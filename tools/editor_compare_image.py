"""Takes docs/editor_compare.png: the editor's compare split operated through its panel by the
Dear ImGui Test Engine, captured by the engine (the whole window, the panel's Compare section open).

    xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/alight edit --new --size 1100x620 \\
        --ui-test tools/editor_compare_image.py
"""

from pathlib import Path

from alight.frontends.editor.ui_test import editor, view

OUT = Path(__file__).resolve().parents[1] / "docs" / "editor_compare.png"


def test_compare_picture(ctx):
    from imgui_bundle import imgui
    from imgui_bundle.immapp.testing import capture

    win = editor()
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_input_value("**/roughness", 0.3)
    ctx.item_close("**/Performance")
    ctx.item_open("**/Compare")
    ctx.combo_click("compare/material")
    ctx.item_click("**/snapshot A")
    ctx.item_click("**/silver")
    ctx.item_close("**/Material")   # the Compare section in sight
    view(ctx)
    ctx.mouse_click_on_void()
    view_w = imgui.get_io().display_size.x - win.panel_width()
    h = imgui.get_io().display_size.y
    ctx.mouse_move_to_pos(imgui.ImVec2(0.5 * view_w, 0.5 * h))
    ctx.mouse_drag_with_delta(imgui.ImVec2(-0.08 * view_w, 0))   # the divider, dragged left
    ctx.mouse_move_to_pos(imgui.ImVec2(0.9 * view_w, 0.9 * h))
    ctx.yield_(10)
    capture(ctx, str(OUT))
    assert OUT.is_file()
