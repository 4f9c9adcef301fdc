"""Texture lookups where a pixel's footprint is huge (a texture tiled 1000 times) give the right
picture: the image's mean where the footprint covers it, the filtered texture where it does not
(common/mesh_material.glsl's sample_map), and whole-period shifts or clamped maps change what they
should. What they cost is in benchmarks/bench_gltf_sampling.py, not here. Renders linear, as
tests/test_gltf.py; the x1000 sphere without MSAA (with it, llvmpipe takes about 30 s at 96 px)."""

from __future__ import annotations

import numpy as np
import pytest
from tests.gltf_builder import USHORT, Gltf, checker
from tests.test_gltf import assert_equivalent, render
from tests.test_gltf_compressed import SPHERE_CAMERA, sphere


def srgb_to_linear(c):
    c = np.asarray(c, np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def tiled_sphere(path, tiles: float, texture=None, sampler=None, base=None):
    g = Gltf()
    pos, nrm, uv, tri = sphere(32, 64)
    pbr = {"metallicFactor": 0.0, "roughnessFactor": 0.5}
    attributes = {"POSITION": g.accessor(pos, bounds=True), "NORMAL": g.accessor(nrm),
                  "TEXCOORD_0": g.accessor(uv * np.float32(tiles))}
    if base is not None:
        pbr["baseColorFactor"] = [*map(float, base), 1.0]
    else:
        pbr["baseColorTexture"] = {"index": g.image(checker() if texture is None else texture, sampler)}
    mat = g.material(pbrMetallicRoughness=pbr)
    g.mesh([{"attributes": attributes, "indices": g.accessor(tri.ravel(), USHORT), "material": mat}])
    return g.save(path)


def view(path, aa="msaa"):
    return render(path, camera=SPHERE_CAMERA, aa=aa)


def test_thousand_tiles_give_the_mean(tmp_path):
    """x1000 on a 64x64 checker: every pixel covers many whole periods, so the sphere is the
    checker's linear mean (sRGB decoded, then averaged, as the GL's sRGB mipmaps are)."""
    image = checker()
    mean = srgb_to_linear(image[..., :3]).reshape(-1, 3).mean(axis=0)
    assert_equivalent(view(tiled_sphere(tmp_path / "t.glb", 1000.0), "none"),
                      view(tiled_sphere(tmp_path / "m.glb", 0, base=mean), "none"))


@pytest.mark.parametrize("tiles", [1.0, 3.0])
def test_few_tiles_unchanged_by_a_shift_of_whole_periods(tmp_path, tiles):
    """REPEAT coordinates are taken into [0, 1) before the lookup: uvs moved by 37 whole periods
    render as the unmoved ones (the fract adds no seam and changes no mip level)."""
    a = tiled_sphere(tmp_path / "a.glb", tiles)
    g = Gltf()
    pos, nrm, uv, tri = sphere(32, 64)
    mat = g.material(pbrMetallicRoughness={"metallicFactor": 0.0, "roughnessFactor": 0.5,
                                           "baseColorTexture": {"index": g.image(checker())}})
    g.mesh([{"attributes": {"POSITION": g.accessor(pos, bounds=True), "NORMAL": g.accessor(nrm),
                            "TEXCOORD_0": g.accessor(uv * np.float32(tiles) + np.float32(37.0))},
             "indices": g.accessor(tri.ravel(), USHORT), "material": mat}])
    assert_equivalent(view(g.save(tmp_path / "b.glb")), view(a), 0.002)


def test_clamped_map_is_not_wrapped(tmp_path):
    """CLAMP_TO_EDGE keeps its coordinates: uvs x3 on a clamped map show its edge texels past 1,
    unlike the same uvs on a repeating one."""
    image = np.zeros((64, 64, 3), np.uint8)
    image[:, :32] = (230, 30, 30)
    image[:, 32:] = (30, 30, 230)
    clamp = {"wrapS": 33071, "wrapT": 33071}
    clamped = view(tiled_sphere(tmp_path / "c.glb", 3.0, texture=image, sampler=clamp))
    repeated = view(tiled_sphere(tmp_path / "r.glb", 3.0, texture=image))
    covered = clamped[..., 3] > 0
    red_c = (clamped[..., 0] > clamped[..., 2])[covered].mean()
    red_r = (repeated[..., 0] > repeated[..., 2])[covered].mean()
    assert red_c < 0.05 and red_r > 0.3, (red_c, red_r)   # measured: 0 and 0.65
