"""The editor guide's pictures of the library, the thumbnails and the checkerboard, taken by the
Dear ImGui Test Engine inside the real window (``alight edit --ui-test``), at 1280x720:

    xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/alight edit --new --size 1280x720 \\
        --ui-test tools/editor_library_images.py

Writes docs/editor_library.png and docs/editor_checker.png (ALIGHT_DATA_DIR and ALIGHT_CACHE_DIR
pointed at a scratch folder keep the user's library out of it)."""

from pathlib import Path

from imgui_bundle.immapp.testing import capture

from alight.frontends.editor.ui_test import editor

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _wait_for_thumbnails(ctx) -> None:
    import time

    end = time.monotonic() + 600
    while time.monotonic() < end:
        ctx.yield_()
        if not editor().thumbnails.pending():
            return


def test_library_picture(ctx):
    ctx.set_ref("alight")
    for preset, roughness, name in (("copper", 0.35, "satin_copper"), ("gold", 0.6, "brushed_gold")):
        ctx.item_click(f"**/{preset}")
        ctx.item_input_value("**/roughness", roughness)
        ctx.item_input_value("**/library name", name)
        ctx.item_click("**/save to library")
    ctx.item_click("**/satin_copper##library")
    _wait_for_thumbnails(ctx)
    ctx.mouse_move_to_pos(__import__("imgui_bundle").imgui.ImVec2(200, 600))
    ctx.yield_(3)
    capture(ctx, str(DOCS / "editor_library.png"))


def test_checker_picture(ctx):
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.combo_click("background/transparent")
    ctx.item_close("**/Environment")
    ctx.item_open("**/Display & camera")
    ctx.yield_(3)
    capture(ctx, str(DOCS / "editor_checker.png"))
    ctx.item_close("**/Display & camera")
