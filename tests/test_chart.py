"""app/accuracy/chart.py: the sweep's design, the reference's basis-material decomposition, the Pareto
frontier, the error map, and ``alight chart --quick`` end to end. No timing is asserted."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import re
import subprocess
import sys
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import pytest

from alight.accuracy.chart import (
    LAYER_ROWS,
    NV_BINS,
    ErrorMap,
    Setting,
    pareto,
    read_summary,
    reference_terms,
    sweep,
)
from alight.core.ibl_models import IBL_MODELS
from alight.ibl.bake import QUALITY

REPO = Path(__file__).resolve().parents[1]


# Fields that are one knob together: the convolution's step counts; the prefilter's sample count
# and its per-mip cap (raised with it so the first mip gets the count asked for).
KNOBS = {"irradiance_theta_steps": "irradiance_phi_steps", "prefilter_max_samples": "prefilter_samples"}


def _changed_fields(setting: Setting) -> set[str]:
    base = QUALITY["medium"]
    return {KNOBS.get(f.name, f.name) for f in fields(base)
            if f.name != "name" and getattr(setting.quality, f.name) != getattr(base, f.name)}


def test_the_sweep_is_one_factor_at_a_time_and_covers_the_method_space():
    settings = sweep()
    names = [s.name for s in settings]
    assert len(names) == len(set(names))
    assert settings[0].factor == "baseline" and not _changed_fields(settings[0])
    for s in settings[1:]:
        changed = _changed_fields(s)
        if s.factor in ("IBL model", "multiple scattering", "layer"):
            assert not changed, (s.name, changed)
            assert (s.factor == "layer") == bool(s.layer), s.name
        else:
            assert len(changed) == 1 and s.ibl_model == settings[0].ibl_model, (s.name, changed)
    qs = [s.quality for s in settings]
    assert {q.irradiance for q in qs} == {"convolution", "sh9"}
    assert len({(q.irradiance_phi_steps, q.irradiance_theta_steps) for q in qs}) >= 3
    assert len({q.irradiance_size for q in qs}) >= 3
    assert len({q.prefiltered_size for q in qs}) >= 3
    samples = {q.prefilter_samples for q in qs}
    assert min(samples) == 4 and max(samples) == 1024
    assert {q.filtered_importance_sampling for q in qs} == {True, False}
    assert len({q.lut_size for q in qs}) >= 3 and len({q.lut_samples for q in qs}) >= 3
    # every IBL model, each judged against the truth with MS off and by the furnace with MS on
    judged = {s.ibl_model for s in settings if s.judged_by_truth}
    furnace_only = {s.ibl_model for s in settings if s.multiple_scattering}
    assert judged == set(IBL_MODELS) == furnace_only
    quick = sweep(quick=True)
    assert len(quick) < len(settings) and {s.ibl_model for s in quick} == set(IBL_MODELS)
    # a row per material layer, at medium with the default model, in both sweeps
    from alight.accuracy.chart import LAYER_ROWS

    for sw in (settings, quick):
        assert [s.layer for s in sw if s.factor == "layer"] == list(LAYER_ROWS)
        assert all(s.ibl_model == settings[0].ibl_model for s in sw if s.layer)


def test_each_layered_preset_counts_in_one_layer_row():
    """A preset with layers is judged in exactly one layer row, the last of LAYER_ROWS it uses (a
    dispersive glass in the dispersion row, not also in the transmission row), and every layer
    row has a preset, a furnace material that uses the layer and a frame preset."""
    from alight.accuracy.chart import LAYER_FRAME_PRESET, LAYER_FURNACE, QUICK_PRESETS, layer_row
    from alight.core.material import Material
    from alight.exchange.presets import list_presets, load_preset

    rows = {name: layer_row(load_preset(name)) for name in list_presets()}
    assert rows["flint_glass"] == "dispersion" and rows["water"] == "transmission" and rows["leaf"] == \
        "diffuse_transmission" and rows["gold"] == ""
    for layer in LAYER_ROWS:
        assert layer in Material(**LAYER_FURNACE[layer]).layers(), layer
        assert layer_row(load_preset(LAYER_FRAME_PRESET[layer])) == layer
        assert any(rows[p] == layer for p in QUICK_PRESETS), layer


def test_pareto_frontier():
    pts = [(1.0, 10.0), (2.0, 5.0), (3.0, 6.0), (4.0, 1.0), (2.0, 5.0), (math.nan, 0.1), (5.0, 1.0)]
    assert pareto(pts) == [True, True, False, True, True, False, False]


def test_reference_terms_combine_to_the_direct_reference():
    """The three basis materials give any material's ground truth (the BRDF is linear in F0 and
    the base colour): checked against a direct GPU reference of each material."""
    from alight.accuracy.reference import ReferenceRenderer, probe_gbuffer
    from alight.core.material import Material
    from alight.core.scene import Scene
    from alight.exchange.presets import load_preset
    from tests.gpu import renderer

    rng = np.random.default_rng(3)
    radiance = (rng.uniform(0.0, 1.0, (16, 32, 3)) * np.linspace(0.2, 3.0, 32)[None, :, None]).astype(np.float32)
    # The tests' one shared GL context: a second context would leave the others' not current.
    ref = ReferenceRenderer(renderer())
    size, rs = 12, (0.3, 0.8)
    terms = reference_terms(ref, radiance, size, rs)
    for mat in (load_preset("gold"), load_preset("water"), Material(base_color=(0.2, 0.5, 0.9), metallic=0.4,
                                                                    specular_f0=(0.1, 0.05, 0.02),
                                                                    emissive=(0.1, 0.0, 0.0))):
        for r in rs:
            m = replace(mat, roughness=r)
            direct = ref.render_gbuffer(probe_gbuffer(size, m), Scene(view="probe"), radiance, env_level=1).linear
            combined = terms.combine(m, r)
            inside = terms.inside
            assert np.array_equal(combined[..., 3] > 0, inside)
            err = np.abs(combined[..., :3] - direct[..., :3])[inside].sum() / np.abs(direct[..., :3])[inside].sum()
            assert err < 1e-4, (mat.name, r, err)
    with pytest.raises(ValueError):
        terms.combine(load_preset("gold"), 0.5)
    # A layer row's reference (layer_reference): each roughness's tile of the one G-buffer equals
    # a direct reference of the layered material alone (here brushed_aluminium's anisotropy).
    from alight.accuracy.chart import layer_reference

    aniso = load_preset("brushed_aluminium")
    tiles = layer_reference(ref, radiance, size, aniso, rs)
    assert sorted(tiles) == list(rs)
    for r in rs:
        m = replace(aniso, roughness=r)
        direct = ref.render_gbuffer(probe_gbuffer(size, m), Scene(view="probe", material=m), radiance, env_level=1).linear
        err = np.abs(tiles[r][..., :3] - direct[..., :3])[inside].sum() / np.abs(direct[..., :3])[inside].sum()
        assert err < 1e-5, (r, err)


def test_error_map_bins_by_nv_and_roughness():
    size = 32
    em = ErrorMap((0.25, 0.5), size)
    ref = np.ones((size, size, 4), np.float32)
    test = ref.copy()
    from alight.core.shading import probe_normals

    n, inside = probe_normals(size)
    test[..., :3] += np.where(n[..., 2:3] < 0.3, 0.5, 0.0)     # wrong only near grazing
    em.add("m", 0.5, test, ref)
    em.add("m", 0.25, ref, ref)
    rel = em.relative("m")
    assert rel.shape == (2, NV_BINS)
    assert np.all(rel[0] == 0.0)                                  # r = 0.25: exact
    assert np.allclose(rel[1, :3], 0.5) and np.all(rel[1, 3:] == 0.0)


@pytest.fixture(scope="module")
def quick_chart(tmp_path_factory):
    """``alight chart --quick`` run once for the tests below: (its output folder, the process)."""
    out = tmp_path_factory.mktemp("chart") / "chart"
    proc = subprocess.run([sys.executable, "-m", "alight", "chart", "--quick", "--size", "16", "--out", str(out)],
                          cwd=REPO, env=dict(os.environ), capture_output=True, text=True, timeout=600)
    return out, proc


def test_chart_quick_end_to_end(quick_chart):
    out, proc = quick_chart
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "Traceback" not in proc.stderr
    steps = [l for l in proc.stderr.splitlines() if "step " in l]
    assert steps and "ETA" in steps[-1] and steps[-1].split("step ")[1].split()[0].split("/")[0] == \
        steps[-1].split("step ")[1].split()[0].split("/")[1]
    for name in ("chart.csv", "chart_cases.csv", "furnace.csv", "error_map.csv", "chart.png", "error_map.png"):
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name
    rows = read_summary(out / "chart.csv")
    vis_rows = [r for r in rows if r["factor"] == "visibility"]
    rows = [r for r in rows if r["factor"] != "visibility"]
    assert [r["setting"] for r in rows] == [s.name for s in sweep(quick=True)]
    for r in rows:
        assert r["bake_ms"] > 0 and r["frame_ms"] > 0 and r["lut_cold_ms"] > 0
        # (The diffuse transmission's furnace is a white dielectric, whose BRDF exceeds 1 toward
        # grazing view at low roughness with or without the layer: docs/conventions.md. That the
        # layer adds nothing there is tests/test_diffuse_transmission.py's furnace test.)
        bound = 1.5 if r["setting"] == "layer diffuse_transmission" else 1.05
        assert 0.0 < r["furnace_min"] <= r["furnace_mean"] <= r["furnace_max"] <= bound, r["setting"]
        if r["multiple_scattering"]:
            assert math.isnan(r["rel_mae_mean"]) and math.isnan(r["flip_mean"])   # kept out of the truth
        else:
            assert 0.0 < r["rel_mae_mean"] <= r["rel_mae_max"] < 2.0
            assert 0.0 < r["flip_mean"] < 1.0
    assert any(r["pareto_bake"] for r in rows) and any(r["pareto_frame"] for r in rows)
    with open(out / "chart_cases.csv", newline="") as f:
        cases = list(csv.DictReader(f))
    judged = [r for r in rows if not r["multiple_scattering"]]
    # The base rows: the 2 presets without layers x 3 roughness values, one environment; each
    # layer's row: its preset at the roughness values whose lobes the texel sum can integrate
    # (alight.accuracy.reference's checks: a narrow anisotropic lobe has no case; water at
    # r = 0.25: its refracted lobe is too narrow, alight.accuracy.ground_truth.check_transmission_lobe).
    layer_rows = [r for r in judged if r["factor"] == "layer"]
    layer_preset = {"layer clearcoat": "car_paint", "layer sheen": "velvet", "layer anisotropy": "brushed_aluminium",
                    "layer transmission": "water", "layer iridescence": "oil_film", "layer dispersion": "flint_glass",
                    "layer diffuse_transmission": "leaf"}
    assert [r["setting"] for r in layer_rows] == list(layer_preset)
    per_layer = {name: [c for c in cases if c["setting"] == name] for name in layer_preset}
    for name, preset in layer_preset.items():
        assert {c["preset"] for c in per_layer[name]} == {preset}
        assert 1 <= len(per_layer[name]) <= 3
    assert {float(c["roughness"]) for c in per_layer["layer transmission"]} == {0.5, 1.0}
    # flint_glass's ior 1.7 bends more than water's 1.33: its refracted lobe at r = 0.25 is wide enough.
    assert {float(c["roughness"]) for c in per_layer["layer dispersion"]} == {0.25, 0.5, 1.0}
    assert {float(c["roughness"]) for c in per_layer["layer diffuse_transmission"]} == {0.25, 0.5, 1.0}
    assert len(cases) == ((len(judged) - len(layer_preset)) * 2 * 3 + sum(len(v) for v in per_layer.values())
                          + len(vis_rows))   # one environment: one case per visibility row
    # The baseline's summary is the mean of its cases.
    base = [float(c["rel_mae"]) for c in cases if c["setting"] == rows[0]["setting"]]
    assert rows[0]["rel_mae_mean"] == pytest.approx(np.mean(base), rel=1e-4)
    # The furnace: a constant environment of 1, a metal with F0 = 1: at r = 0 the mirror gives 1.
    with open(out / "furnace.csv", newline="") as f:
        furnace = list(csv.DictReader(f))
    # (A layer's row is not a mirror at r = 0: anisotropy stretches it.)
    mirror = [float(r["mean"]) for r in furnace if float(r["roughness"]) == 0.0 and not r["setting"].startswith("layer ")]
    assert mirror and all(abs(v - 1.0) < 0.01 for v in mirror)
    # The layers at r = 1 (every lobe wide): at most 1, the diffuse transmission's sheet too.
    rough = {r["setting"]: float(r["max"]) for r in furnace if float(r["roughness"]) == 1.0 and r["setting"].startswith("layer ")}
    assert len(rough) == len(LAYER_ROWS) and all(v <= 1.0 + 1e-3 for v in rough.values()), rough
    truth = [r for r in furnace if r["setting"] == "ground truth"]
    assert truth and all(0.0 < float(r["mean"]) <= 1.0 for r in truth)
    import OpenImageIO as oiio

    for png in ("chart.png", "error_map.png"):
        spec = oiio.ImageInput.open(str(out / png)).spec()
        assert spec.width > 500 and spec.height > 300


def test_chart_quick_prints_no_unexplained_nan(quick_chart):
    """The tables print 'n/a(k)' with footnote k saying why (the multiple scattering rows' error,
    the visibility rows' bake without occlusion), never 'nan'."""
    out, proc = quick_chart
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert not re.search(r"\bnan\b", proc.stdout, re.IGNORECASE), proc.stdout   # ('dominant' has 'nan' in it)
    table = proc.stdout.splitlines()
    ms = [line for line in table if "+ MS" in line]
    assert ms and all("n/a(" in line for line in ms)
    marks = {m.split(")")[0] for line in table if not line.startswith("  n/a(") for m in line.split("n/a(")[1:]}
    notes = [line for line in table if line.startswith("  n/a(")]
    assert marks and len(notes) >= len(marks)
    assert any("white furnace" in n for n in notes) and any("occlusion is off" in n for n in notes)


def test_chart_quick_pareto_compares_alternatives_only(quick_chart):
    """The Pareto fronts hold only the IBL settings' alternatives (Setting.alternative): never a
    layer row (other presets, another frame material) or a multiple scattering row."""
    out, proc = quick_chart
    rows = [r for r in read_summary(out / "chart.csv") if r["factor"] != "visibility"]
    for r in rows:
        if r["factor"] in ("layer", "multiple scattering"):
            assert not r["pareto_bake"] and not r["pareto_frame"], r["setting"]
    assert any(r["pareto_bake"] for r in rows) and any(r["pareto_frame"] for r in rows)


def test_chart_quick_eta_waits_for_measured_steps(quick_chart):
    """The ETA is a lower bound naming the kinds of step not timed yet until every kind left has
    run (the first one, guessed from weights, was 14 s for a run of 51 s); then the measured
    times'."""
    out, proc = quick_chart
    steps = [line for line in proc.stderr.splitlines() if "alight chart: step " in line]
    assert "ETA unknown (reference, setting, frames, visibility not timed yet)" in steps[0], steps[0]
    assert steps[-1].endswith("ETA 0m00s"), steps[-1]


def test_progress_eta_from_measured_steps():
    """Progress: per kind the median of its steps after the first (the first compiles shaders)."""
    from alight.accuracy.chart import Progress

    now = [0.0]
    lines = io.StringIO()
    p = Progress(["a", "b", "b", "b", "b", "c"], lines, clock=lambda: now[0])
    # a: 2 s; b: 28 s (its first, with its shaders' compiles: not a typical b while 3 are left),
    # then 1 s each; c: a lower bound until it ran
    for t, expect in ((2.0, "ETA unknown (b, c not timed yet)"), (30.0, "ETA unknown (b, c not timed yet)"),
                      (31.0, "ETA >0m02s (c not timed yet)"), (32.0, "ETA >0m01s (c not timed yet)"),
                      (33.0, "ETA unknown (c not timed yet)"), (40.0, "ETA 0m00s")):
        now[0] = t
        p.step("x")
        assert lines.getvalue().splitlines()[-1].endswith(expect), (t, lines.getvalue())


def test_chart_quick_visibility_rows(quick_chart):
    """--quick's visibility rows: the bowl under royal_esplanade with each configuration, against
    the path tracer. Occlusion must remove most of the bowl's error (21.7% off, 2.8% on when
    written; benchmarks/results/occlusion-stretched-default.md has the same pair), and the
    reference's own noise (seed 0 against seed 1) must sit below the error it resolves."""
    from alight.accuracy.chart_visibility import QUICK_VISIBILITY_SCENES, VISIBILITY_CONFIGS

    out, proc = quick_chart
    assert proc.returncode == 0, proc.stderr[-3000:]
    rows = {r["setting"]: r for r in read_summary(out / "chart.csv") if r["factor"] == "visibility"}
    assert list(rows) == [f"visibility {s}: {c}" for s in QUICK_VISIBILITY_SCENES for c in VISIBILITY_CONFIGS]
    by = {name.split(": ")[1]: r for name, r in rows.items()}
    for config, r in by.items():
        assert r["scene"] == "bowl" and r["frame_ms"] > 0, config
        assert 0.0 < r["rel_mae_mean"] < 2.0, config
        assert r["rel_mae_mean"] == pytest.approx(r["rel_mae_max"]), config   # one environment
        assert 0.0 < r["ref_noise_mean"] < 0.05, config
        assert math.isnan(r["bake_ms"]) and not r["pareto_bake"]    # kept off the IBL bake panel
    assert by["off"]["occlusion"] == "off" and by["occlusion"]["occlusion"] == "on"
    assert by["off"]["shadows"] == by["occlusion"]["shadows"] == "off"
    # royal_esplanade has a sun: the shadow rows drew its map, and were timed under it
    assert by["shadows"]["shadows"] == by["auto"]["shadows"] == "on"
    meta = json.loads((out / "chart_meta.json").read_text())
    assert "royal_esplanade" in meta["visibility"] and "128 spp" in meta["visibility_error"]
    assert by["auto"]["occlusion"] == "on"      # the bowl hides enough of itself for 'auto' to bake
    assert math.isnan(by["off"]["visibility_bake_ms"]) and by["occlusion"]["visibility_bake_ms"] > 0
    assert by["occlusion"]["rel_mae_mean"] < 0.5 * by["off"]["rel_mae_mean"]
    assert by["auto"]["rel_mae_mean"] < 0.5 * by["off"]["rel_mae_mean"]
    assert by["occlusion"]["rel_mae_mean"] > by["occlusion"]["ref_noise_mean"]
    assert any(r["pareto_frame"] for r in by.values())
    assert "visibility bowl: occlusion" in proc.stdout


def test_visibility_summary_rows_keep_each_scene_apart():
    """The frontier is per scene (one scene's error is not another's), and the summary leaves out
    SUMMARY_EXCLUDED's environments as the probe rows do."""
    from alight.accuracy.chart import visibility_summary_rows
    from alight.accuracy.chart_visibility import VisibilityResult

    res = [VisibilityResult("bowl", "off", frame_seconds=0.01,
                            cases=[("a.hdr", 0.2, 0.01, False), ("spot1Lux.hdr", 0.9, 0.1, False)]),
           VisibilityResult("bowl", "occlusion", baked=True, bake_seconds=0.5, frame_seconds=0.02,
                            cases=[("a.hdr", 0.03, 0.01, False)]),
           VisibilityResult("bowl", "auto", baked=True, frame_seconds=0.03,
                            cases=[("a.hdr", 0.04, 0.01, True), ("b.hdr", 0.04, 0.01, False)]),
           VisibilityResult("corner", "off", frame_seconds=0.05, cases=[("a.hdr", 0.3, 0.02, False)])]
    rows = visibility_summary_rows(res)
    assert [r["setting"] for r in rows] == ["visibility bowl: off", "visibility bowl: occlusion",
                                            "visibility bowl: auto", "visibility corner: off"]
    assert [r["pareto_frame"] for r in rows] == [True, True, False, True]
    assert rows[0]["rel_mae_mean"] == pytest.approx(0.2) and rows[0]["ref_noise_mean"] == pytest.approx(0.01)
    assert rows[1]["visibility_bake_ms"] == pytest.approx(500.0) and rows[1]["occlusion"] == "on"
    assert [r["shadows"] for r in rows] == ["off", "off", "1/2 maps", "off"]


def test_chart_without_the_path_tracer_skips_the_visibility_rows(monkeypatch):
    import io

    from alight.accuracy import chart
    from alight.accuracy.chart_visibility import VisibilitySettings
    from alight.core import visibility

    monkeypatch.setattr(visibility, "embree_available", lambda: False)
    stream = io.StringIO()
    assert chart._visibility_rows(VisibilitySettings(), stream) is None
    assert len(stream.getvalue().splitlines()) == 1 and "embreex" in stream.getvalue()
    assert chart._visibility_rows(None, stream) is None


def test_chart_refuses_a_bad_environment(tmp_path, shared_data):
    bad = shared_data / "env" / "memorial.exr"
    proc = subprocess.run([sys.executable, "-m", "alight", "chart", "--quick", "--env", str(bad), "--out",
                           str(tmp_path / "c")], cwd=REPO, env=dict(os.environ), capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 2
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("alight: error: ") and "memorial.exr" in lines[0], proc.stderr
    assert not (tmp_path / "c").exists()


def test_editor_chart_view_reads_and_draws_the_latest_chart(quick_chart):
    """The panel's view finds the chart the last run noted, loads its series and draws them with
    implot (an imgui frame without a window: the draw calls run, nothing is shown)."""
    from alight.frontends.editor.chart_view import ChartView, find_chart_csv, load_chart

    out, proc = quick_chart
    assert proc.returncode == 0
    assert find_chart_csv() == (out / "chart.csv").resolve()      # noted in ALIGHT_CACHE_DIR by the run
    data = load_chart(out / "chart.csv")
    rows = read_summary(out / "chart.csv")
    # (The visibility rows have no bake time: the editor's bake-time view leaves them out.)
    judged = [r for r in rows if math.isfinite(r["rel_mae_mean"]) and r["factor"] != "visibility"]
    assert sum(len(x) for x, _, _ in data.factors.values()) == len(judged)
    assert data.frontier[2] and set(data.frontier[2]) == {r["setting"] for r in judged if r["pareto_bake"] == 1.0}
    assert np.all(np.diff(data.frontier[0]) >= 0) and np.all(np.diff(data.frontier[1]) <= 0)

    from imgui_bundle import imgui, implot

    ctx = imgui.create_context()
    implot.create_context()
    try:
        io = imgui.get_io()
        io.set_ini_filename("")   # imgui would write imgui.ini into the working directory
        io.display_size = imgui.ImVec2(600, 500)
        io.delta_time = 1 / 60
        io.backend_flags |= imgui.BackendFlags_.renderer_has_textures.value
        view = ChartView()
        for _ in range(2):
            imgui.new_frame()
            imgui.begin("chart")
            view.draw()
            imgui.end()
            imgui.render()
        assert view.error == "" and view.data is not None and view.data.settings == len(rows)
        broken = ChartView(out / "error_map.png")        # not a chart CSV: one line, no exception
        imgui.new_frame()
        imgui.begin("chart")
        broken.draw()
        imgui.end()
        imgui.render()
        assert broken.data is None and "error_map.png" in broken.error
    finally:
        implot.destroy_context()
        imgui.destroy_context(ctx)
