"""Skins and morph targets in the rest pose a glTF file gives (glTF 2.0 sections 3.7.2.2 and
3.7.3), each by equivalence: a file using the feature renders like a file with the result baked
into plain positions (linear, 1% relMAE). Animations are not played: warned once, in one line."""

from __future__ import annotations

import numpy as np
import pytest
from tests.gltf_builder import UBYTE, USHORT, Gltf
from tests.test_gltf import assert_equivalent, render

from alight.core.scene import Camera
from alight.exchange.meshes import load_mesh

CAMERA = Camera(position=(3.0, 2.0, 5.0), target=(0.0, 0.3, 0.0), fov_y_deg=40.0, near=0.1, far=30.0)
MATERIAL = {"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.1, 1.0], "metallicFactor": 0.0,
                                     "roughnessFactor": 0.5}}


def box(nx: int = 4):
    """A unit cube of flat faces, each an (nx x nx) grid, so a bend shows: positions, normals, triangles."""
    pos, nrm, tri = [], [], []
    g = np.linspace(-1.0, 1.0, nx + 1)
    u, v = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    for axis in range(3):
        for sign in (-1.0, 1.0):
            p = np.zeros((len(u), 3))
            p[:, axis] = sign
            p[:, (axis + 1) % 3], p[:, (axis + 2) % 3] = u, v
            n = np.zeros(3)
            n[axis] = sign
            i = np.arange(nx)[:, None] * (nx + 1) + np.arange(nx)[None, :]
            a, b = i.ravel(), i.ravel() + nx + 1
            t = np.concatenate([np.stack([a, b, a + 1], 1), np.stack([a + 1, b, b + 1], 1)]) + sum(len(x) for x in pos)
            if sign < 0:
                t = t[:, ::-1]
            pos.append(p)
            nrm.append(np.tile(n, (len(p), 1)))
            tri.append(t)
    return (np.concatenate(pos).astype(np.float32), np.concatenate(nrm).astype(np.float32),
            np.concatenate(tri).astype(np.uint32))


def plain_file(path, positions, normals, tri, **node):
    g = Gltf()
    mat = g.material(**MATERIAL)
    g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals)},
             "indices": g.accessor(tri.ravel(), USHORT), "material": mat}], **node)
    return g.save(path)


def view(path):
    return render(path, camera=CAMERA)


# --- morph targets ---------------------------------------------------------------------------

def stretch_target(positions):
    """A displacement lifting the top half: y += 1.5 * max(y, 0)."""
    delta = np.zeros_like(positions)
    delta[:, 1] = 1.5 * np.maximum(positions[:, 1], 0.0)
    return delta


def shear_target(positions):
    delta = np.zeros_like(positions)
    delta[:, 0] = 0.6 * positions[:, 1]
    return delta


def morph_file(path, mesh_weights=None, node_weights=None, sparse: bool = False):
    pos, nrm, tri = box()
    g = Gltf()
    mat = g.material(**MATERIAL)
    targets = []
    for delta in (stretch_target(pos), shear_target(pos)):
        if sparse:
            moved = np.flatnonzero(np.abs(delta).sum(axis=1) > 0)
            targets.append({"POSITION": g.accessor(np.zeros_like(delta), sparse=(moved, delta[moved]), bounds=True)})
        else:
            targets.append({"POSITION": g.accessor(delta, bounds=True)})
    node = {} if node_weights is None else {"weights": list(node_weights)}
    g.mesh([{"attributes": {"POSITION": g.accessor(pos, bounds=True), "NORMAL": g.accessor(nrm)},
             "indices": g.accessor(tri.ravel(), USHORT), "material": mat, "targets": targets}], **node)
    if mesh_weights is not None:
        g.doc["meshes"][0]["weights"] = list(mesh_weights)
    return g.save(path)


def baked_file(path, weights):
    """The morphed positions written out; the normals the file gives are the base's (morph
    targets without NORMAL leave them as they are)."""
    pos, nrm, tri = box()
    moved = pos + weights[0] * stretch_target(pos) + weights[1] * shear_target(pos)
    return plain_file(path, moved.astype(np.float32), nrm, tri)


def test_mesh_weights_one_like_baked(tmp_path):
    assert_equivalent(view(morph_file(tmp_path / "m.glb", mesh_weights=[1.0, 0.0])),
                      view(baked_file(tmp_path / "b.glb", (1.0, 0.0))))


def test_node_weights_override_mesh_weights(tmp_path):
    assert_equivalent(view(morph_file(tmp_path / "m.glb", mesh_weights=[1.0, 0.0], node_weights=[0.25, 0.7])),
                      view(baked_file(tmp_path / "b.glb", (0.25, 0.7))))


def test_sparse_targets_blend_like_baked(tmp_path):
    assert_equivalent(view(morph_file(tmp_path / "m.glb", mesh_weights=[0.5, 1.0], sparse=True)),
                      view(baked_file(tmp_path / "b.glb", (0.5, 1.0))))


def test_no_weights_is_the_base_shape(tmp_path):
    assert_equivalent(view(morph_file(tmp_path / "m.glb")), view(baked_file(tmp_path / "b.glb", (0.0, 0.0))))


def test_morph_case_like_its_control(shared_data):
    cases = shared_data / "cases" / "with_controls"
    assert_equivalent(view(cases / "morph_mesh_weights_1.glb"), view(cases / "morph_ctrl_baked.glb"))


# --- skins -----------------------------------------------------------------------------------

def _trs(t=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), angle=0.0):
    """4x4 of a translation and a rotation about an axis; the glTF rotation quaternion (x, y, z, w)."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    c, s = np.cos(angle), np.sin(angle)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + s * k + (1 - c) * k @ k
    m[:3, 3] = t
    q = [*(axis * np.sin(angle / 2)), np.cos(angle / 2)]
    return m, [float(x) for x in q]


def skin_files(tmp_path):
    """A box bent by two joints (the upper joint turned and moved), its node moved and turned
    (which a skin ignores), inverse bind matrices that are not identity; and the box skinned in
    numpy (linear blend skinning), written as a plain mesh."""
    pos, nrm, tri = box()
    pos = pos * np.array([0.5, 1.0, 0.5], np.float32)
    upper = np.clip((pos[:, 1] + 0.5), 0.0, 1.0)          # 0 below y = -0.5, 1 above y = 0.5
    weights = np.stack([1.0 - upper, upper, np.zeros_like(upper), np.zeros_like(upper)], axis=1).astype(np.float32)
    joints = np.tile(np.array([0, 1, 0, 0], np.uint8), (len(pos), 1))
    bind = [np.eye(4), _trs((0.0, 0.3, 0.0))[0]]              # where each joint sat when bound
    ibm = [np.linalg.inv(b) for b in bind]
    root_m, root_q = _trs((0.0, -0.2, 0.0), (0, 1, 0), 0.3)
    local_m, local_q = _trs((0.1, 0.4, 0.0), (0, 0, 1), 0.5)  # the posed upper joint, relative to the root
    joint_world = [root_m, root_m @ local_m]
    mats = [jw @ ib for jw, ib in zip(joint_world, ibm)]
    per_vertex = np.einsum("nk,kij->nij", weights[:, :2].astype(np.float64), np.stack(mats))
    skinned = np.einsum("nij,nj->ni", per_vertex[:, :3, :3], pos) + per_vertex[:, :3, 3]
    cof = np.linalg.inv(per_vertex[:, :3, :3]).transpose(0, 2, 1)
    normals = np.einsum("nij,nj->ni", cof, nrm)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)

    g = Gltf()
    mat = g.material(**MATERIAL)
    prim = {"attributes": {"POSITION": g.accessor(pos, bounds=True), "NORMAL": g.accessor(nrm),
                           "JOINTS_0": g.accessor(joints, UBYTE), "WEIGHTS_0": g.accessor(weights)},
            "indices": g.accessor(tri.ravel(), USHORT), "material": mat}
    mesh_node = g.mesh([prim], translation=[2.0, 1.0, -1.0], rotation=[0.0, 0.0, 0.3826834, 0.9238795], skin=0)
    g.doc["scenes"][0]["nodes"].remove(mesh_node)
    g.doc["nodes"].append({"translation": [0.1, 0.4, 0.0], "rotation": local_q})            # joint 1
    g.doc["nodes"].append({"translation": [0.0, -0.2, 0.0], "rotation": root_q,              # joint 0
                           "children": [len(g.doc["nodes"]) - 1]})
    root = len(g.doc["nodes"]) - 1
    g.doc["nodes"].append({"children": [root, mesh_node]})   # the skinned node under a moved parent too
    g.doc["nodes"][-1]["translation"] = [0.0, 0.0, 0.0]
    g.doc["scenes"][0]["nodes"].append(len(g.doc["nodes"]) - 1)
    ibm_view = g._view(np.stack([m.T for m in ibm]).astype(np.float32).tobytes())
    g.doc["accessors"].append({"bufferView": ibm_view, "componentType": 5126, "count": 2, "type": "MAT4"})
    g.doc["skins"] = [{"joints": [root, root - 1], "inverseBindMatrices": len(g.doc["accessors"]) - 1}]
    skinned_path = g.save(tmp_path / "skinned.glb")
    return skinned_path, plain_file(tmp_path / "baked.glb", skinned.astype(np.float32), normals.astype(np.float32), tri)


def test_posed_skin_like_preskinned(tmp_path):
    skinned, baked = skin_files(tmp_path)
    assert load_mesh(str(skinned)).warnings == []
    assert_equivalent(view(skinned), view(baked))


def test_skin_case_like_its_control(shared_data):
    cases = shared_data / "cases" / "with_controls"
    assert_equivalent(view(cases / "skin_mesh_node_transform.glb"), view(cases / "skin_ctrl_unskinned.glb"))


def test_animations_warned_once_in_one_line(tmp_path):
    path = morph_file(tmp_path / "m.glb", mesh_weights=[1.0, 0.0])
    import json
    import struct

    data = path.read_bytes()
    n = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20:20 + n])
    g = Gltf()
    g.doc, g.blob = doc, bytearray(data[20 + n + 8:])
    time_view = g._view(np.array([0.0, 1.0], np.float32).tobytes())
    g.doc["accessors"].append({"bufferView": time_view, "componentType": 5126, "count": 2, "type": "SCALAR",
                               "min": [0.0], "max": [1.0]})
    t = len(g.doc["accessors"]) - 1
    value_view = g._view(np.array([0, 0, 1, 0], np.float32).tobytes())
    g.doc["accessors"].append({"bufferView": value_view, "componentType": 5126, "count": 4, "type": "SCALAR"})
    v = len(g.doc["accessors"]) - 1
    channel = {"sampler": 0, "target": {"node": 0, "path": "weights"}}
    g.doc["animations"] = [{"samplers": [{"input": t, "output": v}], "channels": [channel]} for _ in range(2)]
    animated = g.save(tmp_path / "animated.glb")
    mesh = load_mesh(str(animated))
    lines = [w for w in mesh.warnings if "animation" in w]
    assert len(lines) == 1 and "\n" not in lines[0] and "animated.glb" in lines[0], mesh.warnings
    assert_equivalent(view(animated), view(baked_file(tmp_path / "b.glb", (1.0, 0.0))))


@pytest.mark.parametrize("weights", [(1.0, 0.0), (0.3, 0.6)])
def test_morph_positions_are_exact(tmp_path, weights):
    """The loaded positions are the base plus the weighted targets (no render)."""
    (part,) = load_mesh(str(morph_file(tmp_path / "m.glb", mesh_weights=list(weights)))).parts
    (ref,) = load_mesh(str(baked_file(tmp_path / "b.glb", weights))).parts
    assert np.abs(np.sort(part.positions, axis=0) - np.sort(ref.positions, axis=0)).max() < 1e-6
