"""The compare split's plain parts (app/frontends/editor/compare.py): what each half draws, the
divider's grab, the session's dict and its bad values, --script. The split view itself is
operated through the real UI in tests/editor_ui_checks.py."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from alight.core.material import Material
from alight.core.scene import Scene
from alight.errors import AlightError
from alight.exchange.presets import load_preset
from alight.frontends.editor import compare
from alight.frontends.editor.compare_view import composite_rows, split_column
from alight.frontends.editor.state import EditorState


def test_each_half_draws_its_own_material_or_model():
    scene = Scene(material=load_preset("silver"), ibl_model="alight")
    c = compare.CompareState(mode="material")
    assert not c.active                                     # A not chosen: no split
    c.a_material = load_preset("copper")
    assert c.active and compare.a_scene(c, scene).material.name == "copper"
    assert compare.a_scene(c, scene).ibl_model == "alight"
    c = compare.CompareState(mode="ibl model", a_ibl_model="lecture")
    a = compare.a_scene(c, scene)
    assert (a.material, a.ibl_model) == (scene.material, "lecture")
    assert not compare.CompareState().active


def test_the_divider_is_grabbed_near_its_line_only():
    c = compare.CompareState(mode="reference", divider=0.5)
    assert compare.near_divider(c, 200 + compare.GRAB_PX, 100, 400, 300)
    assert not compare.near_divider(c, 200 + compare.GRAB_PX + 1, 100, 400, 300)
    assert not compare.near_divider(c, 200, 300, 400, 300)   # below the view
    assert compare.divider_from_mouse(-20, 400) == 0.0 and compare.divider_from_mouse(500, 400) == 1.0


def test_composite_takes_a_left_of_the_split_and_b_right():
    a = np.zeros((2, 10, 4), np.uint8)
    b = np.full((2, 10, 4), 200, np.uint8)
    out = composite_rows(a, b, 0.3)
    assert split_column(0.3, 10) == 3
    assert (out[:, :3] == 0).all() and (out[:, 3:] == 200).all()
    a[:, 1, 3] = 255   # only column 1 of A is covered: with B behind A, the rest is B's
    out = composite_rows(a, b, 0.3, b_behind_a=True)
    assert (out[:, 1] == a[:, 1]).all() and (out[:, 0] == 200).all() and (out[:, 2] == 200).all()


def test_the_compare_state_goes_through_the_session_dict():
    c = compare.CompareState(mode="material", divider=0.3, a_material=load_preset("gold"), a_label="preset gold",
                             a_ibl_model="karis", dragging=True)
    back = compare.from_dict(json.loads(json.dumps(compare.to_dict(c))), "session.json")
    assert back == dataclasses.replace(c, dragging=False)


@pytest.mark.parametrize("field, value, says", [
    ("mode", "sideways", "mode 'sideways'"),
    ("divider", "half", "divider"),
    ("a_ibl_model", "magic", "a_ibl_model 'magic'"),
    ("a_material", {"rougness": 0.5}, "rougness"),
])
def test_a_bad_compare_in_the_session_is_one_line(field, value, says):
    data = compare.to_dict(compare.CompareState(mode="material", a_material=Material()))
    data[field] = value
    with pytest.raises(AlightError) as err:
        compare.from_dict(data, "session.json")
    assert says in str(err.value) and "session.json" in str(err.value) and "\n" not in str(err.value)


def test_a_bad_compare_in_the_session_file_keeps_the_rest(tmp_path, monkeypatch):
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import restore_session, save_session, session_path

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path))
    state = EditorState()
    state.compare = compare.CompareState(mode="ibl model", divider=0.7)
    state.env_rotation_deg = 30.0
    save_session(state, OrbitCamera())
    fresh = EditorState()
    assert restore_session(fresh, OrbitCamera()) == ""
    assert (fresh.compare.mode, fresh.compare.divider) == ("ibl model", 0.7)
    data = json.loads(session_path().read_text())
    data["compare"]["mode"] = "sideways"
    session_path().write_text(json.dumps(data))
    fresh = EditorState()
    warning = restore_session(fresh, OrbitCamera())
    assert "mode 'sideways'" in warning and fresh.compare.mode == "off" and fresh.env_rotation_deg == 30.0


def test_script_edits_set_the_split():
    state = EditorState()
    state.material = load_preset("copper")
    for edit in ("compare=material", "compare_a=snapshot", "compare_divider=0.25", "compare_a_ibl_model=karis"):
        state.apply_edit(edit)
    c = state.compare
    assert (c.mode, c.divider, c.a_label, c.a_ibl_model) == ("material", 0.25, "snapshot of copper", "karis")
    state.apply_edit("compare_a=gold")
    assert c.a_material.name == "gold" and c.a_label == "preset gold"
    with pytest.raises(AlightError, match="compare 'sideways'"):
        state.apply_edit("compare=sideways")


def test_the_reference_half_is_for_the_sphere_only():
    state = EditorState()
    assert compare.reference_problem(state) == ""
    state.mesh_spec = "shader_ball"
    assert "sphere" in compare.reference_problem(state)


def _material_plane(path):
    """A glTF plane with a material of its own (red), so the editor ticks 'own materials'."""
    from tests.gltf_builder import FLOAT, UINT, Gltf, grid_plane

    g = Gltf()
    pos, nor, _, idx = grid_plane(2, 2.0)
    mat = g.material(pbrMetallicRoughness={"baseColorFactor": [1.0, 0.0, 0.0, 1.0]})
    g.mesh([{"attributes": {"POSITION": g.accessor(pos, FLOAT, bounds=True), "NORMAL": g.accessor(nor)},
             "indices": g.accessor(idx.reshape(-1), UINT), "material": mat}])
    return g.save(path)


def test_a_snapshot_keeps_its_maps_and_a_preset_has_none(tmp_path):
    """Compare's A is the snapshot with the maps it was taken with: B's later maps (or none) never
    reach it; a preset for A has no maps; A is drawn on every part even where B shows a mesh
    file's own materials."""
    from PIL import Image

    brown = tmp_path / "wood_BaseColor.png"
    Image.fromarray(np.full((8, 8, 3), (120, 70, 30), np.uint8)).save(brown)
    state = EditorState()
    state.material = load_preset("silver")
    state.open_texture_set([str(brown)])
    assert state.texture_maps.paths() == {"base_color": str(brown)}
    state.apply_edit("compare=material")
    state.apply_edit("compare_a=snapshot")
    state.apply_preset(load_preset("gold"))      # B: gold, its maps cleared
    assert state.texture_maps.paths() == {}
    a = compare.a_scene(state.compare, state.scene(None))
    assert a.texture_maps.paths() == {"base_color": str(brown)} and str(brown) in a.texture_images
    state.open_texture_set([str(brown)])         # B has maps again; a preset for A has none
    state.apply_edit("compare_a=gold")
    a = compare.a_scene(state.compare, state.scene(None))
    assert a.material.name == "gold" and a.texture_maps.paths() == {} and not a.use_file_materials


def test_a_snapshots_maps_and_the_own_materials_box_survive_the_session(tmp_path, monkeypatch):
    from PIL import Image

    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import restore_session, save_session

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path))
    brown = tmp_path / "wood_BaseColor.png"
    Image.fromarray(np.full((8, 8, 3), (120, 70, 30), np.uint8)).save(brown)
    plane = _material_plane(tmp_path / "red_plane.gltf")
    state = EditorState()
    state.load_mesh(str(plane))
    assert state.use_file_materials               # the file has a material: ticked on loading
    state.use_file_materials = False              # the artist unticks it
    state.open_texture_set([str(brown)])
    state.apply_edit("compare=material")
    state.apply_edit("compare_a=snapshot")
    save_session(state, OrbitCamera())
    fresh = EditorState()
    assert restore_session(fresh, OrbitCamera()) == ""
    assert not fresh.use_file_materials           # as left, not as the mesh's default
    fresh.texture_maps = dataclasses.replace(fresh.texture_maps, base_color="")
    fresh.revert()                                # back to the restored material with its maps
    assert fresh.texture_maps.paths() == {"base_color": str(brown)}
    assert fresh.compare.a_texture_maps.paths() == {"base_color": str(brown)}
    np.testing.assert_array_equal(fresh.compare.a_texture_images[str(brown)],
                                  state.compare.a_texture_images[str(brown)])


def test_undo_while_split_names_b_and_what_changed_and_leaves_a():
    """Undo acts on B alone; the row says the step ('roughness 0.4 -> 0.3'), and with nothing to
    undo that A's choice and the mode are no undo steps (it said 'nothing to undo' only)."""
    from alight.frontends.editor.state import History, look_change

    s = EditorState()
    s.apply_preset(load_preset("copper"))
    history = History(s.look)
    s.compare.mode = "material"
    compare.take_snapshot(s.compare, s)
    s.step_history(history)
    assert s.message.startswith("nothing to undo on B (A's snapshot"), s.message
    s.material = dataclasses.replace(s.material, roughness=0.4)
    history.settle(s.look, False)
    s.step_history(history)
    assert s.message == "undo on B: copper (roughness 0.4 -> 0.3)" and s.compare.a_material.name == "copper"
    s.compare.mode = "off"
    s.step_history(history, redo=True)
    assert s.message == "redo: copper (roughness 0.3 -> 0.4)", s.message
    gold = (load_preset("gold"), s.texture_maps)
    assert look_change(s.look, gold) == "was copper"
    many = dataclasses.replace(s.material, metallic=0.5, roughness=0.9, ior=1.6, transmission=0.5)
    assert look_change(s.look, (many, s.texture_maps)).endswith(" more")
