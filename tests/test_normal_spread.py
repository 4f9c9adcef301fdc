"""The normal map's spread widening the roughness (NORMAL_MAP_TOKSVIG: alight.render.normal_spread,
mesh_material.glsl, surface.glsl normal_map_roughness): the levels it uploads, a mirror it must
leave alone, and by equivalence a glossy plane whose fine checker of two tilts, seen minified,
should shade as the mean of the two tilted planes (the footprint's average). And the normal maps'
fetch one level finer (NORMAL_MAP_LOD_BIAS)."""

from __future__ import annotations

import numpy as np
import pytest

from alight.core import shading
from alight.core.gpu import read_rgba8
from alight.core.scene import Camera, Scene
from alight.exchange.meshes import load_mesh
from alight.ibl.environment import Environment
from alight.render import normal_spread
from alight.render.mesh_upload import mip_levels
from alight.render.normal_spread import normal_map_levels, spread_to_alpha_channel
from tests.gltf_builder import USHORT, Gltf, grid_plane
from tests.gpu import renderer

# Straight on, the quad (2 x 2 at z = 0) filling most of the frame: v = +Z everywhere.
FRONT = Camera(position=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), ortho_half_height=1.2)
SIZE = 32          # the quad spans 27 pixels: a 256-texel map is read about 3 levels up
TEXELS = 256


def _texel(tilt_deg: float) -> np.ndarray:
    """The 8-bit texel of a tangent-space normal tilted about the tangent's bitangent axis (x)."""
    t = np.radians(tilt_deg)
    return np.rint((np.array([np.sin(t), 0.0, np.cos(t)]) + 1.0) / 2.0 * 255.0).astype(np.uint8)


def _map(*texels) -> np.ndarray:
    """A TEXELS^2 RGBA map: one texel, or a 1-texel checker of two."""
    y, x = np.mgrid[0:TEXELS, 0:TEXELS]
    pick = ((x + y) % len(texels))[..., None]
    rgb = np.where(pick == 0, texels[0], texels[-1])
    return np.concatenate([rgb, np.full((TEXELS, TEXELS, 1), 255)], axis=2).astype(np.uint8)


def _plane(path, roughness: float, normal_map: np.ndarray | None, scale: float | None = None, normal=None):
    """The 2 x 2 metal quad facing +Z (tangent +X, bitangent +Y), its vertex normals ``normal``."""
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(2)
    if normal is not None:
        normals = np.tile(np.asarray(normal, np.float64) / np.linalg.norm(normal), (len(normals), 1))
    material = {"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 1.0,
                                         "roughnessFactor": roughness}}
    if normal_map is not None:
        material["normalTexture"] = {"index": g.image(normal_map)}
        if scale is not None:
            material["normalTexture"]["scale"] = scale
    g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals),
                            "TEXCOORD_0": g.accessor(uvs)},
             "indices": g.accessor(idx.ravel(), USHORT), "material": g.material(**material)}])
    return g.save(path)


def _spot_environment() -> Environment:
    """Grey with a bright round spot (about 25 degrees) toward +Z, which the plane mirrors to the eye."""
    d, _ = shading.texel_directions(64, 128)
    spot = np.exp(-(1.0 - d[..., 2]) / (1.0 - np.cos(np.radians(25.0))))
    return Environment(np.repeat((0.2 + 6.0 * spot)[..., None], 3, axis=2).astype(np.float32), "spot")


@pytest.fixture(scope="module")
def lit():
    r = renderer()
    return r, r.bake(_spot_environment(), "medium")


def _render(lit, path, toksvig: bool = True, size: int = SIZE, camera: Camera = FRONT):
    """The plane's Frame (no MSAA), NORMAL_MAP_TOKSVIG as ``toksvig`` says."""
    r, maps = lit
    was = normal_spread.NORMAL_MAP_TOKSVIG
    normal_spread.NORMAL_MAP_TOKSVIG = toksvig
    try:
        r.meshes.release_meshes()   # the normal map's upload depends on the flag
        return r.render(Scene(mesh=load_mesh(str(path)), view="camera", camera=camera),
                        maps, size, size, aa="none")
    finally:
        normal_spread.NORMAL_MAP_TOKSVIG = was
        r.meshes.release_meshes()



def _quad_pixels(image: np.ndarray) -> np.ndarray:
    """The pixels well inside the quad (its middle 20 x 20)."""
    c = SIZE // 2
    return image[c - 10:c + 10, c - 10:c + 10, :3].astype(np.float64)


def test_levels_keep_gl_rgb_and_put_the_spread_in_alpha():
    rng = np.random.default_rng(3)
    image = rng.integers(0, 256, (64, 32, 3), dtype=np.uint8)
    image[..., 2] = rng.integers(128, 256, (64, 32))
    levels = normal_map_levels(image, 1.0)
    gl = mip_levels(image, False)
    assert len(levels) == len(gl)
    for mine, theirs in zip(levels, gl):
        assert np.array_equal(mine[..., :3], theirs[..., :3])   # the filtered normal is unchanged
    assert not levels[0][..., 3].any()                           # level 0: no widening
    assert all(level[..., 3].mean() > 100 for level in levels[1:])   # random normals: a wide spread
    assert normal_map_levels(np.zeros((6, 8, 3), np.uint8), 1.0) is None   # not a power of two


def test_a_flat_8_bit_map_has_no_spread_at_any_level():
    # (128, 128, 255) decodes to length 1.00002, not 1: its renormalised normals agree exactly
    for scale in (1.0, 0.3, 2.0):
        assert all(not level[..., 3].any() for level in normal_map_levels(_map(np.array([128, 128, 255])), scale))


def test_a_checker_of_two_tilts_reads_toksvigs_spread_and_honours_the_scale():
    t = 10.0
    image = _map(_texel(t), _texel(-t))[..., :3]
    m = _texel(t) / 255.0 * 2.0 - 1.0
    for scale in (1.0, 0.5):
        tilted = np.array([m[0] * scale, m[1] * scale, m[2]])
        length = abs(tilted[2]) / np.linalg.norm(tilted)   # the mean of (x, y, z) and (-x, y, z): y is tiny
        want = spread_to_alpha_channel(np.array([length]))[0]
        levels = normal_map_levels(image, scale)
        assert np.abs(levels[1][..., 3].astype(int) - int(want)).max() <= 1
        assert np.abs(levels[4][..., 3].astype(int) - int(want)).max() <= 1
    # and the encoding: A = 255 (sigma^2)^(1/4), sigma^2 = (1 - |Na|) / |Na|
    assert spread_to_alpha_channel(np.array([1.0, 0.5, 0.9]))[2] == round(255 * ((0.1 / 0.9) ** 0.25))
    assert list(spread_to_alpha_channel(np.array([1.0, 0.5]))) == [0, 255]


def test_mirror_with_a_flat_normal_map_is_not_widened(lit, tmp_path):
    # (128, 128, 255) decodes to (1/255, 1/255, 1): a normal 0.3 degrees off the plane's, and of
    # length 1.00002, not 1. The widening must add nothing to it at any level.
    flat = _map(np.array([128, 128, 255]))
    mapped = _plane(tmp_path / "flat.glb", 0.0, flat)
    c = 128 / 255 * 2 - 1
    twin = _plane(tmp_path / "twin.glb", 0.0, None, normal=(c, c, 1.0))   # its normal without a map
    for size in (SIZE, 256):   # the map minified (read 3 levels up) and magnified (level 0)
        on = _render(lit, mapped, True, size).srgb.astype(int)
        off = _render(lit, mapped, False, size).srgb.astype(int)
        assert np.array_equal(on, off), size          # exactly the shading before the widening
        bare = _render(lit, twin, True, size).srgb.astype(int)
        assert np.abs(on - bare).max() <= 1, size     # the mirror without a map, to 1/255


# relMAE of the plane's middle against the footprint average (the two tilted planes' mean). Measured
# (spot 25 degrees, roughness 0.05): t = 5 degrees 0.019 widened, 0.138 at the mean normal alone
# (the shading before NORMAL_MAP_TOKSVIG); t = 8: 0.055 and 0.351. With an 8-degree spot, where one
# widened lobe stands for two lobes 16 degrees apart, 0.53 and 0.82 at t = 5: still closer, not close.
FOOTPRINT_REL = 0.08


@pytest.mark.parametrize("tilt", [5.0, 8.0])
def test_fine_checker_of_tilts_shades_as_the_footprint_average(lit, tmp_path, tilt):
    # A glossy metal plane whose map alternates two tilts (+-t) texel by texel, seen 8 texels to
    # the pixel: the pixel's true value is the mean of the two tilted planes' shading (each a
    # uniform map, which mips leave as it is). Shaded at the mean normal alone the plane mirrors
    # the spot as if flat (too bright); the widening spreads it as the two tilts do.
    checker = _plane(tmp_path / "checker.glb", 0.05, _map(_texel(tilt), _texel(-tilt)))
    plus = _render(lit, _plane(tmp_path / "plus.glb", 0.05, _map(_texel(tilt)))).linear
    minus = _render(lit, _plane(tmp_path / "minus.glb", 0.05, _map(_texel(-tilt)))).linear
    want = 0.5 * (_quad_pixels(plus) + _quad_pixels(minus))
    widened = _quad_pixels(_render(lit, checker, True).linear)
    sharp = _quad_pixels(_render(lit, checker, False).linear)
    err = lambda got: float(np.abs(got - want).sum() / want.sum())   # noqa: E731
    assert err(sharp) > 1.5 * FOOTPRINT_REL          # the shading before: far off
    assert err(widened) < FOOTPRINT_REL, (err(widened), err(sharp))


def test_the_define_and_the_upload_only_where_a_part_has_a_normal_map(tmp_path):
    from alight.render.gpu_mesh import texture_key
    from alight.render.mesh_upload import prepare_upload
    from alight.render.variants import part_defines

    r = renderer()
    image = _map(_texel(10.0), _texel(-10.0))
    for path, has_map in ((_plane(tmp_path / "m.glb", 0.2, image, scale=0.5), True),
                          (_plane(tmp_path / "b.glb", 0.2, None), False)):
        mesh = load_mesh(str(path))
        for toksvig in (True, False):
            normal_spread.NORMAL_MAP_TOKSVIG = toksvig
            try:
                r.meshes.release_meshes()
                gpu = r.meshes.parts(mesh)[0]
                defines = part_defines(Scene(mesh=mesh), gpu, mesh.parts[0], set())
            finally:
                normal_spread.NORMAL_MAP_TOKSVIG = True
            assert ("NORMAL_MAP_TOKSVIG" in defines) == (has_map and toksvig)
            if has_map and toksvig:
                # the levels as normal_map_levels makes them at the material's scale (the spread
                # made on the GPU: alight.render.normal_spread_pass), in the frame's upload and in
                # the editor's (mesh_upload: prepare_upload's RGB levels with A = 0, its steps
                # the spread), under the same key
                want = normal_map_levels(image, 0.5)
                assert want[1][..., 3].min() > 0
                got = [read_rgba8(r.ctx, gpu.textures["normal"], n) for n in range(len(want))]
                assert all(np.array_equal(a, b) for a, b in zip(got, want))
                upload = prepare_upload(mesh)
                (key, _, _, levels), = upload.textures
                assert key == texture_key(mesh.parts[0].material.textures()["normal"], False, 0.5)
                assert all(np.array_equal(a[..., :3], b[..., :3]) and not a[..., 3].any()
                           for a, b in zip(levels, want))
                while upload.next < len(upload.pieces):
                    upload.step(r.ctx, r.shaders, r.meshes, r.shadow_maps)
                staged = [read_rgba8(r.ctx, upload.made[0], n) for n in range(len(want))]
                upload.drop()
                assert all(np.array_equal(a, b) for a, b in zip(staged, want))
    r.meshes.release_meshes()


def _stripes(tilt_deg: float, width: int) -> np.ndarray:
    """A TEXELS^2 RGBA map of stripes ``width`` texels wide across x, tilted +-t in turn."""
    x = np.arange(TEXELS)[None, :, None] * np.ones((TEXELS, 1, 1), int)
    rgb = np.where((x // width) % 2 == 0, _texel(tilt_deg), _texel(-tilt_deg))
    return np.concatenate([rgb, np.full((TEXELS, TEXELS, 1), 255)], axis=2).astype(np.uint8)


def _render_bias(lit, path, bias: float, size: int = SIZE):
    was = normal_spread.NORMAL_MAP_LOD_BIAS
    normal_spread.NORMAL_MAP_LOD_BIAS = bias
    try:
        return _render(lit, path, True, size)
    finally:
        normal_spread.NORMAL_MAP_LOD_BIAS = was


def test_the_normal_map_is_fetched_one_level_finer(lit, tmp_path):
    # NORMAL_MAP_LOD_BIAS (mesh_material.glsl normal_from_map): stripes 8 texels wide, read
    # about 3.2 levels up at SIZE. Without the bias the fetch blends level 3 (one stripe a texel)
    # with level 4 (both stripes' mean: flat), so the tilts fade; one level finer reads levels 2
    # and 3, both striped, so the pixels see the tilts. Magnified (level 0 either way) the bias
    # changes nothing.
    assert normal_spread.NORMAL_MAP_LOD_BIAS == -1.0
    path = _plane(tmp_path / "stripes.glb", 0.05, _stripes(10.0, 8))
    contrast = lambda image: float(_quad_pixels(image).mean(axis=(0, 2)).std())   # noqa: E731 (across columns)
    plain = _render_bias(lit, path, 0.0).linear
    finer = _render_bias(lit, path, -1.0).linear
    assert contrast(finer) > 1.3 * contrast(plain), (contrast(finer), contrast(plain))
    big = [_render_bias(lit, path, b, 512).srgb.astype(int) for b in (0.0, -1.0)]
    assert np.array_equal(big[0], big[1])


def test_the_lod_bias_define_only_where_a_part_has_a_normal_map(tmp_path):
    from alight.render.variants import part_defines

    r = renderer()
    image = _map(_texel(10.0), _texel(-10.0))
    for path, has_map in ((_plane(tmp_path / "m.glb", 0.2, image), True), (_plane(tmp_path / "b.glb", 0.2, None), False)):
        mesh = load_mesh(str(path))
        gpu = r.meshes.parts(mesh)[0]
        for bias in (-1.0, 0.0):
            was, normal_spread.NORMAL_MAP_LOD_BIAS = normal_spread.NORMAL_MAP_LOD_BIAS, bias
            try:
                defines = part_defines(Scene(mesh=mesh), gpu, mesh.parts[0], set())
            finally:
                normal_spread.NORMAL_MAP_LOD_BIAS = was
            assert ("NORMAL_MAP_LOD_BIAS" in defines) == (has_map and bias != 0.0)
            if has_map and bias:
                assert float(defines["NORMAL_MAP_LOD_BIAS"]) == bias
    r.meshes.release_meshes()
