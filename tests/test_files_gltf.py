"""glTF files as they reach users: a texture file missing (drawn without it, warned once), a
texture up to the GL limit (9000x4 is valid). Through the real command, against the shared
cases' controls and against equivalent files the tests write."""

from __future__ import annotations

import io

import numpy as np
import pytest

from tests.files_cases import CONTROLS, rel_mae, render_exr
from tests.gltf_builder import FLOAT, UINT, Gltf, grid_plane

VIEW = ("--elevation", "30")


def _png(rgba: np.ndarray) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(rgba).save(buf, "PNG")
    return buf.getvalue()


def _plane(path, image_uri: str | None = None, image=None, embedded: bool = False):
    """A textured 2x2 plane facing +Z; the base colour texture from ``image_uri`` (a file beside
    it) or ``image`` (RGBA, stored in the buffer), or none."""
    g = Gltf()
    pos, nor, uv, idx = grid_plane(2, 2.0)
    prim = {"attributes": {"POSITION": g.accessor(pos, FLOAT, bounds=True), "NORMAL": g.accessor(nor),
                           "TEXCOORD_0": g.accessor(uv)},
            "indices": g.accessor(idx.reshape(-1), UINT)}
    pbr = {"metallicFactor": 0.0, "roughnessFactor": 0.6, "baseColorFactor": [0.8, 0.7, 0.6, 1.0]}
    if image_uri is not None or image is not None:
        if image_uri is not None:
            g.doc.setdefault("images", []).append({"uri": image_uri})
            g.doc.setdefault("textures", []).append({"source": len(g.doc["images"]) - 1})
            texture = len(g.doc["textures"]) - 1
        else:
            texture = g.image(image)
        pbr["baseColorTexture"] = {"index": texture}
    prim["material"] = g.material(pbrMetallicRoughness=pbr)
    g.mesh([prim])
    return g.save(path, embedded=embedded)


# --- a missing texture file ---------------------------------------------------------------------

def test_missing_texture_case_draws_without_it(tmp_path):
    a, warn = render_exr(tmp_path / "a.exr", "--mesh", CONTROLS / "missing_texture" / "plane.gltf", *VIEW)
    assert (a[..., 3] > 0).mean() > 0.1
    assert len(warn) == 1 and "not_shipped.png" in warn[0] and "without" in warn[0], warn


def test_missing_texture_renders_like_the_file_without_it(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    a_path = _plane(tmp_path / "a" / "plane.gltf", image_uri="gone%20away.png")   # never written
    b_path = _plane(tmp_path / "b" / "plane.gltf")
    a, warn = render_exr(tmp_path / "a.exr", "--mesh", a_path, *VIEW)
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", b_path, *VIEW)
    assert rel_mae(a, b) < 1e-6
    assert len(warn) == 1 and "gone%20away.png" in warn[0] and "gone away.png" in warn[0], warn


def test_present_external_texture_is_used(tmp_path):
    rgba = np.zeros((8, 8, 4), np.uint8)
    rgba[..., 0], rgba[..., 3] = 255, 255
    (tmp_path / "red.png").write_bytes(_png(rgba))
    a, warn = render_exr(tmp_path / "a.exr", "--mesh", _plane(tmp_path / "p.gltf", image_uri="red.png"), *VIEW)
    assert warn == []
    covered = a[..., 3] > 0
    assert a[..., 0][covered].mean() > 3 * a[..., 1][covered].mean()


# --- textures up to the GL limit -------------------------------------------------------------

def test_wide_texture_case_renders_like_its_control(tmp_path):
    a, warn = render_exr(tmp_path / "a.exr", "--mesh", CONTROLS / "texture_9000x4.glb", *VIEW)
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", CONTROLS / "texture_ctrl_4500x4.glb", *VIEW)
    assert warn == []
    assert rel_mae(a, b) < 0.01


@pytest.mark.parametrize("width", [9000, 16384])
def test_wide_texture_renders_like_a_narrow_one(tmp_path, width):
    """Six coloured stripes along u, 4 rows alike: at any width the same picture (mip-mapping
    averages the rows, which are equal, and keeps stripes hundreds of texels wide)."""
    def strip(w):
        colours = np.array([[230, 40, 40, 255], [40, 200, 60, 255], [40, 60, 220, 255], [240, 240, 240, 255],
                            [20, 20, 20, 255], [200, 200, 40, 255]], np.uint8)
        row = colours[(np.arange(w) * 6) // w]
        return np.ascontiguousarray(np.repeat(row[None], 4, axis=0))

    a, warn = render_exr(tmp_path / "a.exr", "--mesh", _plane(tmp_path / "a.glb", image=strip(width)), *VIEW)
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", _plane(tmp_path / "b.glb", image=strip(width // 2)), *VIEW)
    assert warn == []
    assert rel_mae(a, b) < 0.01


def test_texture_beyond_the_gl_limit_is_refused_in_one_line(tmp_path):
    from tests.files_cases import run

    rgba = np.zeros((2, 16385, 4), np.uint8)
    path = _plane(tmp_path / "big.glb", image=rgba)
    out = tmp_path / "x.png"
    proc = run("render", "--size", "16", "--mesh", path, "--out", out)
    assert proc.returncode == 2 and "16385x2" in proc.stderr and "16384" in proc.stderr
    assert len(proc.stderr.splitlines()) == 1 and not out.exists()


# --- far from the origin ---------------------------------------------------------------------

def test_far_case_renders_like_its_control(tmp_path):
    a, warn = render_exr(tmp_path / "a.exr", "--mesh", CONTROLS / "far_1e6.glb")
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", CONTROLS / "far_ctrl_origin.glb")
    assert warn == [] and rel_mae(a, b) < 0.01


def _sphere_glb(path, translation):
    from alight.core.mesh import sphere

    part = sphere().parts[0]
    g = Gltf()
    prim = {"attributes": {"POSITION": g.accessor(part.positions, FLOAT, bounds=True),
                           "NORMAL": g.accessor(part.normals)},
            "indices": g.accessor(part.indices.reshape(-1), UINT),
            "material": g.material(pbrMetallicRoughness={"metallicFactor": 1.0, "roughnessFactor": 0.1})}
    g.mesh([prim], translation=list(translation))
    return g.save(path)


@pytest.mark.parametrize("far", [(1e6, 0.0, 1e6), (-3e7, 2e5, 0.0)])
def test_far_gltf_renders_like_at_the_origin(tmp_path, far):
    x, y, z = far
    a, _ = render_exr(tmp_path / "a.exr", "--mesh", _sphere_glb(tmp_path / "a.glb", far),
                      "--target", f"{x!r},{y!r},{z!r}", "--orbit", "-20", "--distance", "4")
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", _sphere_glb(tmp_path / "b.glb", (0, 0, 0)),
                      "--target", "0,0,0", "--orbit", "-20", "--distance", "4")
    assert rel_mae(a, b) < 0.01


def test_far_obj_renders_like_at_the_origin(tmp_path):
    from alight.core.mesh import sphere

    part = sphere().parts[0]
    for name, offset in (("far.obj", np.array([1e6, 0.0, -1e6])), ("near.obj", np.zeros(3))):
        p = part.positions.astype(np.float64) + offset
        text = "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in p)
        text += "".join(f"vn {x} {y} {z}\n" for x, y, z in part.normals)
        text += "".join("f " + " ".join(f"{i + 1}//{i + 1}" for i in tri) + "\n" for tri in part.indices)
        (tmp_path / name).write_text(text)
    a, _ = render_exr(tmp_path / "a.exr", "--mesh", tmp_path / "far.obj")
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", tmp_path / "near.obj")
    assert rel_mae(a, b) < 0.01


def test_a_file_light_moves_with_the_model(tmp_path):
    """A point light placed beside a far model lights it as beside the same model at the origin."""
    def with_light(path, offset):
        g = Gltf()
        pos, nor, uv, idx = grid_plane(2, 2.0)
        g.mesh([{"attributes": {"POSITION": g.accessor(pos, FLOAT, bounds=True), "NORMAL": g.accessor(nor)},
                 "indices": g.accessor(idx.reshape(-1), UINT)}], translation=list(offset))
        g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5.0}]}}
        g.node(translation=[offset[0] + 0.5, offset[1], offset[2] + 1.0],
               extensions={"KHR_lights_punctual": {"light": 0}})
        g.use("KHR_lights_punctual")
        return g.save(path)

    a, _ = render_exr(tmp_path / "a.exr", "--mesh", with_light(tmp_path / "a.glb", (2e6, 0.0, 0.0)), "--no-ibl")
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", with_light(tmp_path / "b.glb", (0.0, 0.0, 0.0)), "--no-ibl")
    assert rel_mae(a, b) < 0.01 and a[..., :3].max() > 0.05
