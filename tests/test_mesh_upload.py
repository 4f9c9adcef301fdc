"""The staged mesh upload (app/render/mesh_upload.py, the editor's open of a mesh file): mip levels
made with numpy against GL's own generate_mipmap, and a mesh uploaded in steps drawn as
``render()``'s own upload draws it, with no texture upload left for its first frame."""

from __future__ import annotations

import numpy as np
import pytest

from alight.core.scene import Light, Scene
from alight.render import gpu_mesh
from alight.render.gpu_mesh import upload_image
from alight.render.mesh_upload import STEP_BYTES, mip_levels, prepare_upload
from alight.render.renderer import ForwardRenderer


@pytest.fixture(scope="module")
def renderer():
    r = ForwardRenderer()
    yield r
    r.release()


def gl_levels(ctx, image, srgb):
    tex = upload_image(ctx, image, srgb)
    w, h = tex.size
    levels, n = [], 0
    while True:
        lw, lh = max(1, w >> n), max(1, h >> n)
        levels.append(np.frombuffer(tex.read(level=n), np.uint8).reshape(lh, lw, 4))
        if lw == 1 and lh == 1:
            break
        n += 1
    tex.release()
    return levels


def test_linear_levels_are_gl_generate_mipmap_bit_for_bit(renderer):
    image = np.random.default_rng(1).integers(0, 256, (32, 128, 4), dtype=np.uint8)   # not square
    ours, gl = mip_levels(image, srgb=False), gl_levels(renderer.ctx, image, False)
    assert len(ours) == len(gl) == 8
    for n, (a, b) in enumerate(zip(ours, gl)):
        np.testing.assert_array_equal(a, b, err_msg=f"level {n}")


def test_srgb_levels_within_one_of_gl_generate_mipmap(renderer):
    """llvmpipe's sRGB encoding is an approximation of the exact curve used here: at most 1 apart
    at any level (each level made from the one before, as GL does: the error does not grow)."""
    image = np.random.default_rng(2).integers(0, 256, (64, 64, 3), dtype=np.uint8)
    ours, gl = mip_levels(image, srgb=True), gl_levels(renderer.ctx, image, True)
    for n, (a, b) in enumerate(zip(ours, gl)):
        diff = np.abs(a.astype(int) - b)
        assert diff.max() <= 1, (n, diff.max())
        assert (diff > 0).mean() < 0.3, (n, (diff > 0).mean())


def test_a_side_that_is_not_a_power_of_two_is_left_to_gl():
    assert mip_levels(np.zeros((48, 64, 4), np.uint8), srgb=False) is None
    assert len(mip_levels(np.zeros((48, 64, 4), np.uint8), srgb=False, mipmaps=False)) == 1


def test_a_staged_mesh_draws_as_render_uploads_it(renderer, shared_data, monkeypatch):
    """DamagedHelmet (five 2048² maps, self-shadowing): in steps of at most STEP_BYTES, then
    drawn with no texture upload and no self-shadowing test in its frame; the picture as
    render()'s own upload gives it (mip levels within 1 of GL's: a few pixels a hair apart)."""
    from alight.exchange.meshes import load_mesh

    path = str(shared_data / "models" / "DamagedHelmet" / "DamagedHelmet.gltf")
    lights = [Light("point", (2.0, 3.0, 4.0), (1.0, 0.95, 0.9), 10.0),
              Light("directional", (-0.3, -1.0, -0.5), (1.0, 1.0, 1.0), 1.0)]
    plain = load_mesh(path)
    expected = renderer.render(Scene(mesh=plain, use_file_materials=True, lights=lights), None, 160, 160).linear
    mesh = load_mesh(path)
    upload = prepare_upload(mesh)
    assert upload.self_shadowing and len(upload.textures) == 5
    steps = 0
    while not renderer.upload_step(upload):
        steps += 1
        assert steps < 100
    # Level 0 of a 2048² map is 16 MiB: four steps of STEP_BYTES each, the rest in one more.
    assert steps >= 5 * (2048 * 2048 * 4 // STEP_BYTES), steps

    def refused(*args, **kwargs):
        raise AssertionError("a texture was uploaded in the frame that draws the staged mesh")

    monkeypatch.setattr(gpu_mesh, "upload_image", refused)
    monkeypatch.setattr("alight.render.shadows.can_shadow_itself", refused)
    got = renderer.render(Scene(mesh=mesh, use_file_materials=True, lights=lights), None, 160, 160).linear
    assert renderer.shadow_maps.last_active
    diff = np.abs(got - expected)
    print(f"staged vs render(): max {diff.max():.4f}, mean {diff.mean():.2e}")
    assert diff.max() < 0.02 and diff.mean() < 1e-4, (diff.max(), diff.mean())


def test_a_dropped_upload_releases_its_textures(renderer, shared_data):
    from alight.exchange.meshes import load_mesh

    mesh = load_mesh(str(shared_data / "models" / "Duck.glb"))
    upload = prepare_upload(mesh)
    assert not renderer.upload_step(upload)
    made = list(upload.made.values())
    assert made
    upload.drop()
    assert not upload.made and all(type(t.mglo).__name__ == "InvalidObject" for t in made), [t.mglo for t in made]
