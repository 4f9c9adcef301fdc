"""Export glTF with the mesh file's own materials (app/exchange/gltf_file_materials.py): a file
rendered with its own materials, exported through the editor's 'export glTF' control (the UI test
engine, tests/editor_ui_checks_export.py) and through the API the CLI and the panel share,
renders the same picture as the original; the validator reports no error."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gltf_builder import Gltf, checker, grid_plane
from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test
from test_gltf_material import validate  # noqa: F401  (the Khronos validator fixture)

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared" / "data"
KHRONOS = SHARED / "models" / "khronos"
CHECKS = REPO / "tests" / "editor_ui_checks_export.py"
# Differences allowed between the two renders (8-bit sRGB, 0..255): the geometry is written in
# world space (one node a part) and the tangents as computed, so a few edge pixels may move.
MAX_MEAN, MAX_PIXEL_SHARE = 0.5, 0.01


def two_part_file(path: Path, second_material: bool = True) -> Path:
    """Two tilted planes, two materials: a checker base colour (KHR_texture_transform: offset,
    rotation, scale; a nearest/clamp sampler) and a normal + metallicRoughness map (REPEAT,
    TEXCOORD_1 for the metallicRoughness map); ``second_material`` False: the second part has
    none (drawn with the panel's material)."""
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(4, size=1.6)
    y, x = np.mgrid[0:32, 0:32] / 32.0
    bumps = np.stack([0.5 + 0.35 * np.sin(x * 12.0), 0.5 + 0.35 * np.cos(y * 9.0), np.full_like(x, 0.8)], -1)
    normal_map = (bumps / np.linalg.norm(bumps - 0.5, axis=-1, keepdims=True) * 0.5 + 0.5).clip(0, 1) * 255
    mr = np.stack([np.full_like(x, 255), 40 + 200 * x, 255 * (y > 0.5)], -1)
    checker_tex = g.image(checker(4, 32), {"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33648})
    normal_tex = g.image(normal_map.astype(np.uint8))
    mr_tex = g.image(mr.astype(np.uint8), {"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497})
    g.use("KHR_texture_transform")
    painted = g.material(name="painted", pbrMetallicRoughness={
        "baseColorFactor": [1.0, 0.9, 0.8, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6,
        "baseColorTexture": {"index": checker_tex, "extensions": {"KHR_texture_transform": {
            "offset": [0.1, -0.2], "rotation": 0.4, "scale": [1.5, 2.0]}}}})
    metal = g.material(name="bumpy metal", normalTexture={"index": normal_tex, "scale": 0.8},
                       pbrMetallicRoughness={"baseColorFactor": [0.9, 0.6, 0.3, 1.0], "metallicFactor": 1.0,
                                             "roughnessFactor": 0.9,
                                             "metallicRoughnessTexture": {"index": mr_tex, "texCoord": 1}})
    uvs1 = uvs[:, ::-1].copy()   # a second uv set that differs from the first
    for material, x0, turn in ((painted, -0.85, 0.3), (metal, 0.85, -0.3)):
        attrs = {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals),
                 "TEXCOORD_0": g.accessor(uvs), "TEXCOORD_1": g.accessor(uvs1)}
        prim = {"attributes": attrs, "indices": g.accessor(idx.reshape(-1), component=5125), "material": material}
        if material == metal and not second_material:
            del prim["material"]
        g.mesh([prim],
               translation=[x0, 0.0, 0.0], rotation=[0.0, math.sin(turn / 2), 0.0, math.cos(turn / 2)])
    return g.save(path)


def alight(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "alight", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=600)


def render(mesh: Path, out: Path) -> np.ndarray:
    from PIL import Image

    r = alight("render", "--mesh", str(mesh), "--size", "160x96", "--occlusion", "off", "--shadows", "off",
               "--out", str(out), cwd=out.parent)
    assert r.returncode == 0, r.stderr
    return np.asarray(Image.open(out).convert("RGB"), np.float64)


def difference(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    """(max, mean, share of pixels off by more than 8 of 255)."""
    d = np.abs(a - b)
    return float(d.max()), float(d.mean()), float((d.max(axis=-1) > 8).mean())


def assert_same_picture(original: Path, exported: Path, tmp: Path) -> tuple[float, float, float]:
    a = render(original, tmp / f"{original.stem}_original.png")
    b = render(exported, tmp / f"{exported.stem}_exported.png")
    got = difference(a, b)
    assert got[1] <= MAX_MEAN and got[2] <= MAX_PIXEL_SHARE, (original, got)
    return got


def export_cli(mesh_path: Path, out: Path) -> str:
    """`alight export --mesh FILE` (no preset, maps or field flags: the file's own materials);
    returns its stderr."""
    r = alight("export", "--mesh", str(mesh_path), "--out", str(out), cwd=out.parent)
    assert r.returncode == 0 and r.stdout.strip() == str(out), r.stderr
    return r.stderr


def test_the_editors_export_renders_as_the_file_it_opened(display, tmp_path, validate):
    """The panel's 'export glTF' with the file's own materials shown writes a file that renders
    as the original; with them off, the panel's material on every part (a different picture)."""
    original = two_part_file(tmp_path / "two_parts.glb")
    result = ui_test(tmp_path, CHECKS, "--new", size="1280x720")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "1 passed, 0 failed" in result.stdout, result.stdout
    got = assert_same_picture(original, tmp_path / "from_editor.gltf", tmp_path)
    print("editor export: max %.0f mean %.3f share %.4f" % got)
    panel = render(tmp_path / "panel_material.glb", tmp_path / "panel_material.png")
    assert difference(render(original, tmp_path / "again.png"), panel)[1] > 5.0   # the comparison can fail
    reports = validate(tmp_path / "from_editor.gltf", tmp_path / "panel_material.glb")
    assert all((r["errors"], r["warnings"]) == (0, 0) for r in reports), reports


def test_two_materials_with_textures_export_as_they_render(tmp_path, validate):
    original = two_part_file(tmp_path / "two_parts.glb")
    for out in (tmp_path / "two_parts_out.gltf", tmp_path / "two_parts_out.glb"):
        assert "left out" not in export_cli(original, out)
        got = assert_same_picture(original, out, tmp_path)
        print(out.name, "max %.0f mean %.3f share %.4f" % got)
        (report,) = validate(out)
        assert (report["errors"], report["warnings"]) == (0, 0), report["messages"]
    doc = json.loads((tmp_path / "two_parts_out.gltf").read_text())
    names = [doc["materials"][m["primitives"][0]["material"]]["name"] for m in doc["meshes"]]
    assert names == ["painted", "bumpy metal"], names
    painted, metal = doc["materials"]
    t = painted["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]
    assert t == {"offset": [0.1, -0.2], "rotation": 0.4, "scale": [1.5, 2.0]}, t
    assert metal["pbrMetallicRoughness"]["metallicRoughnessTexture"]["texCoord"] == 1
    assert metal["normalTexture"]["scale"] == 0.8
    sampler = doc["samplers"][doc["textures"][painted["pbrMetallicRoughness"]["baseColorTexture"]["index"]]["sampler"]]
    assert sampler == {"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33648}, sampler
    assert len(doc["images"]) == 3 and all((tmp_path / i["uri"]).is_file() for i in doc["images"])


@pytest.mark.parametrize("model", ["TextureTransformTest/glTF/TextureTransformTest.gltf",
                                   "TextureSettingsTest/glTF-Binary/TextureSettingsTest.glb"])
def test_a_khronos_model_exports_as_it_renders(tmp_path, model, validate):
    original = KHRONOS / model
    if not original.is_file():
        pytest.skip(f"{original} is not in the shared data")
    out = tmp_path / "exported.glb"
    export_cli(original, out)
    got = assert_same_picture(original, out, tmp_path)
    print(model, "max %.0f mean %.3f share %.4f" % got)
    (report,) = validate(out)
    assert (report["errors"], report["warnings"]) == (0, 0), report["messages"]


def test_a_part_without_a_material_gets_the_panels_after_one_with_its_own(tmp_path, validate):
    """The first part has its own material, the second none (the panel's is drawn on it): both
    go out, in that order, and the export renders as the original."""
    original = two_part_file(tmp_path / "one_bare.glb", second_material=False)
    out = tmp_path / "one_bare_out.glb"
    export_cli(original, out)
    assert_same_picture(original, out, tmp_path)
    from alight.exchange.gltf_material import read_gltf_json

    doc = read_gltf_json(out)
    assert [doc["materials"][m["primitives"][0]["material"]]["name"] for m in doc["meshes"]] == ["painted", "default"]
    (report,) = validate(out)
    assert (report["errors"], report["warnings"]) == (0, 0), report["messages"]


def test_field_flags_export_the_flag_built_material_on_every_part(tmp_path):
    """`alight export --mesh FILE --roughness X`: the material the flags build, on every part
    (the export of a file's own materials takes no edits)."""
    original = two_part_file(tmp_path / "two_parts.glb")
    out = tmp_path / "flags.gltf"
    r = alight("export", "--mesh", str(original), "--roughness", "0.3", "--out", str(out), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    doc = json.loads(out.read_text())
    assert len(doc["materials"]) == 1 and doc["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] == 0.3
    assert "images" not in doc


def _jpeg_file(path: Path) -> tuple[Path, bytes]:
    """One plane whose base colour is a JPEG (the bytes returned)."""
    import io

    from PIL import Image

    g = Gltf()
    positions, normals, uvs, idx = grid_plane(2)
    buf = io.BytesIO()
    Image.fromarray(checker(4, 32)).save(buf, "JPEG", quality=80)
    jpeg = buf.getvalue()
    g.doc.setdefault("images", []).append({"bufferView": g._view(jpeg), "mimeType": "image/jpeg"})
    g.doc.setdefault("textures", []).append({"source": 0})
    m = g.material(name="jpeg", pbrMetallicRoughness={"baseColorTexture": {"index": 0}, "metallicFactor": 0.0})
    g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals),
                            "TEXCOORD_0": g.accessor(uvs)},
             "indices": g.accessor(idx.reshape(-1), component=5125), "material": m}])
    return g.save(path), jpeg


def test_images_go_out_as_the_file_had_them_unless_their_pixels_changed(tmp_path):
    """A JPEG texture is written back as the same bytes (not a PNG four times its size); where
    the pixels drawn are no longer what those bytes decode to, the pixels go out as PNG."""
    from alight.core.material import Material
    from alight.exchange.gltf_export import export_gltf
    from alight.exchange.images import decode_texture
    from alight.exchange.meshes import load_mesh

    original, jpeg = _jpeg_file(tmp_path / "jpeg.gltf")
    out = tmp_path / "jpeg_out.gltf"
    export_cli(original, out)
    doc = json.loads(out.read_text())
    assert [i["uri"] for i in doc["images"]] == ["jpeg_out_m0_base_color.jpg"], doc["images"]
    assert (tmp_path / "jpeg_out_m0_base_color.jpg").read_bytes() == jpeg
    assert_same_picture(original, out, tmp_path)

    mesh = load_mesh(str(original))
    info = mesh.parts[0].material.base_color_texture
    info.image = info.image.copy()
    info.image[0, 0] = (1, 2, 3, 255)   # drawn now, and not what the JPEG decodes to
    # the panel's material (a clearcoat) is on no part: neither it nor its extension is written
    export_gltf(Material(clearcoat=1.0), tmp_path / "changed.gltf", None, mesh, file_materials=True)
    written = tmp_path / "changed_m0_base_color.png"
    assert np.array_equal(decode_texture(written.read_bytes(), str(written)), info.image)
    doc = json.loads((tmp_path / "changed.gltf").read_text())
    assert [m["name"] for m in doc["materials"]] == ["jpeg"] and "extensionsUsed" not in doc, doc


def test_what_the_file_brought_and_the_export_drops_is_said(tmp_path):
    """CesiumMilkTruck's animation is not written (the parts go out in the pose drawn): the one
    note says so, as it says a camera or a light (a new user saw it dropped in silence)."""
    truck = SHARED / "models" / "CesiumMilkTruck.glb"
    note = export_cli(truck, tmp_path / "truck.glb")
    assert "1 animation left out" in note, note
