"""The display curves by the names peers use: each GLSL curve against its numpy twin, the
relations between them, and the command picking them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from alight.core import shading
from alight.core.scene import TONEMAPS
from tests.files_cases import run
from tests.gpu import evaluate

rng = np.random.default_rng(11)
TWINS = {
    "aces": shading.tonemap_aces_fitted, "aces-hill": shading.tonemap_aces_fitted,
    "neutral": shading.tonemap_pbr_neutral, "aces-narkowicz": shading.tonemap_aces_narkowicz,
    "aces-hill-exposure-boost": shading.tonemap_aces_hill_exposure_boost, "agx": shading.tonemap_agx,
    "none": lambda c: np.clip(c, 0.0, 1.0),
}


def _inputs():
    return np.concatenate([rng.uniform(0, 1, (300, 3)), rng.uniform(0, 50, (300, 3)), np.zeros((1, 3)),
                           np.full((1, 3), 0.18), np.full((1, 3), 1e30), 10.0 ** rng.uniform(-6, 4, (200, 3))])


@pytest.mark.parametrize("name", TONEMAPS)
def test_glsl_curve_matches_its_twin(name):
    c = _inputs()
    gpu = evaluate(TONEMAPS.index(name), c, shader="accuracy/evaluate_tonemaps.comp")[:, :3]
    # AgX's 6th-order polynomial of a log, in float32: a little more rounding than the others
    np.testing.assert_allclose(gpu, TWINS[name](c), rtol=2e-5, atol=3e-5 if name == "agx" else 5e-6)
    assert np.isfinite(gpu).all() and gpu.min() >= 0.0 and gpu.max() <= 1.0


def test_every_curve_has_a_twin_and_the_command_offers_it():
    from alight.frontends.cli import TONEMAP_CHOICES

    assert set(TWINS) == set(TONEMAPS) and TONEMAP_CHOICES == TONEMAPS


def test_known_values():
    # Narkowicz at 1: (2.51 + 0.03) / (2.43 + 0.59 + 0.14)
    assert shading.tonemap_aces_narkowicz(np.ones(3))[0] == pytest.approx(2.54 / 3.16)
    c = rng.uniform(0, 4, (100, 3))
    np.testing.assert_allclose(shading.tonemap_aces_hill_exposure_boost(c), shading.tonemap_aces_fitted(c / 0.6))
    # the boost is log2(1 / 0.6) = 0.737 EV: the 0.74 EV by which 'aces' was darker than the peers
    assert math.log2(1 / 0.6) == pytest.approx(0.737, abs=5e-4)


def test_curves_are_monotonic_and_agx_keeps_grey_grey():
    x = np.geomspace(1e-4, 1e3, 400)
    grey = np.repeat(x[:, None], 3, axis=1)
    for name, f in TWINS.items():
        y = f(grey)[:, 0]
        assert (np.diff(y) >= -1e-9).all(), name
    agx = shading.tonemap_agx(grey)
    assert np.abs(agx - agx.mean(axis=1, keepdims=True)).max() < 2e-3   # neutral axis kept
    assert 0.1 < shading.tonemap_agx(np.full(3, 0.18))[0] < 0.3          # mid grey near the middle


def _png(path):
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"), np.float64)


def test_exposure_boost_equals_aces_at_plus_0737_ev(tmp_path):
    """Through the command: the boosted curve is 'aces' with --exposure log2(1/0.6)."""
    common = ("render", "--size", "48", "--quality", "low", "--aa", "none")
    a, b, c = (tmp_path / n for n in ("a.png", "b.png", "c.png"))
    assert run(*common, "--tonemap", "aces-hill-exposure-boost", "--out", a).returncode == 0
    assert run(*common, "--tonemap", "aces", "--exposure", repr(math.log2(1 / 0.6)), "--out", b).returncode == 0
    assert run(*common, "--tonemap", "aces-hill", "--out", c).returncode == 0
    assert np.abs(_png(a) - _png(b)).max() <= 1.0
    assert _png(a).mean() > _png(c).mean() + 5


@pytest.mark.parametrize("name", ["aces-narkowicz", "agx"])
def test_the_command_renders_each_curve(tmp_path, name):
    out = tmp_path / "t.png"
    proc = run("render", "--size", "32", "--quality", "low", "--aa", "none", "--tonemap", name, "--out", out)
    assert proc.returncode == 0 and out.is_file(), proc.stderr
