"""A library entry named as a built-in preset (a material saved as 'gold.glb') does not pass for
the preset: the library lists it as 'gold (library)' with one warning line naming the file and the
name (in the library's box and on stderr), the F0 table's 'gold' stays the preset, and each click
applies its own material. Through the real UI: `alight edit --ui-test` with the Dear ImGui Test
Engine under Xvfb; the entry is written into the library folder as a copy from elsewhere would be."""

from __future__ import annotations

from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

CHECKS = """
from alight.frontends.editor.ui_test import editor

def test_an_entry_named_gold_is_told_apart_from_the_preset(ctx):
    import time
    from alight.core.material import Material
    from alight.exchange.presets import load_preset
    from alight.frontends.editor import library

    win = editor()
    s = win.state
    mine = Material(name="gold", base_color=(0.2, 0.5, 0.9), roughness=0.8)
    path = library.save_entry(mine, s.texture_maps, "gold")
    start = time.monotonic()
    while not win.panel.library.entries and time.monotonic() - start < 30:   # the box looks twice a second
        ctx.yield_()
    ctx.yield_(2)
    assert win.panel.library.clashes == [f"{path}: the library entry 'gold' has a built-in preset's name: "
                                         f"listed as 'gold (library)'; the F0 table's 'gold' is the preset"], \\
        win.panel.library.clashes
    ctx.set_ref("alight")
    ctx.item_click("**/gold (library)##library")
    assert s.material.base_color == mine.base_color and s.material.roughness == mine.roughness, s.material
    ctx.item_click("**/gold")
    assert s.material == load_preset("gold"), s.material
"""


def test_a_library_entry_named_as_a_preset_is_told_apart(display, tmp_path):
    file = tmp_path / "checks.py"
    file.write_text(CHECKS)
    result = ui_test(tmp_path, file, "--new", size="1280x720")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "1 passed, 0 failed" in result.stdout, result.stdout
    warnings = [line for line in result.stderr.splitlines() if "built-in preset's name" in line]
    assert len(warnings) == 1 and "gold.glb" in warnings[0], result.stderr
