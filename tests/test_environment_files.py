"""Environment files in every legal layout, and huge texels.

Each test writes its own files: Radiance pictures in all eight orientations (literal-run RLE
scanlines, placed by the definition in Radiance's resolu.c), OpenEXR files with display and data
windows, tiles, several parts, layers, and luminance channels.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import OpenImageIO as oiio
import pytest

from alight.errors import AlightError
from alight.exchange.environment_files import RADIANCE_MAX
from alight.ibl.environment import Environment, load_environment

H, W = 32, 64


def _picture(h: int = H, w: int = W) -> np.ndarray:
    """A map no flip, turn or transpose leaves unchanged, with values RGBE stores exactly."""
    rng = np.random.default_rng(7)
    # mantissas 128..255 of one shared exponent per texel: exact in RGBE
    m = rng.integers(0, 256, (h, w, 3))
    m[..., 0] = np.maximum(m[..., 0], 128)
    exp = rng.integers(-3, 4, (h, w, 1))
    pic = (m + 0.0) / 256.0 * np.exp2(exp)
    pic[:4, : w // 4] = 8.0                      # a bright patch up and to the left
    pic[h - 3:, w // 2:] = (0.5, 0.0, 0.0)       # red ground in the right half, low down
    return pic.astype(np.float32)


def _rgbe(pixels: np.ndarray) -> np.ndarray:
    """float RGB -> RGBE bytes (Ward's shared exponent), (..., 4) uint8."""
    peak = pixels.max(axis=-1)
    mant, exp = np.frexp(peak)
    scale = np.where(peak > 0, mant * 256.0 / np.where(peak > 0, peak, 1.0), 0.0)
    out = np.zeros(pixels.shape[:-1] + (4,), np.uint8)
    out[..., :3] = np.floor(pixels * scale[..., None]).astype(np.uint8)
    out[..., 3] = np.where(peak > 0, exp + 128, 0).astype(np.uint8)
    return out


def _stored_order(picture: np.ndarray, resolution: str) -> np.ndarray:
    """The picture as the scanlines a file with this resolution string holds: (scanlines, length, 3).

    Radiance's resolu.c: the picture's true coordinates have their origin at the lower left, x to
    the right, y up; the first axis of the string is the one scanlines follow each other along
    (sign: the direction), the second the one pixels follow along within a scanline (pix2loc).
    """
    h, w = picture.shape[:2]
    major, minor = resolution.split()[0], resolution.split()[2]
    n_scan, length = (h, w) if major[1] == "Y" else (w, h)
    s, p = np.meshgrid(np.arange(n_scan), np.arange(length), indexing="ij")
    coords = {major[1]: s if major[0] == "+" else n_scan - 1 - s,
              minor[1]: p if minor[0] == "+" else length - 1 - p}
    x, y_up = coords["X"], coords["Y"]
    return picture[h - 1 - y_up, x]


def write_radiance(path, picture: np.ndarray, resolution: str = "-Y {h} +X {w}") -> None:
    """A Radiance picture with RLE scanlines (literal runs only), in the order the string says."""
    h, w = picture.shape[:2]
    resolution = resolution.format(h=h, w=w)
    stored = _rgbe(_stored_order(picture, resolution))
    chunks = [b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n", resolution.encode() + b"\n"]
    length = stored.shape[1]
    for scan in stored:
        chunks.append(bytes([2, 2, length >> 8, length & 255]))
        for c in range(4):
            comp = scan[:, c]
            for i in range(0, length, 128):
                part = comp[i:i + 128]
                chunks.append(bytes([len(part)]) + part.tobytes())
    with open(path, "wb") as f:
        f.write(b"".join(chunks))


def _decoded(picture: np.ndarray) -> np.ndarray:
    """What an RGBE file of ``picture`` holds, as floats (OpenImageIO's decoding)."""
    e = _rgbe(picture)
    return np.where(e[..., 3:] > 0, e[..., :3] * np.exp2(e[..., 3:].astype(np.float64) - 136.0), 0.0).astype(np.float32)


ORIENTATIONS = ["-Y {h} +X {w}", "-Y {h} -X {w}", "+Y {h} -X {w}", "+Y {h} +X {w}",
                "+X {w} -Y {h}", "+X {w} +Y {h}", "-X {w} +Y {h}", "-X {w} -Y {h}"]


@pytest.mark.parametrize("resolution", ORIENTATIONS)
def test_radiance_orientations_match_the_control(tmp_path, resolution):
    pic = _picture()
    write_radiance(tmp_path / "control.hdr", pic)
    write_radiance(tmp_path / "oriented.hdr", pic, resolution)
    control = load_environment(str(tmp_path / "control.hdr"))
    oriented = load_environment(str(tmp_path / "oriented.hdr"))
    np.testing.assert_array_equal(control.radiance, _decoded(pic))
    np.testing.assert_array_equal(oriented.radiance, control.radiance)
    assert oriented.warnings == []


@pytest.mark.parametrize("resolution", ["+Y {h} +X {w}", "-X {w} +Y {h}"])
def test_oriented_radiance_box_reduces_like_the_control(tmp_path, resolution):
    pic = _picture(64, 128)
    write_radiance(tmp_path / "control.hdr", pic)
    write_radiance(tmp_path / "oriented.hdr", pic, resolution)
    a = load_environment(str(tmp_path / "control.hdr"), max_width=32)
    b = load_environment(str(tmp_path / "oriented.hdr"), max_width=32)
    assert b.radiance.shape == (16, 32, 3)
    np.testing.assert_allclose(b.radiance, a.radiance, rtol=1e-6, atol=1e-7)


def test_shared_plus_y_case_is_the_control(shared_data):
    cases = shared_data / "cases"
    a = load_environment(str(cases / "hdr_minusY_rle.hdr"))
    b = load_environment(str(cases / "hdr_plusY_rle.hdr"))
    np.testing.assert_array_equal(a.radiance, b.radiance)
    lum = a.radiance.mean(axis=2)
    # "sky above, red ground below"
    sky, ground = a.radiance[: H // 2].mean(axis=(0, 1)), a.radiance[H // 2:].mean(axis=(0, 1))
    assert ground[0] > 2 * ground[2] and sky[2] > ground[2]
    assert lum.max() > 0


def test_plus_y_renders_like_minus_y(tmp_path):
    """The equivalence test of the issue: a +Y Radiance file renders (EXR, no tone mapping) within
    1% relMAE of the same picture stored -Y."""
    from alight.accuracy.metrics import relative_mae
    from alight.core.material import Material
    from alight.core.scene import Scene
    from tests.gpu import renderer

    pic = _picture()
    write_radiance(tmp_path / "minus.hdr", pic)
    write_radiance(tmp_path / "plus.hdr", pic, "+Y {h} +X {w}")
    write_radiance(tmp_path / "upside_down.hdr", pic[::-1])   # what ignoring the orientation gives
    r = renderer()
    scene = Scene(view="probe", material=Material(roughness=0.3))
    frames = {name: r.render(scene, r.bake(load_environment(str(tmp_path / name)), "low"), 48, 48,
                             read_srgb=False).linear
              for name in ("minus.hdr", "plus.hdr", "upside_down.hdr")}
    assert relative_mae(frames["plus.hdr"], frames["minus.hdr"]) < 0.01
    assert relative_mae(frames["upside_down.hdr"], frames["minus.hdr"]) > 0.05


# --- OpenEXR windows ----------------------------------------------------------------------

def _write_exr(path, pixels, names=None, data=None, display=None, tile=None, fmt=oiio.FLOAT):
    pixels = np.ascontiguousarray(pixels, dtype=np.float32)
    h, w, c = pixels.shape
    spec = oiio.ImageSpec(w, h, c, fmt)
    if names:
        spec.channelnames = tuple(names)
    if data:
        spec.x, spec.y = data
    if display:
        spec.full_x, spec.full_y, spec.full_width, spec.full_height = display
    if tile:
        spec.tile_width = spec.tile_height = tile
        spec.tile_depth = 1
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec), out.geterror()
    assert out.write_image(pixels), out.geterror()
    out.close()
    return str(path)


@pytest.mark.parametrize("tile", [None, 8])
@pytest.mark.parametrize("origin, size", [((24, 4), (16, 8)),       # inside the display window
                                          ((-8, -3), (40, 12)),     # over its top-left corner
                                          ((50, 20), (30, 20)),     # over its bottom-right corner
                                          ((-10, -5), (90, 45))])   # larger than it on every side
def test_exr_display_window_is_the_picture(tmp_path, origin, size, tile):
    rng = np.random.default_rng(3)
    data = rng.uniform(0.5, 2.0, (size[1], size[0], 3)).astype(np.float32)
    path = _write_exr(tmp_path / "win.exr", data, data=origin, display=(0, 0, W, H), tile=tile)
    expect = np.zeros((H, W, 3), np.float32)
    x0, y0 = origin
    for j in range(size[1]):
        for i in range(size[0]):
            if 0 <= x0 + i < W and 0 <= y0 + j < H:
                expect[y0 + j, x0 + i] = data[j, i]
    env = load_environment(path)
    assert env.radiance.shape == (H, W, 3)
    np.testing.assert_array_equal(env.radiance, expect)
    assert env.warnings == []


def test_exr_display_window_offset(tmp_path):
    """A display window that does not start at 0: the picture is still the display window."""
    data = np.arange(W * H * 3, dtype=np.float32).reshape(H, W, 3)
    path = _write_exr(tmp_path / "offset.exr", data, data=(100, 200), display=(100, 200, W, H))
    np.testing.assert_array_equal(load_environment(path).radiance, data)


def test_exr_shape_is_the_display_windows(tmp_path):
    # data 64x32 (2:1) inside a 64x64 display window: the picture is not 2:1
    path = _write_exr(tmp_path / "square.exr", np.ones((H, W, 3)), display=(0, 0, W, W))
    with pytest.raises(AlightError) as ei:
        load_environment(path)
    assert "not a 2:1 equirectangular map (64x64)" in str(ei.value) and "square.exr" in str(ei.value)


def test_shared_data_window_case(shared_data):
    env = load_environment(str(shared_data / "cases" / "exr_datawindow_crop.exr"))
    assert env.radiance.shape == (32, 64, 3)
    lit = np.argwhere(env.radiance.max(axis=2) > 0)
    assert lit[:, 0].min() == 4 and lit[:, 0].max() == 11 and lit[:, 1].min() == 24 and lit[:, 1].max() == 39
    assert lit[:, 0].max() < 16    # "a bright patch above the horizon"


# --- parts, layers, channels --------------------------------------------------------------

def _write_parts(path, parts):
    """parts: [(name, channel names, pixels)] as a multi-part OpenEXR file."""
    specs = []
    for name, names, px in parts:
        h, w, c = px.shape
        spec = oiio.ImageSpec(w, h, c, oiio.FLOAT)
        spec.channelnames = tuple(names)
        spec.attribute("name", name)
        specs.append(spec)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), specs), out.geterror()
    for i, (_, _, px) in enumerate(parts):
        if i:
            assert out.open(str(path), specs[i], "AppendSubimage"), out.geterror()
        assert out.write_image(np.ascontiguousarray(px, np.float32)), out.geterror()
    out.close()
    return str(path)


def test_multipart_takes_the_first_rgb_part(tmp_path):
    rgb = np.random.default_rng(4).uniform(0, 1, (H, W, 3))
    path = _write_parts(tmp_path / "mp.exr", [("depth", ["Z"], np.full((H, W, 1), 7.0)),
                                              ("beauty", ["R", "G", "B"], rgb),
                                              ("other", ["R", "G", "B"], rgb * 0 + 5)])
    env = load_environment(path)
    np.testing.assert_array_equal(env.radiance, rgb.astype(np.float32))
    assert len(env.warnings) == 1
    w = env.warnings[0]
    assert w.startswith(path) and "took part 1 'beauty' (R, G, B)" in w and "part 0 'depth' (Z)" in w


def test_shared_multipart_case(shared_data):
    env = load_environment(str(shared_data / "cases" / "exr_multipart_Z_first.exr"))
    assert len(env.warnings) == 1 and "took part 1 'beauty'" in env.warnings[0]
    assert env.radiance.max() > 0 and env.radiance.std() > 0


def test_multipart_without_colour_is_refused_naming_the_parts(tmp_path):
    path = _write_parts(tmp_path / "nocolour.exr", [("depth", ["Z"], np.ones((H, W, 1))),
                                                    ("normals", ["N.x", "N.y", "N.z"], np.ones((H, W, 3)))])
    with pytest.raises(AlightError) as ei:
        load_environment(path)
    msg = str(ei.value)
    assert "\n" not in msg and msg.startswith(path)
    assert "part 0 'depth': Z" in msg and "part 1 'normals': N.x, N.y, N.z" in msg


def test_depth_only_file_is_refused(tmp_path):
    path = _write_exr(tmp_path / "z.exr", np.ones((H, W, 1)), names=["Z"])
    with pytest.raises(AlightError) as ei:
        load_environment(path)
    assert "channels Z: need R, G and B, or Y (grey)" in str(ei.value)


@pytest.mark.parametrize("names", [["Y"], ["Y", "A"], ["A", "Y"]])
def test_luminance_loads_as_grey(tmp_path, names):
    px = np.random.default_rng(5).uniform(0, 3, (H, W, len(names))).astype(np.float32)
    path = _write_exr(tmp_path / "y.exr", px, names=names)
    env = load_environment(path)
    y = px[..., names.index("Y")]
    for c in range(3):
        np.testing.assert_array_equal(env.radiance[..., c], y)
    assert env.warnings == []


def test_shared_luminance_alpha_case(shared_data):
    env = load_environment(str(shared_data / "cases" / "exr_YA.exr"))
    r = env.radiance
    assert r.max() > 0 and np.array_equal(r[..., 0], r[..., 1]) and np.array_equal(r[..., 1], r[..., 2])


def test_channels_chosen_by_name_not_position(tmp_path):
    px = np.random.default_rng(6).uniform(0, 1, (H, W, 4)).astype(np.float32)
    path = _write_exr(tmp_path / "abgr.exr", px, names=["A", "B", "G", "R"])
    np.testing.assert_array_equal(load_environment(path).radiance, px[..., [3, 2, 1]])


def test_layer_when_no_plain_rgb(tmp_path):
    px = np.random.default_rng(8).uniform(0, 1, (H, W, 4)).astype(np.float32)
    path = _write_exr(tmp_path / "layers.exr", px, names=["depth.Z", "diffuse.R", "diffuse.G", "diffuse.B"])
    env = load_environment(path)
    np.testing.assert_array_equal(env.radiance, px[..., 1:])
    assert len(env.warnings) == 1 and "diffuse.R, diffuse.G, diffuse.B" in env.warnings[0]


# --- memory stays bounded for oriented and windowed files ----------------------------------

def test_transposed_radiance_is_read_in_strips(tmp_path):
    h, w = 2048, 4096
    rows = (0.5 + 3.0 * np.sin(np.arange(h) / 37.0) ** 2).astype(np.float32)
    cols = (1.0 + 0.5 * np.cos(np.arange(w) / 53.0)).astype(np.float32)
    pic = rows[:, None, None] * cols[None, :, None] * np.array([1.0, 0.5, 2.0], np.float32)
    write_radiance(tmp_path / "control.hdr", pic)
    write_radiance(tmp_path / "big.hdr", pic, "-X {w} +Y {h}")
    del pic
    control = load_environment(str(tmp_path / "control.hdr"), max_width=1024)
    tracemalloc.start()
    try:
        env = load_environment(str(tmp_path / "big.hdr"), max_width=1024)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert env.radiance.shape == (512, 1024, 3)
    assert peak < 48e6   # the full map is 100 MB as float RGB: it is never held whole
    np.testing.assert_allclose(env.radiance, control.radiance, rtol=1e-6)


# --- huge finite texels (item 14) ---------------------------------------------------------

def test_huge_texel_is_clamped_with_one_warning(tmp_path):
    px = np.ones((H, W, 3), np.float32)
    px[8, 40] = 1e30
    px[9, 41, 1] = 3.0e38
    px[10, 42] = RADIANCE_MAX        # at the clamp: kept, not counted
    env = load_environment(_write_exr(tmp_path / "hot.exr", px))
    assert env.radiance.max() == RADIANCE_MAX
    assert env.radiance[8, 40].tolist() == [RADIANCE_MAX] * 3
    assert env.radiance[9, 41].tolist() == [1.0, RADIANCE_MAX, 1.0]
    assert env.warnings == [f"{tmp_path / 'hot.exr'}: 2 texels above 1e+10 clamped to 1e+10 (the brightest was 3e+38)"]


def test_huge_texel_in_an_array_is_clamped():
    px = np.ones((H, W, 3), np.float32)
    px[3, 3] = 1e30
    px[4, 4] = np.nan
    env = Environment(px, "api")
    assert env.radiance.max() == RADIANCE_MAX and np.isfinite(env.radiance).all()
    assert px[3, 3, 0] == 1e30        # the caller's array is left alone
    assert env.warnings == ["api: 1 NaN/Inf/negative texels set to 0",
                            "api: 1 texel above 1e+10 clamped to 1e+10 (the brightest was 1e+30)"]


def test_the_clamp_changes_no_shared_map(shared_data):
    """RADIANCE_MAX is far above every real map: none of the shared ones is touched."""
    for path in sorted((shared_data / "env").iterdir()):
        peak = float(oiio.ImageBuf(str(path)).get_pixels(oiio.FLOAT).max())
        assert peak < RADIANCE_MAX / 1e4, path


def test_shared_huge_texel_case(shared_data):
    env = load_environment(str(shared_data / "cases" / "exr_texel_1e30_float.exr"))
    assert np.isfinite(env.radiance).all() and env.radiance.max() == RADIANCE_MAX
    assert len(env.warnings) == 1 and "clamped to 1e+10" in env.warnings[0]


@pytest.mark.parametrize("orientation", range(1, 9))
def test_exif_orientation_of_other_formats(tmp_path, orientation):
    """A TIFF's Orientation tag (TIFF 6.0: how the stored rows and columns lie in the picture) is
    applied like a Radiance file's: each of the eight gives the picture back."""
    pic = _picture()
    stored = {1: pic, 2: pic[:, ::-1], 3: pic[::-1, ::-1], 4: pic[::-1],
              5: pic.transpose(1, 0, 2), 6: pic[:, ::-1].transpose(1, 0, 2),    # 6: turn 90 CW to see it
              7: pic[::-1, ::-1].transpose(1, 0, 2), 8: pic[::-1].transpose(1, 0, 2)}[orientation]
    h, w, c = stored.shape
    spec = oiio.ImageSpec(w, h, c, oiio.FLOAT)
    spec.attribute("Orientation", orientation)
    path = str(tmp_path / "oriented.tif")
    out = oiio.ImageOutput.create(path)
    assert out.open(path, spec), out.geterror()
    assert out.write_image(np.ascontiguousarray(stored)), out.geterror()
    out.close()
    assert oiio.ImageInput.open(path).spec().get_int_attribute("Orientation") == orientation
    np.testing.assert_array_equal(load_environment(path).radiance, pic)
