"""The pytest plugin (app/frontends/pytest_plugin.py), used by inner test files run through pytester."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import OpenImageIO as oiio  # imported here: pytester restores sys.modules after each test, and a
import pytest  # nanobind module imported twice in one process aborts it
import tomllib

from alight.frontends.pytest_plugin import _assert_image_matches

REPO = Path(__file__).resolve().parents[1]

INNER = '''
import os

def test_render(alight_renderer, assert_image_matches):
    r = alight_renderer
    r.set_mesh("sphere").set_environment("studio").set_material(os.environ.get("PRESET", "gold"))
    metric = os.environ.get("METRIC", "rel")
    if os.environ.get("HDR"):
        assert_image_matches(r.render(48, 48, linear=True), "goldens/ball.exr", metric=metric)
    else:
        assert_image_matches(r.render(48, 48), "goldens/ball.png", metric=metric)
'''


@pytest.fixture
def run_inner(pytester, monkeypatch):
    """Run INNER in a fresh pytest process (its own GL context) with the installed alight."""
    pytester.makepyfile(test_inner=INNER)
    # The installed package registers the plugin through its pytest11 entry point.
    plugin: list[str] = []

    def run(*args, **env):
        for k in ("PRESET", "METRIC", "HDR"):
            monkeypatch.delenv(k, raising=False)
        for k, v in env.items():
            monkeypatch.setenv(k, v)
        return pytester.runpytest_subprocess(*plugin, "-p", "no:cacheprovider", *args)

    return run


@pytest.mark.parametrize("hdr", [False, True], ids=["srgb-png", "linear-exr"])
def test_goldens_written_matched_and_a_wrong_render_fails(run_inner, pytester, hdr):
    env = {"HDR": "1"} if hdr else {}
    suffix = ".exr" if hdr else ".png"
    golden = pytester.path / "goldens" / f"ball{suffix}"

    missing = run_inner(**env)
    missing.assert_outcomes(failed=1)
    missing.stdout.fnmatch_lines(["*no golden image*--alight-update-goldens*"])

    run_inner("--alight-update-goldens", **env).assert_outcomes(passed=1)
    assert golden.is_file()
    run_inner(**env).assert_outcomes(passed=1)

    wrong = run_inner(PRESET="silver", **env)  # a deliberately wrong render
    wrong.assert_outcomes(failed=1)
    wrong.stdout.fnmatch_lines(["*rel error * > tolerance*"])
    for kind in ("actual", "expected", "diff"):
        path = pytester.path / "goldens" / f"ball.{kind}.png"
        assert path.is_file(), kind
    diff = oiio.ImageInput.open(str(pytester.path / "goldens" / "ball.diff.png")).read_image()
    assert diff.max() > 0.5  # the difference image shows the difference
    # The golden itself is untouched by a failure, and updating accepts the new look; a pass
    # and an update each remove the failure images an earlier run left.
    run_inner(**env).assert_outcomes(passed=1)
    assert not list((pytester.path / "goldens").glob("ball.*.png"))
    run_inner(PRESET="silver", **env).assert_outcomes(failed=1)
    assert len(list((pytester.path / "goldens").glob("ball.*.png"))) == 3
    run_inner("--alight-update-goldens", PRESET="silver", **env).assert_outcomes(passed=1)
    assert not list((pytester.path / "goldens").glob("ball.*.png"))
    run_inner(PRESET="silver", **env).assert_outcomes(passed=1)


def test_flip_metric_passes_same_and_fails_wrong(run_inner):
    pytest.importorskip("flip_evaluator")
    run_inner("--alight-update-goldens", METRIC="flip").assert_outcomes(passed=1)
    run_inner(METRIC="flip").assert_outcomes(passed=1)
    wrong = run_inner(METRIC="flip", PRESET="copper")
    wrong.assert_outcomes(failed=1)
    wrong.stdout.fnmatch_lines(["*flip error * > tolerance*"])


def test_session_renderer_fixture_renders(alight_renderer, assert_image_matches, tmp_path):
    """The plugin used directly by this suite: the same render twice matches itself."""
    alight_renderer.set_mesh("sphere").set_environment("studio").set_material("copper")
    image = alight_renderer.render(32, 32)
    assert image.shape == (32, 32, 4)
    _assert_image_matches(image, tmp_path / "g.png", "rel", None, update=True)
    assert assert_image_matches(alight_renderer.render(32, 32), tmp_path / "g.png") == 0.0


def test_relative_error_is_what_it_says(tmp_path):
    expected = np.full((8, 8, 3), 0.5, np.float32)
    _assert_image_matches(expected, tmp_path / "g.exr", "rel", None, update=True)
    assert _assert_image_matches(expected * 1.01, tmp_path / "g.exr", "rel", 0.02, False) == pytest.approx(0.01, rel=1e-4)
    with pytest.raises(AssertionError, match="rel error 0.03"):
        _assert_image_matches(expected * 1.03, tmp_path / "g.exr", "rel", 0.02, False)
    with pytest.raises(AssertionError, match=r"size 4x8 differs from the golden's 8x8; "
                                             r"wrote g.actual.png, g.expected.png in "):
        _assert_image_matches(expected[:, :4], tmp_path / "g.exr", "rel", 0.02, False)
    assert not (tmp_path / "g.diff.png").exists()
    with pytest.raises(ValueError):
        _assert_image_matches(expected, tmp_path / "g.exr", "mse", None, False)


DUCK_INNER = '''
import os

def test_duck(alight_renderer, assert_image_matches):
    r = alight_renderer
    r.aa = os.environ.get("AA", "msaa")
    r.set_mesh(os.environ["DUCK"]).set_environment("studio")
    r.set_camera(orbit_deg=float(os.environ.get("ORBIT", "0")), distance=12)  # small in the frame
    if os.environ.get("RED"):
        r.set_material(base_color=(1, 0, 0), use_file_materials=False)
    assert_image_matches(r.render(256, 256), "goldens/duck.png")
'''


def test_a_small_object_changed_fails_and_legit_noise_passes(pytester, monkeypatch, shared_data):
    """Duck.glb small in the frame turned red moves the frame's rel error only 0.017 (< 0.02):
    the local (per-block) criterion catches it; an unchanged render, a camera moved 1e-4 and
    another anti-aliasing (as another GPU rasterises edges) still pass."""
    pytester.makepyfile(test_duck=DUCK_INNER)
    monkeypatch.setenv("DUCK", str(shared_data / "models" / "Duck.glb"))

    def run(*args, **env):
        for k in ("AA", "ORBIT", "RED"):
            monkeypatch.delenv(k, raising=False)
        for k, v in env.items():
            monkeypatch.setenv(k, v)
        return pytester.runpytest_subprocess("-p", "no:cacheprovider", *args)

    run("--alight-update-goldens").assert_outcomes(passed=1)
    run().assert_outcomes(passed=1)
    run(ORBIT="1e-4").assert_outcomes(passed=1)
    run(AA="none").assert_outcomes(passed=1)
    red = run(RED="1")
    red.assert_outcomes(failed=1)
    red.stdout.fnmatch_lines(["*duck.png: local error * (rel error of the 16x16 block at *) > local tolerance 0.25*"])
    # Loosened: per call, and for the project through the ini option.
    pytester.makeini("[pytest]\nalight_local_tolerance = inf\n")
    run(RED="1").assert_outcomes(passed=1)


def test_local_error_is_the_worst_blocks_rel_error(tmp_path):
    expected = np.full((40, 40, 3), 0.5, np.float32)
    _assert_image_matches(expected, tmp_path / "g.exr", "rel", None, update=True)
    spot = expected.copy()
    spot[30:38, 30:38] = 1.0  # 64 pixels off by 0.5: rel 0.02, a block's rel 0.25..1
    assert _assert_image_matches(spot, tmp_path / "g.exr", "rel", 0.05, False, local_tolerance=math.inf) \
        == pytest.approx(64 * 0.5 / 1600 / 0.5)
    # The last column and row of blocks end at the image's edge: the spot lies in the block at 24.
    with pytest.raises(AssertionError, match=r"local error 0.25 \(rel error of the 16x16 block at x=24, y=24\)"):
        _assert_image_matches(spot, tmp_path / "g.exr", "rel", 0.05, False, local_tolerance=0.2)


FORMAT_INNER = '''
import os

def test_format(alight_renderer, assert_image_matches):
    r = alight_renderer
    r.set_mesh("sphere").set_environment("studio").set_material("gold")
    assert_image_matches(r.render(16, 16, linear=bool(os.environ.get("HDR"))), os.environ["GOLDEN"])
'''


@pytest.mark.parametrize("hdr, golden, words", [
    ("1", "g.png", "a float (linear) image needs a .exr golden, not .png"),
    ("", "g.exr", "a uint8 (sRGB) image needs a .png golden, not .exr"),
    ("", "g.jpg", "a uint8 (sRGB) image needs a .png golden, not .jpg (lossy formats*"),
], ids=["float-png", "uint8-exr", "jpg"])
def test_a_golden_format_that_cannot_hold_the_image_is_refused(pytester, monkeypatch, hdr, golden, words):
    """At update time (nothing written) and at compare time, in one line."""
    pytester.makepyfile(test_format=FORMAT_INNER)
    monkeypatch.setenv("HDR", hdr)
    monkeypatch.setenv("GOLDEN", golden)
    for args in (("--alight-update-goldens",), ()):
        result = pytester.runpytest_subprocess("-p", "no:cacheprovider", *args)
        result.assert_outcomes(failed=1)
        result.stdout.fnmatch_lines([f"*{golden}: {words}"])
        assert not (pytester.path / golden).exists()
    with pytest.raises(pytest.fail.Exception, match="actual is uint16"):
        _assert_image_matches(np.zeros((4, 4, 3), np.uint16), pytester.path / "g.png", "rel", None, True)


def test_diff_image_has_a_fixed_scale(tmp_path):
    """A 1-level difference looks faint, 50 levels white, whatever the largest difference."""
    expected = np.full((8, 8, 3), 100, np.uint8)
    _assert_image_matches(expected, tmp_path / "g.png", "rel", None, update=True)
    actual = expected.copy()
    actual[:, :4] += 1
    with pytest.raises(AssertionError, match=r"white 0.25 x the golden's mean"):
        _assert_image_matches(actual, tmp_path / "g.png", "rel", 0.0, False, local_tolerance=math.inf)
    faint = oiio.ImageInput.open(str(tmp_path / "g.diff.png")).read_image(format=oiio.UINT8)
    assert faint[0, 0, 0] == round(1 / (0.25 * 100) * 255) and faint[0, 7, 0] == 0
    actual[:, 4:] += 50
    with pytest.raises(AssertionError):
        _assert_image_matches(actual, tmp_path / "g.png", "rel", 0.0, False, local_tolerance=math.inf)
    both = oiio.ImageInput.open(str(tmp_path / "g.diff.png")).read_image(format=oiio.UINT8)
    assert both[0, 0, 0] == faint[0, 0, 0] and both[0, 7, 0] == 255


def test_a_failure_shows_the_test_not_the_plugin_and_an_update_says_how_many(run_inner, pytester):
    written = run_inner("--alight-update-goldens")
    written.assert_outcomes(passed=1)
    written.stdout.fnmatch_lines(["alight: wrote 1 golden"])
    wrong = run_inner(PRESET="silver")
    wrong.assert_outcomes(failed=1)
    text = wrong.stdout.str()
    # The test's own line, then the message: none of the plugin's source.
    assert "assert_image_matches(r.render(48, 48)" in text and "def _assert_image_matches" not in text, text
    assert "pytest_plugin.py" not in text, text
    run_inner().assert_outcomes(passed=1)
    assert "alight: wrote" not in run_inner().stdout.str()


SETTINGS_INNER = '''
import os

def test_settings(alight_renderer):
    w, h, quality = os.environ["WANT"].split(",")
    assert (alight_renderer.width, alight_renderer.height, alight_renderer.quality) == (int(w), int(h), quality)
'''


def test_renderer_size_and_quality_from_ini_and_command_line(pytester, monkeypatch):
    pytester.makepyfile(test_settings=SETTINGS_INNER)

    def run(want, *args):
        monkeypatch.setenv("WANT", want)
        return pytester.runpytest_subprocess("-p", "no:cacheprovider", *args)

    run("256,256,low").assert_outcomes(passed=1)
    pytester.makeini("[pytest]\nalight_size = 64x32\nalight_quality = medium\n")
    run("64,32,medium").assert_outcomes(passed=1)
    run("40,40,high", "--alight-size=40", "--alight-quality=high").assert_outcomes(passed=1)
    bad = run("0,0,low", "--alight-size=big")
    assert bad.ret == pytest.ExitCode.USAGE_ERROR
    bad.stderr.fnmatch_lines(["*--alight-size: 'big' is not a size (W or WxH, in pixels)"])
    pytester.makeini("[pytest]\nalight_quality = best\n")
    bad = run("0,0,low")
    assert bad.ret == pytest.ExitCode.USAGE_ERROR
    bad.stderr.fnmatch_lines(["*ini option alight_quality: 'best' is not one of low, medium, high, auto"])


def test_quality_choices_are_the_renderers():
    from typing import get_args

    from alight.frontends.api import Quality
    from alight.frontends.pytest_plugin import QUALITIES

    assert QUALITIES == get_args(Quality)


def test_flip_evaluator_is_a_dependency_and_its_absence_says_so(run_inner, pytester):
    """pyproject, the plugin's docstring and the guide agree: a dependency, not optional."""
    import alight.frontends.pytest_plugin as plugin

    project = tomllib.loads((REPO / "pyproject.toml").read_text())
    assert any(d.startswith("flip-evaluator") for d in project["project"]["dependencies"])
    guide = (REPO / "docs" / "guides" / "pytest-plugin.md").read_text()
    for text in (plugin.__doc__, guide):
        assert "a dependency of alight" in text and "optional" not in text
    # An environment without it (an install with --no-deps): one line naming the golden.
    pytester.makeconftest("import sys\nsys.modules['flip_evaluator'] = None  # import fails\n")
    run_inner("--alight-update-goldens").assert_outcomes(passed=1)
    missing = run_inner(METRIC="flip")
    missing.assert_outcomes(failed=1)
    missing.stdout.fnmatch_lines(["*ball.png: metric 'flip' needs the flip-evaluator package, a dependency of "
                                  "alight missing from this environment (pip install flip-evaluator)"])


def test_entry_point_is_declared():
    project = tomllib.loads((REPO / "pyproject.toml").read_text())
    assert project["project"]["entry-points"]["pytest11"]["alight"] == "alight.frontends.pytest_plugin"
    import alight.frontends.pytest_plugin as plugin

    assert callable(plugin.pytest_addoption) and callable(plugin.assert_image_matches)
