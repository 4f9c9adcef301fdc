"""The bake in steps (app/ibl/bake.py bake_steps), which the editor spreads over frames: the same
maps as bake_environment, progress after every pass, nothing left behind when stopped early."""

from __future__ import annotations

import re

import numpy as np
import pytest

from alight.ibl.bake import QUALITY, bake_environment, bake_steps, read_cube
from alight.ibl.environment import load_environment
from tests.gpu import renderer


def test_bake_in_steps_equals_the_bake_in_one_go(shared_data):
    """The editor's stepwise bake (several frames) gives the very maps bake_environment gives,
    and reports a rising fraction below 1 after every pass."""
    r = renderer()
    env = load_environment(str(shared_data / "env" / "quarry_01_1k.hdr"))   # has a sun: two source cubes
    q = QUALITY["low"]
    whole = bake_environment(r.ctx, r.shaders, env, q, r.luts)
    steps = bake_steps(r.ctx, r.shaders, env, q, r.luts)
    fractions = []
    while True:
        try:
            fraction, label = next(steps)
        except StopIteration as done:
            stepped = done.value
            break
        fractions.append(fraction)
        assert isinstance(label, str) and label
    assert len(fractions) >= 2 * q.prefiltered_levels + 3
    assert all(0.0 < a < b < 1.0 for a, b in zip(fractions, fractions[1:]))
    try:
        for name, levels in (("environment", (0, 3)), ("irradiance", (0,)), ("prefiltered_radiance", (0, 1, 3)),
                             ("prefiltered_radiance_mid", (0, 2))):
            a, b = getattr(whole, name), getattr(stepped, name)
            for level in levels:
                assert np.array_equal(read_cube(r.shaders, a, level), read_cube(r.shaders, b, level)), (name, level)
        # The first bake in a process computes the BRDF LUT, later ones find it cached: the same
        # passes either way, whichever of the two ran first.
        def passes(bake):
            return {re.sub(r"^brdf_lut \((baked|cached)\)$", "brdf_lut", name) for name in bake.pass_seconds}
        assert passes(whole) == passes(stepped)
    finally:
        whole.release()
        stepped.release()


def test_a_bake_stopped_early_releases_its_maps():
    r = renderer()
    env = load_environment("studio")
    steps = bake_steps(r.ctx, r.shaders, env, QUALITY["low"], r.luts)
    next(steps)
    next(steps)
    steps.close()    # the editor drops a superseded bake this way; nothing raises, nothing leaks
    with pytest.raises(StopIteration):
        next(steps)
