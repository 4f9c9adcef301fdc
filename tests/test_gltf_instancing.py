"""EXT_mesh_gpu_instancing: a node's mesh drawn once per instance under node_world * T * R * S.
By equivalence through the real command: a file instancing one mesh N times (a rotation, a
non-uniform scale and a mirroring scale among them) renders like a file placing the same mesh
with N plain nodes carrying the same transforms under a parent with the instanced node's own."""

from __future__ import annotations

import numpy as np
import pytest

from tests.files_cases import rel_mae, render_exr, run
from tests.gltf_builder import FLOAT, SHORT, UINT, Gltf, checker

# (translation, rotation xyzw, scale) of each instance
_S = np.sqrt(0.5)
INSTANCES = [
    ((-1.6, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), (1.0, 1.0, 1.0)),
    ((0.0, 1.5, 0.0), (0.2, 0.5, 0.1, 0.84), (1.0, 1.0, 1.0)),
    ((1.6, 0.0, 0.3), (0.0, 0.0, 0.0, 1.0), (0.5, 1.2, 0.8)),              # non-uniform
    ((0.0, -1.5, 0.0), (0.0, _S, 0.0, _S), (-1.0, 0.7, 1.0)),              # mirroring, turned
]
NODE = {"translation": [0.2, 0.1, -0.3], "rotation": [0.0, 0.19509, 0.0, 0.98079], "scale": [0.9, 0.9, 0.9]}


def _quat(q):
    q = np.asarray(q, np.float64)
    return q / np.linalg.norm(q)


def _cube_primitive(g: Gltf) -> dict:
    """A rounded cube with a checker base colour, a bumpy normal map and its tangents; single-sided
    (its back faces culled), so a winding left unreversed under a mirroring transform shows. The
    maps are small enough to be magnified in the views below: the anisotropic filtering level
    is chosen per part from its minified area (alight.core.texture_footprint), and the instances
    are one part where the control's copies are four."""
    from alight.core.preview_meshes import rounded_cube

    part = rounded_cube(1.0).parts[0]
    uv = np.asarray(part.uvs, np.float64).copy()
    uv[:, 1] = 1.0 - uv[:, 1]                      # glTF's v runs down
    y, x = np.mgrid[0:8, 0:8] / 8.0
    bump = np.stack([0.5 + 0.35 * np.sin(6.28 * x), 0.5 + 0.35 * np.cos(6.28 * y), np.full_like(x, 0.9)], -1)
    normal_map = g.image((bump * 255).astype(np.uint8))
    base = g.image(checker(cells=4, size=8))
    material = g.material(pbrMetallicRoughness={"baseColorTexture": {"index": base}, "metallicFactor": 0.0,
                                                "roughnessFactor": 0.5},
                          normalTexture={"index": normal_map})
    tangents = np.asarray(part.tangents, np.float64)
    return {"attributes": {"POSITION": g.accessor(part.positions, FLOAT, bounds=True),
                           "NORMAL": g.accessor(part.normals), "TEXCOORD_0": g.accessor(uv),
                           "TANGENT": g.accessor(tangents)},
            "indices": g.accessor(part.indices.reshape(-1), UINT), "material": material}


def instanced_glb(path, rotation_as=FLOAT, counts=None, required=False):
    g = Gltf()
    prim = _cube_primitive(g)
    t = np.array([i[0] for i in INSTANCES], np.float64)
    r = np.array([_quat(i[1]) for i in INSTANCES], np.float64)
    s = np.array([i[2] for i in INSTANCES], np.float64)
    if counts is not None:
        t = t[:counts]
    rotation = (g.accessor(r, FLOAT) if rotation_as == FLOAT
                else g.accessor(np.round(r * 32767).astype(np.int16), SHORT, normalized=True))
    attributes = {"TRANSLATION": g.accessor(t, FLOAT), "ROTATION": rotation, "SCALE": g.accessor(s, FLOAT),
                  "_ID": g.accessor(np.arange(len(INSTANCES), dtype=np.float32), FLOAT)}
    g.mesh([prim], **NODE, extensions={"EXT_mesh_gpu_instancing": {"attributes": attributes}})
    g.use("EXT_mesh_gpu_instancing", required=required)
    return g.save(path)


def plain_glb(path):
    g = Gltf()
    prim = _cube_primitive(g)
    g.doc["meshes"].append({"primitives": [prim]})
    children = []
    for translation, rotation, scale in INSTANCES:
        g.doc["nodes"].append({"mesh": 0, "translation": list(translation),
                               "rotation": [float(x) for x in _quat(rotation)], "scale": list(scale)})
        children.append(len(g.doc["nodes"]) - 1)
    g.node(children=children, **NODE)
    return g.save(path)


VIEW = ("--elevation", "20", "--orbit", "25")


def test_instances_render_like_plain_nodes(tmp_path):
    a, warn_a = render_exr(tmp_path / "a.exr", "--mesh", instanced_glb(tmp_path / "inst.glb"), *VIEW, size=160)
    b, warn_b = render_exr(tmp_path / "b.exr", "--mesh", plain_glb(tmp_path / "plain.glb"), *VIEW, size=160)
    assert warn_a == [] and warn_b == []
    assert (a[..., 3] > 0).mean() > 0.1
    assert rel_mae(a, b) < 0.005




def test_instances_as_the_reader_gives_them(tmp_path):
    """Four copies in one part; normalized SHORT rotations give the float rotations' placement;
    every face of every copy winds counter-clockwise seen from outside (its normal points away
    from the copy's centre)."""
    from alight.exchange.meshes import load_mesh

    floats = load_mesh(str(instanced_glb(tmp_path / "f.glb"))).parts
    shorts = load_mesh(str(instanced_glb(tmp_path / "s.glb", rotation_as=SHORT))).parts
    plain = load_mesh(str(plain_glb(tmp_path / "p.glb"))).parts
    assert len(floats) == 1 and len(plain) == len(INSTANCES)
    part = floats[0]
    n = len(plain[0].positions)
    assert len(part.positions) == n * len(INSTANCES)
    for k, control in enumerate(plain):
        copy = slice(k * n, (k + 1) * n)
        np.testing.assert_allclose(part.positions[copy], control.positions, atol=1e-5)
        np.testing.assert_allclose(part.normals[copy], control.normals, atol=1e-5)
        np.testing.assert_allclose(part.tangents[copy], control.tangents, atol=1e-5)
        np.testing.assert_array_equal(part.indices[len(control.indices) * k:len(control.indices) * (k + 1)],
                                      control.indices + k * n)
        centre = control.positions.mean(axis=0)
        tri = part.positions[part.indices[len(control.indices) * k:len(control.indices) * (k + 1)]].astype(np.float64)
        face_n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        outward = np.einsum("ij,ij->i", face_n, tri.mean(axis=1) - centre)
        assert (outward > 0).mean() > 0.99, k
    np.testing.assert_allclose(shorts[0].positions, part.positions, atol=2e-4)


def test_a_file_requiring_instancing_loads(tmp_path):
    a, warn = render_exr(tmp_path / "a.exr", "--mesh", instanced_glb(tmp_path / "r.glb", required=True), *VIEW)
    assert warn == [] and (a[..., 3] > 0).mean() > 0.05


def test_mismatched_counts_refused_in_one_line(tmp_path):
    path = instanced_glb(tmp_path / "bad.glb", counts=3)
    out = tmp_path / "bad.png"
    proc = run("render", "--size", "32", "--quality", "low", "--mesh", path, "--out", out)
    assert proc.returncode == 2 and not out.exists() and "Traceback" not in proc.stderr
    (line,) = proc.stderr.strip().splitlines()
    assert line.startswith("alight: error:") and "bad.glb" in line and "EXT_mesh_gpu_instancing" in line
    assert "TRANSLATION 3" in line and "ROTATION 4" in line and "SCALE 4" in line


def test_instancing_on_a_skinned_node_draws_it_once_and_says_so(tmp_path):
    """A skin places its mesh by its joints (the node's own transform takes no part), so the
    instances have nothing to multiply: the skinned mesh is drawn once, with one warning line."""
    import json
    import struct

    from alight.exchange.meshes import load_mesh
    from tests.test_gltf_rest_pose import skin_files

    skinned, _ = skin_files(tmp_path)
    data = skinned.read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    doc = json.loads(data[20:20 + length])
    node = next(n for n in doc["nodes"] if "skin" in n)
    position = doc["meshes"][node["mesh"]]["primitives"][0]["attributes"]["POSITION"]   # a FLOAT VEC3 accessor
    node["extensions"] = {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": position}}}
    doc["extensionsUsed"] = ["EXT_mesh_gpu_instancing"]
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    rest = data[20 + length:]
    instanced = tmp_path / "skinned_instanced.glb"
    instanced.write_bytes(struct.pack("<III", 0x46546C67, 2, 20 + len(text) + len(rest))
                          + struct.pack("<II", len(text), 0x4E4F534A) + text + rest)
    plain, mesh = load_mesh(str(skinned)), load_mesh(str(instanced))
    assert len(mesh.warnings) == 1 and "EXT_mesh_gpu_instancing" in mesh.warnings[0] and "once" in mesh.warnings[0]
    assert [len(p.positions) for p in mesh.parts] == [len(p.positions) for p in plain.parts]
    np.testing.assert_array_equal(mesh.parts[0].positions, plain.parts[0].positions)
