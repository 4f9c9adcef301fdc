"""'export glTF' with the mesh file's own materials, through the panel's real controls. Run by
tests/test_export_file_materials.py as ``alight edit --new --ui-test tests/editor_ui_checks_export.py``
(the Dear ImGui Test Engine against the real window under Xvfb); not collected by pytest.

The test writes ``two_parts.glb`` (two parts, two textured materials) into the run's folder
(ALIGHT_UI_TEST_OUT); this opens it, exports it with its own materials shown and with the panel's,
and leaves both files there for the test to render against the original.
"""

from __future__ import annotations

import json
import os

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")


def test_export_keeps_the_files_own_materials_and_the_panels_when_they_are_off(ctx):
    from alight.frontends.editor.ui_test import editor, files_done

    s = editor().state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    # Enter in the field opens it (as 'open mesh' would: a click after it opened the file a second
    # time, racing the first; a CI run saw the click miss the button and the export's message
    # replaced by a late 'opened mesh')
    ctx.item_input_value("**/mesh", os.path.join(OUT, "two_parts.glb"))
    files_done(ctx)
    assert s.mesh_spec == os.path.join(OUT, "two_parts.glb"), (s.mesh_spec, s.error)
    assert s.use_file_materials and not s.error, (s.error, s.message)
    own = os.path.join(OUT, "from_editor.gltf")
    ctx.item_input_value("**/glTF file", own)
    ctx.item_click("**/export glTF")
    files_done(ctx)
    assert not s.error, s.error
    assert s.message == f"exported {own}", s.message   # nothing left out: no note
    doc = json.loads(open(own, encoding="utf-8").read())
    assert [m["name"] for m in doc["materials"]] == ["painted", "bumpy metal"], doc["materials"]
    ctx.item_uncheck("**/mesh file's own materials and maps")   # today's export: the panel's on every part
    panel = os.path.join(OUT, "panel_material.glb")
    ctx.item_input_value("**/glTF file", panel)
    ctx.item_click("**/export glTF")
    files_done(ctx)
    assert s.message == f"exported {panel}", s.message
    ctx.combo_click("preview mesh/sphere")
    ctx.item_close("**/Environment")
