"""KHR_node_visibility: a node whose ``visible`` is false is not drawn, nor are its lights or
any of its descendants (even one marked visible); its cameras stay. Through the real command,
by equivalence: a file with hidden nodes renders as a control the test writes without them."""

from __future__ import annotations

import numpy as np
import pytest

from tests.files_cases import render_exr, run
from tests.gltf_builder import FLOAT, UINT, Gltf, grid_plane

VIEW = ("--elevation", "30", "--distance", "6", "--target", "0,0,0", "--env", "studio")


def _plane(g: Gltf, colour) -> dict:
    pos, nor, uv, idx = grid_plane(2, 2.0)
    return {"attributes": {"POSITION": g.accessor(pos, FLOAT, bounds=True), "NORMAL": g.accessor(nor)},
            "indices": g.accessor(idx.reshape(-1), UINT),
            "material": g.material(pbrMetallicRoughness={"baseColorFactor": [*colour, 1.0],
                                                         "metallicFactor": 0.0, "roughnessFactor": 0.5})}


def scene(path, hidden: bool | None):
    """A grey plane, and (``hidden`` not None) a group node beside it holding a red plane, a
    child marked visible under it with a blue plane, and a strong red point light; the group
    hidden (``hidden`` True) or marked visible (False). None: the grey plane alone."""
    g = Gltf()
    g.mesh([_plane(g, (0.6, 0.6, 0.6))])
    if hidden is not None:
        g.doc["meshes"].append({"primitives": [_plane(g, (0.9, 0.1, 0.1))]})
        red = len(g.doc["meshes"]) - 1
        g.doc["meshes"].append({"primitives": [_plane(g, (0.1, 0.1, 0.9))]})
        blue = len(g.doc["meshes"]) - 1
        nodes = g.doc["nodes"]
        nodes.append({"mesh": blue, "translation": [0.0, 0.0, 1.0],
                      "extensions": {"KHR_node_visibility": {"visible": True}}})
        nodes.append({"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0.0, 0.0, 2.0]})
        nodes.append({"mesh": red, "translation": [0.5, 0.0, 0.5], "children": [1, 2],
                      "extensions": {"KHR_node_visibility": {"visible": not hidden}}})
        g.doc["scenes"][0]["nodes"].append(3)
        g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1.0, 0.0, 0.0],
                                                                   "intensity": 40.0}]}}
        g.use("KHR_node_visibility", "KHR_lights_punctual")
    return g.save(path)


def test_a_hidden_node_and_everything_under_it_is_not_drawn(tmp_path):
    hidden, warned = render_exr(tmp_path / "hidden.exr", "--mesh", scene(tmp_path / "hidden.glb", True), *VIEW)
    plain, _ = render_exr(tmp_path / "plain.exr", "--mesh", scene(tmp_path / "plain.glb", None), *VIEW)
    shown, _ = render_exr(tmp_path / "shown.exr", "--mesh", scene(tmp_path / "shown.glb", False), *VIEW)
    assert warned == [], warned
    assert (plain[..., 3] > 0).mean() > 0.05
    np.testing.assert_array_equal(hidden, plain)
    # The same file with the group marked visible draws the red and blue planes and the light.
    assert np.abs(shown - plain).mean() > 0.01


def test_a_file_whose_every_mesh_is_hidden_is_one_error_line(tmp_path):
    g = Gltf()
    g.mesh([_plane(g, (0.5, 0.5, 0.5))], extensions={"KHR_node_visibility": {"visible": False}})
    g.use("KHR_node_visibility", required=True)
    path = g.save(tmp_path / "nothing.glb")
    proc = run("render", "--mesh", path, "--size", "32", "--out", tmp_path / "x.png")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "nothing.glb" in lines[0] and "KHR_node_visibility" in lines[0], lines
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("value", ["no", 0])
def test_a_visible_that_is_not_a_boolean_is_refused(tmp_path, value):
    g = Gltf()
    g.mesh([_plane(g, (0.5, 0.5, 0.5))], extensions={"KHR_node_visibility": {"visible": value}})
    g.use("KHR_node_visibility")
    path = g.save(tmp_path / "odd.glb")
    proc = run("render", "--mesh", path, "--size", "32", "--out", tmp_path / "x.png")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert "nodes[0].extensions.KHR_node_visibility.visible" in proc.stderr and "true or false" in proc.stderr, proc.stderr
