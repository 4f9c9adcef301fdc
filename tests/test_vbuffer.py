"""Meshes shaded from the visibility buffer (ForwardRenderer.mesh_shading = "vbuffer",
alight.render.vbuffer) against the forward pass, 4x MSAA: the same pictures within a stated
tolerance (relMAE of the linear radiance), the same coverage, and the scenes it leaves to the
forward pass."""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest
from tests.gltf_builder import USHORT, Gltf, checker, grid_plane

from alight.core.scene import Camera, Display, Light, Scene
from alight.exchange.meshes import load_mesh

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data"
HELMET = SHARED / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
NORMAL_TANGENT = SHARED / "models" / "khronos" / "NormalTangentTest" / "glTF-Binary" / "NormalTangentTest.glb"
CAMERA = Camera(position=(0.3, 0.4, 4.0), target=(0.0, 0.0, 0.0), fov_y_deg=35.0, near=0.1, far=20.0)
LIGHTS = [Light(kind="directional", vector=(-0.4, -0.5, -1.0), intensity=2.0)]
# Every pixel is shaded at the same point as the forward pass; what differs are the maps'
# derivatives (the triangle's one pixel over, not a 2x2 block's differences: another mip level
# here and there) and float rounding. Measured: the helmet 1.3e-4 at 256x256; NormalTangentTest
# 3.8e-3 at 192x192 (a minified bump map under a sharp gold highlight: specks where the level
# differs); the limits leave 1.5-8x room.
REL_LIMIT = 1e-3
REL_LIMIT_BUMPS = 6e-3


@functools.lru_cache(maxsize=1)
def _maps():
    from tests.gpu import renderer

    from alight.ibl.environment import load_environment

    return renderer().bake(load_environment("studio"), "low")


def both(scene: Scene, size: int = 128, **kwargs):
    """(forward, vbuffer) frames of ``scene``, and whether the second used the visibility buffer."""
    from tests.gpu import renderer

    r = renderer()
    frames = []
    try:
        for mode in ("forward", "vbuffer"):
            r.mesh_shading = mode
            frames.append(r.render(scene, _maps(), size, size, aa="msaa", **kwargs))
        used = r.last_vbuffer
    finally:
        r.mesh_shading = "forward"
    return frames[0], frames[1], used


def rel_mae(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a[..., :3] - b[..., :3]).sum() / np.abs(a[..., :3]).sum())


def assert_same(forward, vbuffer, used: bool, limit: float = REL_LIMIT) -> float:
    assert used, "the scene was expected to take the visibility buffer"
    covered = forward.linear[..., 3] > 0
    assert covered.sum() > 500, "the mesh must cover part of the image"
    # Coverage comes from the same rasteriser: equal sample for sample.
    np.testing.assert_array_equal(forward.linear[..., 3], vbuffer.linear[..., 3])
    rel = rel_mae(forward.linear, vbuffer.linear)
    assert rel < limit, rel
    return rel


def test_textured_normal_mapped_helmet():
    """DamagedHelmet: base colour, metal-roughness, normal, emissive and occlusion maps."""
    scene = Scene(mesh=load_mesh(str(HELMET)))
    assert_same(*both(scene, 256))


def test_normal_tangent_model():
    """Khronos NormalTangentTest: normal maps on the file's tangents, both handednesses."""
    scene = Scene(mesh=load_mesh(str(NORMAL_TANGENT)), lights=list(LIGHTS))
    assert_same(*both(scene, 192), limit=REL_LIMIT_BUMPS)


def _masked_plane(path: Path) -> Path:
    """A tilted plane whose base colour texture's alpha is a checker of 0.16 and 1 (alphaMode
    MASK, cutoff 0.5), in front of a second, opaque plane of another material (two parts)."""
    tex = np.zeros((64, 64, 4), np.uint8)
    tex[..., :3] = checker(8, 64)
    tex[..., 3] = np.where(checker(4, 64, colours=((40, 40, 40), (255, 255, 255)))[..., 0] > 100, 255, 40)
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(6)
    t = g.image(tex)
    mat = g.material(pbrMetallicRoughness={"baseColorTexture": {"index": t}, "metallicFactor": 0.0,
                                           "roughnessFactor": 0.4}, alphaMode="MASK", doubleSided=True)
    back = g.material(pbrMetallicRoughness={"baseColorFactor": [0.2, 0.5, 0.9, 1.0], "metallicFactor": 1.0,
                                            "roughnessFactor": 0.3})
    tilted = positions @ np.array([[1.0, 0.0, 0.0], [0.0, 0.8, 0.6], [0.0, -0.6, 0.8]]).T
    g.mesh([{"attributes": {"POSITION": g.accessor(tilted, bounds=True), "NORMAL": g.accessor(normals @ np.array(
        [[1.0, 0.0, 0.0], [0.0, 0.8, 0.6], [0.0, -0.6, 0.8]]).T), "TEXCOORD_0": g.accessor(uvs)},
        "indices": g.accessor(idx.ravel(), USHORT), "material": mat},
        {"attributes": {"POSITION": g.accessor(positions * 1.3 - [0.0, 0.0, 0.8], bounds=True),
                        "NORMAL": g.accessor(normals), "TEXCOORD_0": g.accessor(uvs)},
         "indices": g.accessor(idx.ravel(), USHORT), "material": back}])
    return g.save(path / "masked.glb")


def test_alpha_mask_and_two_parts(tmp_path):
    """MASK parts are tested in the visibility pass as the forward pass tests them; the part
    behind shows through their holes, and both parts' shares of an edge pixel add up."""
    scene = Scene(mesh=load_mesh(str(_masked_plane(tmp_path))), camera=CAMERA, lights=list(LIGHTS),
                  display=Display(background="transparent"))
    forward, vbuffer, used = both(scene, 160)
    assert_same(forward, vbuffer, used)
    alpha = forward.linear[..., 3]
    assert ((alpha > 0) & (alpha < 1)).sum() > 20   # edge pixels, where the two parts share samples


def test_tiles_match_one_framebuffer():
    """A tiled image (each tile's off-centre projection) equals the untiled one."""
    from tests.gpu import renderer

    scene = Scene(mesh=load_mesh(str(HELMET)))
    r = renderer()
    r.mesh_shading = "vbuffer"
    try:
        whole = r.render(scene, _maps(), 160, 160, aa="msaa").linear
        tiled = r.render(scene, _maps(), 160, 160, aa="msaa", tile=(64, 64)).linear
        assert r.last_vbuffer
    finally:
        r.mesh_shading = "forward"
    np.testing.assert_allclose(tiled, whole, atol=2e-3)


@pytest.mark.parametrize("kind", ["blend", "sphere", "ssaa"])
def test_forward_where_not_eligible(tmp_path, kind):
    """Blended parts, the built-in sphere (its impostor) and SSAA keep the forward pass."""
    from tests.gpu import renderer

    if kind == "blend":
        g = Gltf()
        positions, normals, uvs, idx = grid_plane(2)
        mat = g.material(pbrMetallicRoughness={"baseColorFactor": [1.0, 1.0, 1.0, 0.5]}, alphaMode="BLEND")
        g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals)},
                 "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
        scene = Scene(mesh=load_mesh(str(g.save(tmp_path / "b.glb"))), camera=CAMERA)
    else:
        scene = Scene() if kind == "sphere" else Scene(mesh=load_mesh(str(HELMET)))
    r = renderer()
    r.mesh_shading = "vbuffer"
    try:
        r.render(scene, _maps(), 64, 64, aa="ssaa" if kind == "ssaa" else "msaa")
        assert not r.last_vbuffer
    finally:
        r.mesh_shading = "forward"
