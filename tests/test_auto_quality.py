"""--quality auto (app/accuracy/auto_quality.py): the measured table, the pure choice, max_roughness and
the command line. The error the choices achieve against the converged split sum is measured by
benchmarks/bench_auto_quality.py (figures in the README)."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from alight.accuracy.auto_quality import (
    ARCHETYPES,
    CANDIDATES,
    EXCLUDED,
    ROUGHNESS_POINTS,
    EnvironmentFeatures,
    choose_quality,
    environment_features,
    load_table,
    material_need,
    predicted_error,
    prefilter_work,
    scene_needs,
)
from alight.core.material import Material
from alight.core.scene import Display, Scene
from alight.ibl.bake import FETCH_REACH, QUALITY, SKIPPED_STEP_SAMPLES, grid_roughness
from alight.ibl.environment import constant_environment, load_environment
from tests.gpu import renderer

SUN = EnvironmentFeatures(True, 0.05)
SMOOTH = EnvironmentFeatures(False, 0.01)
DETAILED = EnvironmentFeatures(False, 0.04)


def test_table_covers_every_candidate_and_is_a_measurement():
    """Every candidate has an error for every archetype and roughness point on every measured
    map, and a bake time; the errors are spread (not one typed number) and ordered as their
    settings say: 'high' is never worse than 'rough' at r = 0.25 for gold."""
    t = load_table()
    assert t["roughness"] == list(ROUGHNESS_POINTS)
    assert len(t["environments"]) >= 8
    for name, row in t["environments"].items():
        for cand in CANDIDATES:
            for arch in ARCHETYPES:
                values = row["errors"][cand][arch]
                assert len(values) == len(ROUGHNESS_POINTS)
                assert all(v is None or (math.isfinite(v) and v >= 0) for v in values) or name in EXCLUDED
        if name not in EXCLUDED:
            assert row["errors"]["high"]["metal"][2] <= row["errors"]["rough"]["metal"][2]
    for cand in CANDIDATES:
        for kind in ("sun", "no_sun"):
            assert t["bake_seconds"][cand][kind]["total"] > 0
    assert t["bake_seconds"]["high"]["no_sun"]["total"] > t["bake_seconds"]["rough-sh9"]["no_sun"]["total"]
    all_errors = [v for row in t["environments"].values() for c in row["errors"].values()
                  for a in c.values() for v in a if v is not None]
    assert len(set(all_errors)) > 100


def test_environment_off_bakes_nothing():
    c = choose_quality([material_need(0.0, 0.5)], None, off_reason="--no-ibl")
    assert c.quality is None and c.predicted_seconds == 0 and "--no-ibl" in c.line(0.02)


def test_choice_is_the_cheapest_within_budget():
    """For each scene the choice meets the budget and no candidate with a smaller predicted
    time does (the choice function's contract), and a looser budget never costs more."""
    t = load_table()
    for needs in ([material_need(0, 0.8)], [material_need(1, 0.3)], [material_need(0.5, 0.6)], [material_need(1, 0.0)]):
        for env in (SUN, SMOOTH, DETAILED):
            previous = math.inf
            for budget in (0.01, 0.02, 0.05, 0.2):
                c = choose_quality(needs, env, budget, t)
                if c.meets_budget:
                    assert c.predicted_error <= budget
                    for name in CANDIDATES:
                        err, _ = predicted_error(t, name, needs, env)
                        if err <= budget:
                            from alight.accuracy.auto_quality import predicted_seconds
                            assert predicted_seconds(t, name, c.quality.max_roughness, env.has_compact_source) \
                                >= c.predicted_seconds - 1e-12
                    assert c.predicted_seconds <= previous + 1e-12
                    previous = c.predicted_seconds


def test_rough_materials_get_a_smaller_cube_and_fewer_mips():
    """Every material rough: the chosen prefiltered cube is smaller than the default's and the
    grid is not sampled beyond the roughest material."""
    c = choose_quality([material_need(0.0, 0.6), material_need(1.0, 0.8)], DETAILED)
    assert c.meets_budget
    assert c.quality.prefiltered_size < QUALITY["medium"].prefiltered_size
    assert c.quality.max_roughness == pytest.approx(0.8)


def test_smooth_irradiance_allows_sh9_and_a_sun_does_not():
    """A rough dielectric: under a smooth sky without a compact source, SH9 is within a 5% budget
    and chosen (it is the cheaper method; its worst channel is 1.3-3.7% off on those maps); with
    a compact source (SH9 residual 5%, SH9 up to 24% off on quarry) it is not. A metal never
    reads the irradiance: SH9 is taken whatever the sky."""
    need = [material_need(0.0, 0.8)]
    assert choose_quality(need, SMOOTH, 0.05).quality.irradiance == "sh9"
    assert choose_quality(need, SUN, 0.05).quality.irradiance == "convolution"
    assert choose_quality([material_need(1.0, 0.8)], SUN, 0.05).quality.irradiance == "sh9"


def test_more_budget_is_never_slower_and_a_tiny_budget_says_so():
    c = choose_quality([material_need(1.0, 0.15)], SUN, budget=0.0001)
    assert not c.meets_budget and "OVER" in c.line(0.0001) and "no candidate meets the budget" in c.reason


def test_material_needs():
    assert material_need(0.0, 0.4) .archetypes == ("dielectric",)
    assert material_need(1.0, 0.4).archetypes == ("metal",)
    assert material_need(0.3, 0.4).archetypes == ("dielectric", "metal")
    textured = material_need(1.0, 0.7, metallic_map=True, roughness_map=True)
    assert textured.archetypes == ("dielectric", "metal") and textured.roughness_min == 0.0
    blur = scene_needs(Scene(material=Material(roughness=0.2), view="probe",
                             display=Display(background="blur", blur_roughness=0.6)))
    assert max(n.roughness_max for n in blur) == 0.6      # the background blur reads the grid too


def test_environment_features_of_shared_maps(shared_data):
    """quarry_01 has a compact source and irradiance SH9 cannot follow; venice_sunset has
    neither; a constant map has SH9 residual ~0."""
    q = environment_features(load_environment(str(shared_data / "env" / "quarry_01_1k.hdr")).radiance)
    v = environment_features(load_environment(str(shared_data / "env" / "venice_sunset_1k.hdr")).radiance)
    c = environment_features(constant_environment(1.0, 256).radiance)
    assert q.has_compact_source and not q.smooth
    assert not v.has_compact_source and v.smooth
    assert not c.has_compact_source and c.sh9_residual < 1e-3


def test_max_roughness_skips_steps_beyond_it_only():
    """A quality's max_roughness keeps every grid step up to the first at or above it (times
    FETCH_REACH: the stretched lobe's fetches read a little rougher than the material) and
    samples the rest with SKIPPED_STEP_SAMPLES; the prefilter's work drops accordingly (at
    medium, whose samples grow only 2x per mip, the steps above r = 0.42 hold 22% of it)."""
    q = QUALITY["medium"]
    t = replace(q, max_roughness=0.35)   # x FETCH_REACH: 0.40, so steps up to r = 0.42 stay
    levels = q.prefiltered_levels
    first_above = min(s for s in range(2 * levels - 1) if grid_roughness(s, levels) >= 0.35 * FETCH_REACH)
    for step in range(2 * levels - 1):
        if step <= first_above:
            assert t.prefilter_samples_at(step) == q.prefilter_samples_at(step)
        else:
            assert t.prefilter_samples_at(step) == SKIPPED_STEP_SAMPLES
    assert prefilter_work(t) < 0.8 * prefilter_work(q)


def test_max_roughness_changes_nothing_the_material_reads(shared_data):
    """Rendering a material with roughness <= max_roughness gives the same probe with and
    without the trimmed grid (bit for bit: the steps it reads are baked identically), and the
    trimmed steps are finite."""
    env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
    r = renderer()
    full = r.bake(env, QUALITY["low"])
    trimmed = r.bake(env, replace(QUALITY["low"], max_roughness=0.5))
    for rough in (0.0, 0.3, 0.45, 0.5):
        m = Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=rough)
        a = r.render(Scene(material=m, view="probe"), full, 32, 32).linear
        b = r.render(Scene(material=m, view="probe"), trimmed, 32, 32).linear
        np.testing.assert_array_equal(a, b)
    rough = r.render(Scene(material=Material(roughness=1.0), view="probe"), trimmed, 32, 32).linear
    assert np.isfinite(rough).all()


REPO = Path(__file__).resolve().parents[1]


def test_cli_prints_the_choice(tmp_path):
    from alight.frontends.cli import main

    out = tmp_path / "a.png"
    code = subprocess.run([sys.executable, "-m", "alight", "render", "--quality", "auto", "--preset", "copper",
                           "--roughness", "0.8", "--size", "32", "--out", str(out)],
                          capture_output=True, text=True, timeout=120, cwd=REPO)
    assert code.returncode == 0, code.stderr
    lines = [line for line in code.stderr.splitlines() if "quality auto" in line]
    assert len(lines) == 1 and "predicted error" in lines[0] and "within the 2% budget" in lines[0]
    assert out.stat().st_size > 0
    off = subprocess.run([sys.executable, "-m", "alight", "render", "--quality", "auto", "--no-ibl", "--size", "32",
                          "--out", str(tmp_path / "b.png")], capture_output=True, text=True, timeout=120, cwd=REPO)
    assert off.returncode == 0 and "no bake" in off.stderr
    assert main(["render", "--error-budget", "3", "--out", str(tmp_path / "c.png")]) == 2
    assert main(["render", "--quality", "auto", "--irradiance", "sh9", "--out", str(tmp_path / "c.png")]) == 2
    assert not (tmp_path / "c.png").exists()


def test_python_api_auto():
    """Renderer(quality="auto") chooses per render and keeps the choice; a rough material
    gets a cheaper bake than a mirror, and no environment bakes nothing."""
    from alight import Renderer

    with Renderer(32, quality="auto") as r:
        r.set_material("copper", roughness=0.8)
        assert np.isfinite(r.render(linear=True)).all()
        rough = r.last_auto_choice
        r.set_material("silver", roughness=0.0)
        r.render()
        mirror = r.last_auto_choice
        assert rough.meets_budget and rough.quality.max_roughness == pytest.approx(0.8)
        assert mirror.quality.max_roughness == 0.0 and mirror.name != rough.name
        r.set_environment(None)
        r.render()
        assert r.last_auto_choice.quality is None


def test_installed_package_carries_the_table(tmp_path):
    """The measured table loads from the installed package, from any folder (that the wheel holds
    it is tests/test_packaging.py's check)."""
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    code = "import alight.accuracy.auto_quality as a; print(a.TABLE_PATH); print(len(a.load_table()['environments']))"
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    path, count = out.stdout.split()
    assert Path(path).is_file() and Path(path).parent.name == "accuracy" and int(count) >= 8
