"""EXT_mesh_gpu_instancing, KHR_materials_variants, KHR_node_visibility and KHR_xmp_json_ld as
other tools write them, on real models (Duck, CesiumMilkTruck), through ``alight render``.

The files come from glTF Transform (its CLI's ``instance``; its library, @gltf-transform/core and
/extensions, driven by tests/gltf_transform_edit.cjs) and gltfpack (``-mi``, and its pass over a
variants file), installed into tools/node as tools/setup.sh does; without npm (or node) these
tests skip. Each file renders like a control written by the same tool without the extension.

Instanced copies render like the same copies on plain nodes within 1.5% relMAE, not bit for bit:
the instances are one part, the plain nodes twenty, and the anisotropic filtering level is chosen
per part from its texel footprint (alight.core.texture_footprint), so a few small ducks' textures
are filtered at another level. Measured here (96 px): 0.0066 for glTF Transform's file (0.0066
quantized), 0.0072 for gltfpack's (0.0096 with -cc); with the level held at 8 for every part
glTF Transform's pair differs by 3e-6.
"""

from __future__ import annotations

import json
import os
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest
from tests.files_cases import rel_mae, render_exr
from tests.test_gltf_compressed import REPO, npm_tool, run_tool  # noqa: F401 (npm_tool is a fixture)

VIEW = ("--elevation", "30")
SCRIPT = Path(__file__).with_name("gltf_transform_edit.cjs")


@pytest.fixture(scope="session")
def edit(npm_tool):  # noqa: F811
    """``edit(job, input, output, *args)``: tests/gltf_transform_edit.cjs with glTF Transform's
    library from tools/node (installed with @gltf-transform/cli when missing)."""
    if shutil.which("node") is None:
        pytest.skip("node is not installed: glTF Transform (node) writes this test's file")
    npm_tool("gltf-transform")

    def run(job: str, source: Path, out: Path, *args) -> Path:
        env = {**os.environ, "NODE_PATH": str(REPO / "tools" / "node" / "node_modules")}
        done = subprocess.run(["node", str(SCRIPT), job, str(source), str(out), *map(str, args)],
                              capture_output=True, text=True, env=env)
        assert done.returncode == 0, done.stderr
        return out

    return run


def gltf_json(path: Path) -> dict:
    data = path.read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    return json.loads(data[20:20 + length])


def render(path: Path, *args, out: Path | None = None) -> tuple[np.ndarray, list[str]]:
    """``alight render --mesh PATH ARGS``, the EXR written beside PATH (or into ``out``)."""
    exr = (out or path.parent) / f"{path.stem}{'_'.join(args)}.exr"
    return render_exr(exr, "--mesh", path, *VIEW, *args)


def assert_same_copies(instanced: Path, plain: Path, limit: float = 0.015) -> None:
    a, warn_a = render(instanced)
    b, warn_b = render(plain)
    assert warn_a == warn_b == []
    assert (a[..., 3] > 0).mean() > 0.05
    assert np.count_nonzero((a[..., 3] > 0) != (b[..., 3] > 0)) <= 5   # every copy drawn, where it stands
    assert rel_mae(a, b) < limit


# --- EXT_mesh_gpu_instancing -----------------------------------------------------------------

@pytest.mark.parametrize("quantize", [False, True])
def test_gltf_transform_instance_renders_like_its_nodes(tmp_path, shared_data, edit, npm_tool, quantize):  # noqa: F811
    """Duck's mesh on 20 nodes, turned and (non-uniformly) scaled; ``gltf-transform instance``
    turns them into one node with 20 instances (TRANSLATION, ROTATION, SCALE). ``quantize``
    then runs ``gltf-transform quantize`` on both files (the mesh's dequantizing transform moves
    into the instances)."""
    tool = npm_tool("gltf-transform")
    nodes = edit("scatter", shared_data / "models" / "Duck.glb", tmp_path / "nodes.glb", 20)
    run_tool(tool, "instance", nodes, tmp_path / "instanced.glb")
    instanced = tmp_path / "instanced.glb"
    if quantize:
        run_tool(tool, "quantize", instanced, tmp_path / "instanced_q.glb")
        run_tool(tool, "quantize", nodes, tmp_path / "nodes_q.glb")
        instanced, nodes = tmp_path / "instanced_q.glb", tmp_path / "nodes_q.glb"
        assert "KHR_mesh_quantization" in gltf_json(instanced)["extensionsRequired"]
    doc = gltf_json(instanced)
    (node,) = [n for n in doc["nodes"] if "mesh" in n]
    assert set(node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]) == {"TRANSLATION", "ROTATION", "SCALE"}
    assert_same_copies(instanced, nodes)


@pytest.mark.parametrize("flags", [("-mi",), ("-mi", "-cc")])
def test_gltfpack_instancing_renders_like_its_nodes(tmp_path, shared_data, edit, npm_tool, flags):  # noqa: F811
    """gltfpack -mi: the instances over KHR_mesh_quantization's quantized mesh (required), against
    gltfpack's own file without -mi (the same quantization, on plain nodes). With -cc the
    instances' accessors are EXT_meshopt_compression streams too (ROTATION normalized int16
    through the QUATERNION filter, TRANSLATION and SCALE through EXPONENTIAL)."""
    if "-cc" in flags:
        pytest.importorskip("meshopt")
    nodes = edit("scatter", shared_data / "models" / "Duck.glb", tmp_path / "nodes.glb", 20)
    gltfpack = npm_tool("gltfpack")
    run_tool(gltfpack, "-i", nodes, "-o", tmp_path / "instanced.glb", *flags)
    run_tool(gltfpack, "-i", nodes, "-o", tmp_path / "plain.glb", *flags[1:])
    doc = gltf_json(tmp_path / "instanced.glb")
    assert {"EXT_mesh_gpu_instancing", "KHR_mesh_quantization"} <= set(doc["extensionsRequired"])
    assert sum("mesh" in n for n in doc["nodes"]) == 1
    assert sum("mesh" in n for n in gltf_json(tmp_path / "plain.glb")["nodes"]) == 20
    if "-cc" in flags:
        assert {"QUATERNION", "EXPONENTIAL"} <= {(v.get("extensions") or {}).get("EXT_meshopt_compression", {})
                                                 .get("filter") for v in doc["bufferViews"]}
    assert_same_copies(tmp_path / "instanced.glb", tmp_path / "plain.glb")


# --- KHR_materials_variants ------------------------------------------------------------------

def test_gltf_transform_variants_render_like_their_controls(tmp_path, shared_data, edit):
    """KHRMaterialsVariants on Duck: 'red' (a plain material) and 'metal' (the textured material,
    cloned, metal and smooth). ``--variant NAME`` renders exactly as the file with that material
    set on the primitive; no --variant, as the file without the extension."""
    duck = shared_data / "models" / "Duck.glb"
    variants = edit("variants", duck, tmp_path / "variants.glb")
    assert [v["name"] for v in gltf_json(variants)["extensions"]["KHR_materials_variants"]["variants"]] \
        == ["red", "metal"]
    own, warn = render(variants)
    assert warn == []
    np.testing.assert_array_equal(own, render(edit("copy", duck, tmp_path / "own.glb"))[0])
    pictures = [own]
    for name in ("red", "metal"):
        picture, warn = render(variants, "--variant", name)
        assert warn == []
        np.testing.assert_array_equal(picture, render(edit("variant-control", duck, tmp_path / f"{name}.glb",
                                                           name))[0])
        pictures.append(picture)
    assert rel_mae(pictures[1], own) > 0.2 and rel_mae(pictures[2], own) > 0.05   # each variant shows


def test_gltfpack_keeps_variants(tmp_path, shared_data, edit, npm_tool):  # noqa: F811
    """gltfpack over glTF Transform's variants file keeps KHR_materials_variants (quantized mesh,
    the texture's KHR_texture_transform): each ``--variant`` renders like gltfpack's own file of
    that variant's control. 'metal' bit for bit; 'red' within 1% (measured 0.0035): gltfpack drops
    the UVs the control's untextured material does not read, so its vertices are quantized and
    welded apart from the variants file's (each differs from the unpacked control by 0.004)."""
    duck = shared_data / "models" / "Duck.glb"
    gltfpack = npm_tool("gltfpack")
    run_tool(gltfpack, "-i", edit("variants", duck, tmp_path / "variants.glb"), "-o", tmp_path / "packed.glb")
    assert "KHR_materials_variants" in gltf_json(tmp_path / "packed.glb")["extensions"]
    for name, limit in (("red", 0.01), ("metal", 0.0)):
        control = tmp_path / f"{name}_packed.glb"
        run_tool(gltfpack, "-i", edit("variant-control", duck, tmp_path / f"{name}.glb", name), "-o", control)
        picture, warn = render(tmp_path / "packed.glb", "--variant", name)
        assert warn == []
        reference = render(control)[0]
        assert (picture[..., 3] > 0).mean() > 0.1
        assert rel_mae(picture, reference) <= limit


# --- KHR_node_visibility ---------------------------------------------------------------------

def test_gltf_transform_hidden_node_renders_like_the_file_without_it(tmp_path, shared_data, edit):
    """KHRNodeVisibility on CesiumMilkTruck's nodes[1] (the group holding one pair of wheels):
    exactly as the truck with that node removed; shown, the wheels are there."""
    truck = shared_data / "models" / "CesiumMilkTruck.glb"
    hidden = edit("hide", truck, tmp_path / "hidden.glb", 1)
    assert gltf_json(hidden)["nodes"][1]["extensions"]["KHR_node_visibility"] == {"visible": False}
    a, warn_a = render(hidden)
    b, warn_b = render(edit("drop", truck, tmp_path / "dropped.glb", 1))
    assert warn_a == [w.replace("dropped.glb", "hidden.glb") for w in warn_b]   # only the animation's line
    np.testing.assert_array_equal(a, b)
    shown, _ = render(edit("copy", truck, tmp_path / "shown.glb"))
    assert np.count_nonzero(shown[..., 3] > 0) > np.count_nonzero(a[..., 3] > 0) + 20


# --- KHR_xmp_json_ld -------------------------------------------------------------------------

def test_gltf_transform_xmp_changes_no_pixel_and_says_nothing(tmp_path, shared_data, edit):
    """KHRXMP packets on Duck's asset (the root), a node, its mesh and its material: bit for bit
    the original Duck.glb, with no warning."""
    duck = shared_data / "models" / "Duck.glb"
    xmp = edit("xmp", duck, tmp_path / "xmp.glb")
    doc = gltf_json(xmp)
    assert len(doc["extensions"]["KHR_xmp_json_ld"]["packets"]) == 4
    assert all("KHR_xmp_json_ld" in doc[key][0]["extensions"] for key in ("nodes", "meshes", "materials"))
    a, warn = render(xmp)
    assert warn == []
    np.testing.assert_array_equal(a, render(duck, out=tmp_path)[0])
