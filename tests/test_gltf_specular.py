"""KHR_materials_specular's specularFactor scales F90 too (the dielectric Fresnel at grazing
incidence), its specularColorFactor only F0: a black dielectric with specularFactor 0 reflects
nothing (SpecularTest's first sphere "should appear perfectly black"), with specularColorFactor 0
it keeps its white rim. Rendered linear with the studio's IBL and a light, as tests/test_gltf.py."""

from __future__ import annotations

import numpy as np
import pytest
from tests.gltf_builder import USHORT, Gltf
from tests.test_gltf import LIGHTS, assert_equivalent, render
from tests.test_gltf_compressed import SPHERE_CAMERA, sphere

from alight.exchange.meshes import load_mesh


def specular_sphere(path, base=(0.0, 0.0, 0.0), metallic=0.0, texture_alpha=None, **spec):
    g = Gltf()
    pos, nrm, uv, tri = sphere(32, 64)
    ext = dict(spec)
    if texture_alpha is not None:
        rgba = np.zeros((4, 4, 4), np.uint8)
        rgba[..., :3] = (255, 0, 255)   # RGB must be ignored (SpecularTest's purple)
        rgba[..., 3] = texture_alpha
        ext["specularTexture"] = {"index": g.image(rgba)}
    mat = g.material(pbrMetallicRoughness={"baseColorFactor": [*base, 1.0], "metallicFactor": metallic,
                                           "roughnessFactor": 0.3},
                     extensions={"KHR_materials_specular": ext})
    g.use("KHR_materials_specular")
    g.mesh([{"attributes": {"POSITION": g.accessor(pos, bounds=True), "NORMAL": g.accessor(nrm),
                            "TEXCOORD_0": g.accessor(uv)},
             "indices": g.accessor(tri.ravel(), USHORT), "material": mat}])
    return g.save(path)


def view(path, aa="none"):
    return render(path, camera=SPHERE_CAMERA, lights=LIGHTS, aa=aa)


def rim_and_centre(img):
    """Mean radiance of the outer ring and of the middle of the disc."""
    h, w = img.shape[:2]
    yy, xx = np.mgrid[:h, :w]
    covered = img[..., 3] > 0.99
    r = np.hypot(yy - h / 2 + 0.5, xx - w / 2 + 0.5)
    radius = r[covered].max()
    lum = img[..., :3].mean(-1)
    return lum[covered & (r > 0.85 * radius)].mean(), lum[covered & (r < 0.4 * radius)].mean()


@pytest.mark.parametrize("how", ["factor", "texture"])
def test_specular_zero_is_black(tmp_path, how):
    """specularFactor 0 (or a specularTexture of A = 0): F0 = F90 = 0, no reflection, no rim."""
    spec = {"specularFactor": 0.0} if how == "factor" else {"specularFactor": 1.0}
    img = view(specular_sphere(tmp_path / "s.glb", texture_alpha=0 if how == "texture" else None, **spec))
    covered = img[..., 3] > 0
    assert covered.sum() > 1000
    assert img[..., :3][covered].max() < 1e-3, img[..., :3][covered].max()


def test_specular_colour_zero_keeps_the_rim(tmp_path):
    """specularColorFactor 0: F0 = 0 but F90 = 1, so the edge still reflects (the README's rows 3-6)."""
    rim, centre = rim_and_centre(view(specular_sphere(tmp_path / "c.glb", specularColorFactor=[0.0, 0.0, 0.0])))
    assert centre < 0.01 and rim > 10 * max(centre, 1e-4), (rim, centre)


def test_specular_factor_half_halves_the_reflection(tmp_path):
    """Schlick's F is linear in (F0, F90): a black dielectric's reflection with specularFactor 0.5
    is half that with 1 (single scattering, the default model), the rim included."""
    half = view(specular_sphere(tmp_path / "h.glb", specularFactor=0.5))
    full = view(specular_sphere(tmp_path / "f.glb", specularFactor=1.0))
    scaled = full.copy()
    scaled[..., :3] *= 0.5
    assert_equivalent(half, scaled, 0.01)


def test_specular_factor_leaves_metals_alone(tmp_path):
    """A metal's F0 is its base colour and its F90 1: KHR_materials_specular does not touch it."""
    a = view(specular_sphere(tmp_path / "a.glb", base=(0.9, 0.6, 0.3), metallic=1.0, specularFactor=0.0))
    b = view(specular_sphere(tmp_path / "b.glb", base=(0.9, 0.6, 0.3), metallic=1.0, specularFactor=1.0))
    assert_equivalent(a, b, 1e-4)


def test_specular_test_first_sphere_black(shared_data):
    """SpecularTest: the file's materials with specularFactor 0 load with F90 0."""
    mesh = load_mesh(str(shared_data / "models/khronos/SpecularTest/glTF-Binary/SpecularTest.glb"))
    f90 = sorted({round(p.material.specular_f90, 3) for p in mesh.parts if p.material is not None})
    assert f90[0] == 0.0 and f90[-1] == 1.0
