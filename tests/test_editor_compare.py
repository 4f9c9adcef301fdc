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
