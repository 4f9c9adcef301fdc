"""alight.ibl.environment: the studio, loading the shared maps, refusing and repairing bad files."""

from __future__ import annotations

import tracemalloc

import numpy as np
import OpenImageIO as oiio
import pytest

from alight.core.shading import equirect_uv_to_direction, texel_directions
from alight.errors import AlightError
from alight.ibl.environment import (
    MAX_WIDTH,
    STUDIO,
    Environment,
    constant_environment,
    load_environment,
    studio_environment,
)

ENV_FILES = [
    "royal_esplanade_1k.hdr", "venice_sunset_1k.hdr", "quarry_01_1k.hdr", "moonless_golf_1k.hdr",
    "pedestrian_overpass_1k.hdr", "blouberg_sunrise_2_1k.hdr", "spot1Lux.hdr", "newport_loft.hdr",
    "piz_compressed.exr",
]


def _write(path, pixels, fmt=oiio.FLOAT, tile=None):
    pixels = np.ascontiguousarray(pixels, dtype=np.float32)
    h, w, c = pixels.shape
    spec = oiio.ImageSpec(w, h, c, fmt)
    if tile:
        spec.tile_width = spec.tile_height = tile
        spec.tile_depth = 1
    out = oiio.ImageOutput.create(str(path))
    assert out is not None, oiio.geterror()
    assert out.open(str(path), spec), out.geterror()
    assert out.write_image(pixels), out.geterror()
    out.close()
    return path


def _check_invariants(env: Environment):
    r = env.radiance
    assert r.dtype == np.float32 and r.ndim == 3 and r.shape[2] == 3
    assert r.shape[1] == 2 * r.shape[0]
    assert r.flags["C_CONTIGUOUS"]
    assert np.all(np.isfinite(r)) and r.min() >= 0.0


def _one_line_error(excinfo, *fragments):
    msg = str(excinfo.value)
    assert "\n" not in msg and "Traceback" not in msg
    for f in fragments:
        assert f in msg, msg
    assert excinfo.value.__cause__ is None and excinfo.value.__suppress_context__
    return msg


# --- the studio -----------------------------------------------------------------------------

@pytest.fixture(scope="module")
def studio():
    return studio_environment(1024)


def test_studio_is_a_valid_map(studio):
    _check_invariants(studio)
    assert studio.radiance.shape == (512, 1024, 3)
    assert studio.name == "studio" and studio.warnings == []
    assert load_environment("studio").content_hash == studio.content_hash  # deterministic


def test_studio_levels(studio):
    r = studio.radiance
    lum = r @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    assert lum.max() > 0.9 * min(STUDIO["softboxes"][0]["radiance"])  # the key soft box at full strength
    assert lum.max() < 30.0
    h = r.shape[0]
    nadir = lum[-h // 16:].mean()
    below_horizon = lum[h // 2 + 4:h // 2 + 20].mean()
    assert nadir < 0.06  # dark floor under the subject
    assert nadir < below_horizon  # floor darkens toward the nadir
    assert 0.2 <= np.median(lum[h // 2 - 20:h // 2 - 4]) <= 0.5  # backdrop at eye level
    assert lum[h // 2:].max() < 12.0  # nothing but the strip's lower end below the horizon


def test_studio_key_light_is_up_left_front(studio):
    lum = studio.radiance @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    j, i = np.unravel_index(np.argmax(lum), lum.shape)
    h, w = lum.shape
    d = equirect_uv_to_direction(np.array([(i + 0.5) / w, (j + 0.5) / h]))
    assert d[0] < -0.2 and d[1] > 0.2 and d[2] > 0.2, d  # -X (left), +Y (up), +Z (toward the viewer)
    assert [b["name"] for b in STUDIO["softboxes"]] == ["key", "strip", "top"]


def test_studio_right_strip_and_top_light(studio):
    r = studio.radiance
    dirs, _ = texel_directions(*r.shape[:2])
    lum = r @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    right = dirs[..., 0] > 0.9
    up = dirs[..., 1] > 0.97
    # Each soft box reaches at least 80% of its table radiance where it lies; the backdrop is far dimmer.
    boxes = {b["name"]: b for b in STUDIO["softboxes"]}
    strip, top = min(boxes["strip"]["radiance"]), min(boxes["top"]["radiance"])
    assert lum[right].max() > 0.8 * strip > 5 * max(STUDIO["backdrop_horizon"])
    assert lum[up].mean() > 0.8 * top


def test_studio_other_sizes():
    # Its speed is measured in benchmarks/, not asserted here (the machine is shared and noisy).
    small = studio_environment(256)
    _check_invariants(small)
    assert small.radiance.shape == (128, 256, 3)


def test_constant_environment():
    env = constant_environment((1.0, 0.5, 0.25), width=32)
    _check_invariants(env)
    assert env.radiance.shape == (16, 32, 3)
    assert np.all(env.radiance == np.array([1.0, 0.5, 0.25], np.float32))
    assert constant_environment(2.0).radiance.shape == (32, 64, 3)
    with pytest.raises(ValueError):
        constant_environment(-1.0)


def test_content_hash():
    a = constant_environment(1.0, 32)
    b = constant_environment(1.0, 32)
    c = constant_environment(1.0, 64)
    assert a.content_hash == b.content_hash and len(a.content_hash) == 64
    assert a.content_hash != c.content_hash
    assert a.content_hash != constant_environment(1.001, 32).content_hash


# --- the shared maps ------------------------------------------------------------------------

@pytest.mark.parametrize("name", ENV_FILES)
def test_shared_maps_load(shared_data, name):
    path = shared_data / "env" / name
    env = load_environment(str(path))
    _check_invariants(env)
    assert env.name == str(path)
    assert env.warnings == []
    assert env.radiance.max() > 0.0


def test_quarry_peak(shared_data):
    env = load_environment(str(shared_data / "env" / "quarry_01_1k.hdr"))
    assert env.radiance.shape == (512, 1024, 3)
    assert env.radiance.max() == pytest.approx(86528.0, rel=0.01)


def test_newport_loft_size_and_max_width(shared_data):
    path = str(shared_data / "env" / "newport_loft.hdr")
    assert load_environment(path).radiance.shape == (800, 1600, 3)
    small = load_environment(path, max_width=1024)
    assert small.radiance.shape == (400, 800, 3)
    assert len(small.warnings) == 1 and "newport_loft.hdr" in small.warnings[0]


def test_piz_matches_oiio(shared_data):
    path = str(shared_data / "env" / "piz_compressed.exr")
    env = load_environment(path)
    ref = oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[..., :3]
    np.testing.assert_array_equal(env.radiance, ref)


def test_memorial_is_not_2_to_1(shared_data):
    with pytest.raises(AlightError) as ei:
        load_environment(str(shared_data / "env" / "memorial.exr"))
    _one_line_error(ei, "memorial.exr", "not a 2:1 equirectangular map (512x768)")


# --- bad files ------------------------------------------------------------------------------

def test_missing_file(tmp_path):
    with pytest.raises(AlightError) as ei:
        load_environment(str(tmp_path / "nope.hdr"))
    msg = _one_line_error(ei, "nope.hdr")
    assert msg.startswith(str(tmp_path / "nope.hdr"))


def test_truncated_hdr(shared_data, tmp_path):
    data = (shared_data / "env" / "royal_esplanade_1k.hdr").read_bytes()
    bad = tmp_path / "royal_half.hdr"
    bad.write_bytes(data[: len(data) // 2])
    with pytest.raises(AlightError) as ei:
        load_environment(str(bad))
    _one_line_error(ei, "royal_half.hdr", "truncated")


def test_truncated_exr(shared_data, tmp_path):
    data = (shared_data / "env" / "piz_compressed.exr").read_bytes()
    bad = tmp_path / "piz_half.exr"
    bad.write_bytes(data[: len(data) // 2])
    with pytest.raises(AlightError) as ei:
        load_environment(str(bad))
    _one_line_error(ei, "piz_half.exr")


def test_random_bytes(tmp_path):
    bad = tmp_path / "x.hdr"
    bad.write_bytes(np.random.default_rng(0).integers(0, 256, 20000, dtype=np.uint8).tobytes())
    with pytest.raises(AlightError) as ei:
        load_environment(str(bad))
    _one_line_error(ei, "x.hdr")


def test_empty_file(tmp_path):
    bad = tmp_path / "empty.exr"
    bad.write_bytes(b"")
    with pytest.raises(AlightError) as ei:
        load_environment(str(bad))
    _one_line_error(ei, "empty.exr", "empty")


def test_non_finite_and_negative_texels_repaired(tmp_path):
    px = np.ones((16, 32, 3), np.float32)
    px[0, 0, 0] = np.nan
    px[1, 2, 1] = np.inf
    px[2, 3, 2] = -np.inf
    px[3, 4, :] = -0.5
    px[4, 5, 0] = -1e-3
    px[4, 5, 1] = np.nan  # two bad channels in one texel count once
    path = _write(tmp_path / "nan.exr", px)
    env = load_environment(str(path))
    _check_invariants(env)
    assert len(env.warnings) == 1
    assert "nan.exr" in env.warnings[0] and "5 NaN/Inf/negative texels set to 0" in env.warnings[0]
    for j, i in [(0, 0), (1, 2), (2, 3), (3, 4), (4, 5)]:
        assert np.all(env.radiance[j, i] == 0.0)
    assert env.radiance.sum() == pytest.approx(16 * 32 * 3 - 5 * 3)


def test_channels(tmp_path):
    grey = np.linspace(0, 1, 16 * 32, dtype=np.float32).reshape(16, 32, 1)
    env = load_environment(str(_write(tmp_path / "grey.exr", grey)))
    for c in range(3):
        np.testing.assert_array_equal(env.radiance[..., c], grey[..., 0])

    rgba = np.random.default_rng(1).random((16, 32, 4)).astype(np.float32)
    env = load_environment(str(_write(tmp_path / "rgba.exr", rgba)))
    np.testing.assert_array_equal(env.radiance, rgba[..., :3])

    with pytest.raises(AlightError) as ei:
        load_environment(str(_write(tmp_path / "two.exr", np.ones((16, 32, 2), np.float32))))
    _one_line_error(ei, "two.exr", "channels R, G: need R, G and B, or Y (grey)")


def test_tiled_exr(tmp_path):
    px = np.random.default_rng(2).random((64, 128, 3)).astype(np.float32)
    env = load_environment(str(_write(tmp_path / "tiled.exr", px, tile=32)))
    np.testing.assert_array_equal(env.radiance, px)
    env = load_environment(str(tmp_path / "tiled.exr"), max_width=32)
    assert env.radiance.shape == (16, 32, 3)


def test_big_map_box_reduced_in_strips(tmp_path):
    h, w = 2048, 4096
    rows = (0.5 + 3.0 * np.sin(np.arange(h) / 37.0) ** 2).astype(np.float32)
    px = np.empty((h, w, 3), np.float32)
    px[...] = rows[:, None, None] * np.array([1.0, 0.5, 2.0], np.float32)
    path = _write(tmp_path / "big.exr", px, fmt=oiio.HALF)
    px = oiio.ImageBuf(str(path)).get_pixels(oiio.FLOAT)  # what the file holds (half precision)
    _, om = texel_directions(h, w)
    ref = np.einsum("hwc,hw->c", px.astype(np.float64), om)
    del px

    tracemalloc.start()
    try:
        env = load_environment(str(path), max_width=1024)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    _check_invariants(env)
    assert env.radiance.shape == (512, 1024, 3)
    assert peak < 48e6  # the full map is 100 MB as float RGB: it is never held whole
    assert len(env.warnings) == 1 and "big.exr" in env.warnings[0] and "1024x512" in env.warnings[0]
    _, om2 = texel_directions(512, 1024)
    got = np.einsum("hwc,hw->c", env.radiance.astype(np.float64), om2)
    np.testing.assert_allclose(got, ref, rtol=5e-3)
    # constant rows stay constant along the row
    assert np.ptp(env.radiance[100, :, 0]) < 1e-5 * env.radiance[100, 0, 0] + 1e-7


def test_default_max_width():
    assert MAX_WIDTH == 4096
