"""Compressed glTF as optimisers write it: KHR_draco_mesh_compression (with the accessor's
componentType and ``normalized`` applied, and its uncompressed fallback), EXT_meshopt_compression
and KHR_texture_basisu (KTX2). Each file renders like its uncompressed twin (linear, 1% relMAE).

The files come from the tools users run: @gltf-transform/cli (``draco``, ``quantize``,
``meshopt``) and gltfpack (``-c``), installed from npm into tools/node as tools/setup.sh does.
Neither writes KTX2 on this machine (gltfpack's npm build has no BasisU; gltf-transform's
``uastc``/``etc1s`` call KTX-Software's ``ktx`` program, which neither Debian nor PyPI ships), so
the KTX2 images are written by Basis Universal's encoder through alktx2 instead.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from tests.gltf_builder import UBYTE, USHORT, Gltf, checker
from tests.test_gltf import assert_equivalent, render

from alight.core.scene import Camera
from alight.errors import AlightError
from alight.exchange.meshes import load_mesh

REPO = Path(__file__).resolve().parents[1]
NODE_BIN = REPO / "tools" / "node" / "node_modules" / ".bin"
SPHERE_CAMERA = Camera(position=(0.0, 0.0, 4.0), target=(0.0, 0.0, 0.0), fov_y_deg=40.0, near=0.1, far=20.0)


@pytest.fixture(scope="session")
def npm_tool():
    """``npm_tool("gltf-transform")`` -> its path, installed into tools/node when missing."""

    def get(name: str) -> Path:
        path = NODE_BIN / name
        if not path.exists():
            if shutil.which("npm") is None:
                pytest.skip(f"npm is not installed: {name} (npm) writes this test's file")
            package = {"gltf-transform": "@gltf-transform/cli"}.get(name, name)
            subprocess.run(["npm", "install", "--silent", "--no-save", "--prefix", str(REPO / "tools" / "node"), package],
                           check=True, capture_output=True)
        return path

    return get


def run_tool(tool: Path, *args) -> None:
    out = subprocess.run([str(tool), *map(str, args)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr + out.stdout


def sphere(rings: int = 24, segments: int = 48):
    """A unit UV sphere: positions, normals, uvs (u around, v down from the north pole), triangles."""
    theta = np.linspace(0.0, np.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    pos = np.stack([np.sin(t) * np.cos(p), np.cos(t), -np.sin(t) * np.sin(p)], axis=-1).reshape(-1, 3)
    uv = np.stack([p / (2.0 * np.pi), t / np.pi], axis=-1).reshape(-1, 2)
    i = np.arange(rings)[:, None] * (segments + 1) + np.arange(segments)[None, :]
    a, b = i.ravel(), i.ravel() + segments + 1
    tri = np.concatenate([np.stack([a, b, a + 1], 1), np.stack([a + 1, b, b + 1], 1)])
    return pos.astype(np.float32), pos.astype(np.float32), uv.astype(np.float32), tri.astype(np.uint32)


def sphere_file(path: Path, colours: bool = False, texture: bool = True, image=None, basisu: bytes | None = None,
                required: bool = True) -> Path:
    """A sphere with a checker base colour (PNG, or the KTX2 ``basisu`` in KHR_texture_basisu)
    and, with ``colours``, COLOR_0 as normalized unsigned bytes (as gltf-transform writes them)."""
    g = Gltf()
    pos, nrm, uv, tri = sphere()
    attributes = {"POSITION": g.accessor(pos, bounds=True), "NORMAL": g.accessor(nrm), "TEXCOORD_0": g.accessor(uv)}
    if colours:
        rgba = np.c_[np.clip((pos + 1.0) * 127.5, 0, 255), np.full(len(pos), 255)].astype(np.uint8)
        attributes["COLOR_0"] = g.accessor(rgba, UBYTE, normalized=True)
    pbr = {"metallicFactor": 0.0, "roughnessFactor": 0.5}
    if texture:
        tex = g.image(checker() if image is None else image)
        if basisu is not None:
            g.doc["images"].append({"bufferView": g._view(basisu), "mimeType": "image/ktx2"})
            g.doc["textures"][tex] = {"extensions": {"KHR_texture_basisu": {"source": len(g.doc["images"]) - 1}}}
            if required:
                del g.doc["images"][0]   # no PNG fallback: the KTX2 must be decoded
                g.doc["textures"][tex]["extensions"]["KHR_texture_basisu"]["source"] = 0
            else:
                g.doc["textures"][tex]["source"] = 0
            g.use("KHR_texture_basisu", required=required)
        pbr["baseColorTexture"] = {"index": tex}
    mat = g.material(pbrMetallicRoughness=pbr)
    g.mesh([{"attributes": attributes, "indices": g.accessor(tri.ravel(), USHORT), "material": mat}])
    return g.save(path)


def view(path) -> np.ndarray:
    return render(path, camera=SPHERE_CAMERA)


# --- Draco -----------------------------------------------------------------------------------

def test_draco_vertex_colours_from_gltf_transform(tmp_path, npm_tool):
    """gltf-transform's Draco keeps COLOR_0 as normalized bytes: the colours, not a white disc."""
    pytest.importorskip("DracoPy")
    src = sphere_file(tmp_path / "src.glb", colours=True, texture=False)
    run_tool(npm_tool("gltf-transform"), "draco", src, tmp_path / "draco.glb")
    assert b"KHR_draco_mesh_compression" in (tmp_path / "draco.glb").read_bytes()[:4000]
    (part,) = load_mesh(str(tmp_path / "draco.glb")).parts
    assert part.colors is not None and part.colors.max() <= 1.0 and part.colors[:, :3].min() < 0.2
    assert_equivalent(view(tmp_path / "draco.glb"), view(src))


def test_draco_over_quantized_attributes(tmp_path, npm_tool):
    """gltf-transform quantize then draco: normalized int16 positions and uint16 UVs inside
    Draco, dequantized as the accessors say (not positions x32767 and UVs 0..65535)."""
    pytest.importorskip("DracoPy")
    tool = npm_tool("gltf-transform")
    src = sphere_file(tmp_path / "src.glb")
    run_tool(tool, "quantize", src, tmp_path / "q.glb")
    run_tool(tool, "draco", tmp_path / "q.glb", tmp_path / "qd.glb")
    mesh = load_mesh(str(tmp_path / "qd.glb"))
    (part,) = mesh.parts
    assert np.abs(part.positions).max() < 1.01
    assert part.uvs.min() > -0.01 and part.uvs.max() < 1.01
    assert_equivalent(view(tmp_path / "qd.glb"), view(src))


@pytest.mark.parametrize("name, control", [
    ("gltf_transform_draco_vcol.glb", "src_vertex_colour_sphere.glb"),
    ("gltf_transform_quantize_draco.glb", "gltf_transform_quantized_ctrl.glb"),
])
def test_draco_cases_like_their_controls(shared_data, name, control):
    pytest.importorskip("DracoPy")
    cases = shared_data / "cases" / "with_controls"
    assert_equivalent(view(cases / name), view(cases / control))


def _draco_with_fallback(tmp_path, required: bool, draco: bool = True) -> Path:
    """A sphere whose Draco stream is broken, with the plain accessors kept beside it (or,
    ``draco=False``, the same file without the extension: the twin)."""
    g = Gltf()
    pos, nrm, uv, tri = sphere()
    attributes = {"POSITION": g.accessor(pos, bounds=True), "NORMAL": g.accessor(nrm)}
    broken = g._view(b"DRACO" + bytes(range(64)))
    mat = g.material(pbrMetallicRoughness={"baseColorFactor": [0.8, 0.3, 0.2, 1.0], "metallicFactor": 0.0})
    prim = {"attributes": attributes, "indices": g.accessor(tri.ravel(), USHORT), "material": mat}
    if draco:
        prim["extensions"] = {"KHR_draco_mesh_compression": {"bufferView": broken,
                                                             "attributes": {"POSITION": 0, "NORMAL": 1}}}
        g.use("KHR_draco_mesh_compression", required=required)
    g.mesh([prim])
    return g.save(tmp_path / f"fallback_{required}_{draco}.glb")


def test_failed_draco_falls_back_to_the_plain_accessors(tmp_path):
    pytest.importorskip("DracoPy")
    path = _draco_with_fallback(tmp_path, required=False)
    warnings = load_mesh(str(path)).warnings
    assert len(warnings) == 1 and "KHR_draco_mesh_compression" in warnings[0] and "uncompressed" in warnings[0]
    assert_equivalent(view(path), view(_draco_with_fallback(tmp_path, required=False, draco=False)), 1e-6)


def test_failed_draco_refused_when_required(tmp_path):
    pytest.importorskip("DracoPy")
    with pytest.raises(AlightError) as e:
        load_mesh(str(_draco_with_fallback(tmp_path, required=True)))
    message = str(e.value)
    assert "\n" not in message and "fallback_True_True.glb" in message and "KHR_draco_mesh_compression" in message


# --- meshopt ---------------------------------------------------------------------------------

def test_meshopt_from_gltf_transform(tmp_path, npm_tool):
    pytest.importorskip("meshopt")
    src = sphere_file(tmp_path / "src.glb", colours=True)
    run_tool(npm_tool("gltf-transform"), "meshopt", src, tmp_path / "m.glb")
    assert b"EXT_meshopt_compression" in (tmp_path / "m.glb").read_bytes()[:4000]
    mesh = load_mesh(str(tmp_path / "m.glb"))
    assert not any("meshopt" in w for w in mesh.warnings), mesh.warnings
    assert_equivalent(view(tmp_path / "m.glb"), view(src))


@pytest.mark.parametrize("flag", ["-c", "-cc"])
def test_meshopt_from_gltfpack(tmp_path, npm_tool, flag):
    """gltfpack -c: EXT_meshopt_compression over KHR_mesh_quantization with the dequantizing
    node transform; -cc adds the octahedral filter on the normals."""
    pytest.importorskip("meshopt")
    src = sphere_file(tmp_path / "src.glb")
    run_tool(npm_tool("gltfpack"), "-i", src, "-o", tmp_path / "p.glb", flag)
    head = (tmp_path / "p.glb").read_bytes()[:4000]
    assert b"EXT_meshopt_compression" in head and (flag == "-c" or b"OCTAHEDRAL" in head)
    assert_equivalent(view(tmp_path / "p.glb"), view(src))


def test_meshopt_refused_in_one_line_when_broken(tmp_path, npm_tool):
    pytest.importorskip("meshopt")
    src = sphere_file(tmp_path / "src.glb")
    out = tmp_path / "p.glb"
    run_tool(npm_tool("gltfpack"), "-i", src, "-o", out, "-c")
    data = bytearray(out.read_bytes())
    data[-200:] = bytes(200)   # zero the end of the compressed binary chunk
    out.write_bytes(bytes(data))
    with pytest.raises(AlightError) as e:
        load_mesh(str(out))
    assert "\n" not in str(e.value) and "p.glb" in str(e.value)


# --- KTX2 / Basis Universal ------------------------------------------------------------------

@pytest.mark.parametrize("codec, limit", [("uastc", 0.002), ("etc1s", 0.01)])
def test_basisu_texture_like_png(tmp_path, codec, limit):
    """KHR_texture_basisu (required, no PNG beside it) renders like the PNG it was encoded from:
    UASTC near-lossless, ETC1S within 1%."""
    alktx2 = pytest.importorskip("alktx2")
    image = np.dstack([checker(), np.full((64, 64), 255, np.uint8)])
    ktx2 = alktx2.encode_raw_rgba_to_ktx2(image.tobytes(), 64, 64, False, codec=codec, quality=90)
    src = sphere_file(tmp_path / "png.glb", image=image)
    compressed = sphere_file(tmp_path / f"{codec}.glb", image=image, basisu=ktx2)
    assert b"image/png" not in compressed.read_bytes()[:4000]
    assert load_mesh(str(compressed)).warnings == []
    assert_equivalent(view(compressed), view(src), limit)


def test_basisu_with_png_fallback_takes_the_ktx2(tmp_path):
    """Where the file also gives a PNG (extension used, not required) the KTX2 is the one drawn:
    a KTX2 of another picture shows that picture."""
    alktx2 = pytest.importorskip("alktx2")
    other = np.dstack([checker(colours=((20, 30, 200), (240, 240, 240))), np.full((64, 64), 255, np.uint8)])
    ktx2 = alktx2.encode_raw_rgba_to_ktx2(other.tobytes(), 64, 64, False, codec="uastc")
    both = sphere_file(tmp_path / "both.glb", basisu=ktx2, required=False)
    assert_equivalent(view(both), view(sphere_file(tmp_path / "blue.glb", image=other)), 0.002)


def test_broken_ktx2_refused_in_one_line(tmp_path):
    pytest.importorskip("alktx2")
    from alight.exchange.gltf import KTX2_MAGIC

    path = sphere_file(tmp_path / "bad.glb", basisu=KTX2_MAGIC + bytes(100))
    with pytest.raises(AlightError) as e:
        load_mesh(str(path))
    assert "\n" not in str(e.value) and "bad.glb" in str(e.value) and "images[0]" in str(e.value)
