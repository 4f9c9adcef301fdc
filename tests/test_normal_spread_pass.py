"""A normal map's spread made on the GPU (alight.render.normal_spread_pass, render/normal_spread.comp)
against its numpy twin (alight.render.normal_spread.normal_map_levels): every level's RGB bit for
bit (GL's generate_mipmap, which mip_levels reproduces) and A within 1 code value, in the frame's
upload (gpu_mesh.upload_normal_map) and in the editor's staged one (mesh_upload)."""

from __future__ import annotations

import numpy as np
import pytest

from alight.core.gpu import read_rgba8
from alight.render.gpu_mesh import upload_normal_map
from alight.render.mesh_upload import SPREAD, MeshUpload
from alight.render.normal_spread import normal_map_levels
from alight.render.normal_spread_pass import BAND_TEXELS, level_count, spread_bands, spread_defines
from tests.gpu import renderer


def _gpu_levels(ctx, tex, levels: int) -> list[np.ndarray]:
    return [read_rgba8(ctx, tex, n) for n in range(levels)]


def _assert_twins(got: list[np.ndarray], want: list[np.ndarray], what: str) -> int:
    """RGB equal, A within 1; returns how many texels' A differ."""
    assert len(got) == len(want), what
    differ = 0
    for n, (a, b) in enumerate(zip(got, want)):
        assert a.shape == b.shape, (what, n)
        assert np.array_equal(a[..., :3], b[..., :3]), f"{what}: level {n} RGB"
        d = np.abs(a[..., 3].astype(int) - b[..., 3])
        assert d.max() <= 1, f"{what}: level {n} A off by {d.max()} at {(d > 1).sum()} texels"
        differ += int((d > 0).sum())
    return differ


def _random_normals(shape, seed: int) -> np.ndarray:
    """An RGB map of random normals facing out (z > 0), some runs of equal texels among them."""
    rng = np.random.default_rng(seed)
    image = rng.integers(0, 256, shape + (3,), dtype=np.uint8)
    image[..., 2] = rng.integers(128, 256, shape)
    image[: shape[0] // 2, : shape[1] // 2] = (128, 128, 255)    # a flat corner: A = 0 above it
    return image


@pytest.mark.parametrize("shape, scale", [((64, 64), 0.4), ((64, 64), 2.5), ((32, 128), 1.0), ((128, 32), 0.7),
                                          ((1, 64), 1.0), ((64, 1), 1.5), ((2, 1), 1.0), ((1, 1), 1.0)])
def test_the_gpu_levels_are_the_numpy_twins(shape, scale):
    r = renderer()
    image = _random_normals(shape, sum(shape))
    tex = upload_normal_map(r.ctx, r.shaders, image, scale)
    got = _gpu_levels(r.ctx, tex, level_count(shape[::-1]))
    tex.release()
    _assert_twins(got, normal_map_levels(image, scale), f"{shape} scale {scale}")


def test_damaged_helmets_normal_map_on_the_gpu_is_the_numpy_twin(shared_data):
    from alight.exchange.meshes import load_mesh

    r = renderer()
    mesh = load_mesh(str(shared_data / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"))
    image = mesh.parts[0].material.textures()["normal"].image
    assert image.shape[:2] == (2048, 2048)
    for scale in (1.0, 0.6):
        tex = upload_normal_map(r.ctx, r.shaders, image, scale)
        got = _gpu_levels(r.ctx, tex, 12)
        tex.release()
        differ = _assert_twins(got, normal_map_levels(image, scale), f"helmet at {scale}")
        print(f"helmet at scale {scale}: {differ} texels' A differ by 1")


def test_a_side_that_is_not_a_power_of_two_keeps_a_at_zero():
    r = renderer()
    image = _random_normals((48, 64), 5)
    tex = upload_normal_map(r.ctx, r.shaders, image, 1.0)
    assert not any(read_rgba8(r.ctx, tex, n)[..., 3].any() for n in range(level_count((64, 48))))
    tex.release()


def test_the_staged_upload_writes_the_spread_in_bands_of_steps():
    # a 2048x1024 map: its level 1 (512K texels) in bands of BAND_TEXELS, a step each (a band costs
    # about as much as writing STEP_BYTES), after the levels' own pieces
    from alight.core.mesh import TextureInfo
    from alight.render.gpu_mesh import texture_key
    from alight.render.mip_levels import mip_levels
    from alight.render.normal_spread import without_spread

    r = renderer()
    image = _random_normals((1024, 2048), 9)
    info = TextureInfo(image)
    levels = mip_levels(without_spread(image), False)
    upload = MeshUpload(None, [(texture_key(info, False, 0.8), info, False, levels)], False)
    spread = [i for i, p in enumerate(upload.pieces) if p[1] == SPREAD]
    assert len(spread) == 1 + len(spread_bands((2048, 1024), 12)) and spread[0] > 0
    assert upload.pieces[spread[0]][2] == -1    # the means made first, in a step of their own
    spread = spread[1:]
    assert spread == list(range(spread[0], len(upload.pieces)))   # after every level's own pieces
    steps = []
    while upload.next < len(upload.pieces):
        first = upload.next
        upload.step(r.ctx, r.shaders, None, None)   # (the parts' buffers come after: not reached here)
        steps.append(range(first, upload.next))
        assert len(steps) < 100
    bands = spread_bands((2048, 1024), 12)
    level1 = [i for i in spread if bands[upload.pieces[i][2]][0] == 1]
    assert len(level1) == 2 and all(sum(i in s for i in level1) <= 1 for s in steps)
    got = _gpu_levels(r.ctx, upload.made[0], 12)
    assert not upload.spreads    # the means were released with the last band
    upload.drop()
    _assert_twins(got, normal_map_levels(image, 0.8), "staged 2048x1024")


def test_the_bands_cover_each_level_once_in_order():
    bands = spread_bands((2048, 1024), 12, BAND_TEXELS)
    assert [b[0] for b in bands] == sorted(b[0] for b in bands)
    for level in range(1, 12):
        rows = [(y0, y1) for n, y0, y1 in bands if n == level]
        h = max(1, 1024 >> level)
        assert rows[0][0] == 0 and rows[-1][1] == h and all(a[1] == b[0] for a, b in zip(rows, rows[1:]))
        assert all((y1 - y0) * max(1, 2048 >> level) <= max(BAND_TEXELS, 8 * max(1, 2048 >> level))
                   for y0, y1 in rows)


def test_the_shader_takes_the_twins_constants():
    from alight.render import normal_spread

    defines = spread_defines()
    assert float(defines["NORMAL_SPREAD_FLOOR"]) == normal_spread.SPREAD_FLOOR
    assert float(defines["NORMAL_SPREAD_MAX"]) == normal_spread.MAX_SPREAD
    assert float(defines["NORMAL_FLAT_LENGTH"]) == normal_spread.FLAT_LENGTH


def test_the_pass_is_compiled_again_when_its_source_changes(tmp_path, monkeypatch):
    # (the editor's shader reload: a new library from the files as saved, ForwardRenderer.use_shaders;
    # the uploads take the pass from the renderer's library, and the twin's constants are its defines)
    import shutil

    from alight.core.gpu import ShaderLibrary
    from alight.paths import shader_dir
    from alight.render import normal_spread
    from alight.render.normal_spread_pass import SHADER

    r = renderer()
    root = tmp_path / "shaders"
    shutil.copytree(shader_dir(), root)
    image = _random_normals((64, 64), 3)

    def staged_a() -> np.ndarray:
        """A of level 1, the map uploaded by the renderer's staged steps (as the editor does)."""
        from alight.core.mesh import TextureInfo
        from alight.render.gpu_mesh import texture_key
        from alight.render.mip_levels import mip_levels
        from alight.render.normal_spread import without_spread

        info = TextureInfo(image)
        upload = MeshUpload(None, [(texture_key(info, False, 1.0), info, False,
                                    mip_levels(without_spread(image), False))], False)
        while upload.next < len(upload.pieces):
            r.upload_step(upload)   # (the parts' buffers come after: not reached here)
        a = read_rgba8(r.ctx, upload.made[0], 1)[..., 3]
        upload.drop()
        return a

    try:
        r.use_shaders(ShaderLibrary(r.ctx, root))
        first = staged_a()
        assert first.any()
        monkeypatch.setattr(normal_spread, "SPREAD_FLOOR", 2.0)   # another define: another program
        assert not staged_a().any()
        monkeypatch.undo()
        assert np.array_equal(staged_a(), first)
        source = root / SHADER
        source.write_text(source.read_text(encoding="utf-8").replace("code / 255.0", "0.0"), encoding="utf-8")
        assert np.array_equal(staged_a(), first)   # compiled, kept until the library is replaced
        r.use_shaders(ShaderLibrary(r.ctx, root))
        assert not staged_a().any()
    finally:
        r.use_shaders(ShaderLibrary(r.ctx))   # back to the repository's shaders
