"""Finite but huge values: nothing downstream of the loader overflows.

The loader clamps texels to RADIANCE_MAX (tests/test_environment_files.py). Here: a map holding
texels at that clamp bakes (every quality, both irradiance methods, the compact-source path)
to finite maps and renders to finite radiance; the tone map turns any finite radiance, even at
+32 EV, into a PNG that is neither black nor NaN; and a texture cannot carry such values.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import OpenImageIO as oiio
import pytest

from alight.core import shading
from alight.core.material import Material
from alight.core.mesh import sphere
from alight.core.scene import Display, Scene
from alight.exchange.environment_files import RADIANCE_MAX
from alight.ibl.bake import quality_named, read_cube
from alight.ibl.environment import Environment
from tests.conftest import REPO
from tests.gpu import evaluate, renderer

SILVER = Material(base_color=(0.972, 0.960, 0.915), metallic=1.0, roughness=0.05)
GREY = Material(base_color=(0.5, 0.5, 0.5), metallic=0.0, roughness=0.5)


def _hot_map(height: int) -> Environment:
    """Sky 1, ground 0.2 and one texel at the clamp, just above the horizon straight ahead (-Z,
    where the default camera looks): a compact source in a map tall enough to resolve one, a
    plain texel in a 32-row map."""
    px = np.full((height, 2 * height, 3), 1.0, np.float32)
    px[height // 2:] = 0.2
    px[height // 2 - 1, height] = RADIANCE_MAX
    return Environment(px, f"hot{height}")


@pytest.mark.parametrize("height", [32, 128])
@pytest.mark.parametrize("quality, irradiance", [("low", "sh9"), ("medium", "convolution"), ("medium", "sh9")])
def test_a_texel_at_the_clamp_bakes_and_renders_finite(height, quality, irradiance):
    env = _hot_map(height)
    assert env.warnings == []
    r = renderer()
    maps = r.bake(env, quality_named(quality, irradiance))
    levels = maps.quality.prefiltered_levels
    cubes = [read_cube(r.shaders, maps.environment, 0), read_cube(r.shaders, maps.irradiance, 0)]
    cubes += [read_cube(r.shaders, maps.prefiltered_radiance, m) for m in range(levels)]
    cubes += [read_cube(r.shaders, maps.prefiltered_radiance_mid, m) for m in range(levels - 1)]
    for faces in cubes:
        assert np.isfinite(faces).all() and faces.min() >= 0.0
    for scene in (Scene(material=SILVER, view="probe"), Scene(mesh=sphere(), material=GREY),
                  Scene(material=GREY, view="probe", display=Display(exposure=32.0))):
        frame = r.render(scene, maps, 32, 32)
        assert np.isfinite(frame.linear).all() and frame.linear.min() >= 0.0
        covered = frame.linear[..., 3] > 0
        assert frame.srgb[covered, :3].max() > 0    # not black
    # The background alone at +32 EV: every pixel white, the texel at the clamp too (4.3e19
    # there: the ACES fit's v*v overflowed to inf/inf = NaN, a black pixel, before its limit).
    frame = r.render(Scene(mesh=None, display=Display(exposure=32.0)), maps, 33, 33)
    assert np.isfinite(frame.linear).all() and frame.linear[..., :3].max() > 1e9
    assert frame.srgb[..., :3].min() == 255


def test_tone_mapping_huge_finite_radiance_on_the_gpu():
    """The GLSL curves against their twins at and far above TONEMAP_INPUT_MAX, up to float32's limit."""
    big = np.array([[1e6, 1e6, 1e6], [1e7, 0.0, 0.0], [1e30, 1.0, 0.5], [3e38, 3e38, 3e38],
                    [0.0, 2e19, 0.0], [5.0, 1e10, 0.1]], np.float32)
    for term, twin in (("ACES", shading.tonemap_aces_fitted), ("NEUTRAL", shading.tonemap_pbr_neutral)):
        gpu = evaluate(term, big)[:, :3]
        assert np.isfinite(gpu).all(), term
        np.testing.assert_allclose(gpu, twin(big), atol=5e-6)
        assert gpu.min() > 0.9, term     # white, not black


def test_the_limit_changes_no_pixel(monkeypatch):
    """Above TONEMAP_INPUT_MAX each curve is white to within 1/255 of what it would give unlimited
    (float64, where nothing overflows), so limiting its input changes no 8-bit pixel."""
    rng = np.random.default_rng(11)
    c = rng.uniform(0, 1, (2000, 3)) ** 4
    c /= c.max(axis=1, keepdims=True)
    c *= 10.0 ** rng.uniform(6, 30, (2000, 1))          # the brightest channel from 1e6 to 1e30
    limited = {f: f(c) for f in (shading.tonemap_aces_fitted, shading.tonemap_pbr_neutral)}
    monkeypatch.setattr(shading, "TONEMAP_INPUT_MAX", np.inf)
    for f, got in limited.items():
        free = f(c)
        srgb = lambda x: np.round(shading.linear_to_srgb(x) * 255.0)
        assert np.array_equal(srgb(got), srgb(free)), f.__name__


def test_shared_1e30_case_renders_a_png_that_is_not_black(shared_data, tmp_path):
    """cases/exr_texel_1e30_float.exr: 'finite pixels everywhere; the PNG not black'. Before the
    clamp and the tone map's limit, the silver ball in that PNG was black (NaN in the tone map)."""
    case = shared_data / "cases" / "exr_texel_1e30_float.exr"
    outs = {}
    for ext in ("png", "exr"):
        out = tmp_path / f"ball.{ext}"
        proc = subprocess.run([sys.executable, "-m", "alight", "render", "--env", str(case), "--preset", "silver",
                               "--roughness", "0.05", "--size", "64", "--quality", "low", "--out", str(out)],
                              cwd=REPO, capture_output=True, text=True, timeout=300, check=False)
        assert proc.returncode == 0, proc.stderr
        warnings = [line for line in proc.stderr.splitlines() if line.startswith("alight: warning:")]
        assert warnings == [(f"alight: warning: {case}: 1 texel above 1e+10 clamped to 1e+10 "
                             f"(the brightest was 1e+30)")], proc.stderr
        outs[ext] = oiio.ImageBuf(str(out)).get_pixels(oiio.FLOAT)
    linear, png = outs["exr"], outs["png"]
    assert np.isfinite(linear).all()
    ball = linear[..., 3] > 0
    # the ball reflects the sky and the ground as the background shows them: mostly mid-grey,
    # nowhere near black
    assert np.median(png[ball].max(axis=1)) > 0.3
    assert np.mean(png[ball].max(axis=1) < 0.02) < 0.05


def test_textures_cannot_carry_huge_values(tmp_path):
    """Texture maps are decoded to 8 bits: a float image's 1e30, Inf and NaN become 0..255."""
    from alight.exchange.images import load_map_image

    px = np.full((4, 4, 3), 0.5, np.float32)
    px[0, 0] = 1e30
    px[1, 1] = np.inf
    px[2, 2] = np.nan
    path = tmp_path / "hot.exr"
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(4, 4, 3, oiio.FLOAT))
    out.write_image(px)
    out.close()
    image = load_map_image(str(path))
    assert image.dtype == np.uint8
    assert image[0, 0, :3].tolist() == [255, 255, 255] and image[1, 1, :3].tolist() == [255, 255, 255]
