"""``alight chart``: what each bit of IBL accuracy costs.

One factor at a time around the ``medium`` bake quality (a full cartesian product would not be
tractable), plus every IBL model of ``app/core/ibl_models.py`` and multiple scattering on and off:

    irradiance     convolution at several output sizes and step counts; SH9
    specular cube  the prefiltered cube's face size
    samples        prefilter GGX samples at the first mip (4 ... 1024; medium's growth per mip)
    FIS            filtered importance sampling off
    LUT            BRDF LUT size; BRDF LUT sample count
    IBL model      every entry of IBL_MODELS
    layer          one row per material layer (``LAYER_ROWS``): the error of the presets
                   that use the layer against the layer's exact answer, the layer's own white
                   furnace (``LAYER_FURNACE``) and the ball's frame time with the layer on
    MS             multiple-scattering compensation on, for every model: judged by the white
                   furnace only (a metal with F0 = 1 under constant radiance 1 should give 1),
                   never against the single-scattering ground truth

The other rows are judged over the presets without layers (the BRDF's own error); a preset with
a layer counts in that layer's row only.

For each setting and environment: the bake time (the environment's passes, warm; the LUT is
cached on disk and timed apart, cold), the frame time (a fixed scene: the material ball at
``frame_size``, median of a few) and the error of the probe view against docs/conventions.md's ground
truth (``alight.accuracy.reference`` on the GPU) over the presets x roughness values: relMAE in linear
radiance and FLIP on the tone-mapped images (``alight.accuracy.metrics``).

The reference is computed once per environment, for three basis materials, all roughness
values in one G-buffer; every preset follows exactly from them because the BRDF is linear in F0
and in the base colour (see ``ReferenceTerms``). A preset with a layer has its own reference (one
G-buffer of its roughness values per level), without the roughness values where the layer's
lobe is too narrow for a texel sum (``alight.accuracy.reference``'s checks,
``alight.accuracy.ground_truth.check_transmission_lobe``). Roughness below 0.25 is summed over the full map;
from 0.25 up over the map box-reduced by 2 (``alight.accuracy.reference``'s level 1: <= 0.02% change on
royal_esplanade, ~1% on quarry_01's compact sun, small beside the split sum's 5-30%).

Writes in ``out``: chart.csv (one row per setting), chart_cases.csv (one row per setting,
environment, preset and roughness), furnace.csv, error_map.csv, chart.png, error_map.png.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from alight.errors import AlightError
from alight.ibl.bake import QUALITY, BakeQuality

# Roughness values of the ground-truth comparison (the reference refuses r < 0.1).
ROUGHNESS = (0.1, 0.25, 0.4, 0.6, 0.8, 1.0)
QUICK_ROUGHNESS = (0.25, 0.5, 1.0)
FURNACE_ROUGHNESS = (0.0, 0.25, 0.5, 0.75, 1.0)
# The white furnace's ground truth: a constant map this wide (the lobe at r = 0.25 spans several
# of its texels), from this roughness up.
FURNACE_TRUTH_WIDTH = 256
FURNACE_TRUTH_FROM = 0.25
QUICK_PRESETS = ("gold", "plastic_high", "water", "car_paint", "velvet", "brushed_aluminium",
                 "oil_film", "flint_glass", "leaf")   # from water on: the layers' rows
# Layers with a row of their own, the material of their white furnace (radiance 1:
# what the layer reflects and transmits must not exceed 1, and at roughness 0 it is exactly 1)
# and the preset drawn for their frame time. A preset counts in the row of the last of these it
# uses: flint_glass (dispersion, over the transmission it needs) in the dispersion row only.
LAYER_ROWS = ("clearcoat", "sheen", "anisotropy", "transmission", "iridescence", "dispersion",
              "diffuse_transmission")
LAYER_FURNACE = {
    # A white metal under a full coat, or under a white sheen: at most 1 (docs/layer_clearcoat.md,
    # docs/layer_sheen.md).
    "clearcoat": dict(base_color=(1.0, 1.0, 1.0), metallic=1.0, clearcoat=1.0, clearcoat_roughness=0.3),
    "sheen": dict(base_color=(1.0, 1.0, 1.0), metallic=1.0, sheen_color=(1.0, 1.0, 1.0), sheen_roughness=0.5),
    # A white metal with brushed_aluminium's anisotropy: exactly 1 would need multiple scattering,
    # so at most 1 (docs/layer_anisotropy.md).
    "anisotropy": dict(base_color=(1.0, 1.0, 1.0), metallic=1.0, anisotropy_strength=0.8,
                       anisotropy_rotation=1.5707963),
    # A thin white wall of ior 1 that transmits everything (docs/layer_transmission.md).
    "transmission": dict(base_color=(1.0, 1.0, 1.0), transmission=1.0, ior=1.0),
    # A white metal under oil_film's film: F_film (A + B) <= 1 (docs/layer_iridescence.md).
    "iridescence": dict(base_color=(1.0, 1.0, 1.0), metallic=1.0, iridescence=1.0, iridescence_ior=1.47,
                        iridescence_thickness_maximum=380.0),
    # flint_glass's clear, white, dispersive volume: what it reflects and refracts, at most 1
    # (docs/layer_dispersion.md; an ior of 1 would spread nothing).
    "dispersion": dict(base_color=(1.0, 1.0, 1.0), transmission=1.0, ior=1.7, thickness=2.0, dispersion=1.0),
    # A white sheet that sends all its diffuse light through the back: under radiance 1 it shows
    # what the same sheet without the layer shows (docs/layer_diffuse_transmission.md). That is not
    # at most 1: a white dielectric's BRDF exceeds 1 toward grazing view at low roughness
    # (docs/conventions.md; measured: 1.40 at r = 0, 1.05 at r = 0.5, 0.98 at r = 1, with or
    # without the layer).
    "diffuse_transmission": dict(base_color=(1.0, 1.0, 1.0), diffuse_transmission=1.0),
}
LAYER_FRAME_PRESET = {"clearcoat": "car_paint", "sheen": "velvet", "anisotropy": "brushed_aluminium",
                      "transmission": "water", "iridescence": "oil_film", "dispersion": "flint_glass",
                      "diffuse_transmission": "leaf"}


def layer_row(material) -> str:
    """The layer row (LAYER_ROWS) a preset counts in: the last of LAYER_ROWS it uses; '' for none."""
    used = [layer for layer in LAYER_ROWS if layer in material.layers()]
    return used[-1] if used else ""
# Environments left out of the summary columns (still in chart_cases.csv): spot1Lux's truth is
# near zero over most of the ball, where a relative error means little.
SUMMARY_EXCLUDED = ("spot1Lux",)
# n.v bins of the error map.
NV_BINS = 10
# Reference level: box-reduced by 2 from this roughness up (module docstring).
LEVEL1_FROM = 0.25
LATEST_FILE = "latest_chart.txt"   # in alight.paths.cache_dir(): where the last chart's CSV is
FRAME_REPEATS = 5


@dataclass(frozen=True)
class Setting:
    """One point of the sweep."""

    name: str
    factor: str
    quality: BakeQuality
    ibl_model: str
    multiple_scattering: bool = False
    layer: str = ""        # a layer row (LAYER_ROWS): judged over the presets with that layer

    @property
    def bake_key(self) -> BakeQuality:
        """What decides the environment's bake: the quality without its name and LUT (the LUT is
        swapped in without a re-bake)."""
        return replace(self.quality, name="", lut_size=0, lut_samples=0)

    @property
    def judged_by_truth(self) -> bool:
        return not self.multiple_scattering

    @property
    def alternative(self) -> bool:
        """Whether the setting is one of the IBL settings' alternatives to each other (the
        baseline, one factor changed, another IBL model), compared on the Pareto fronts. A layer
        row is judged on other presets (and its frame on another material), and a multiple
        scattering row by the white furnace only: neither is another way to draw the same thing."""
        return self.factor not in ("layer", "multiple scattering")


def sweep(quick: bool = False) -> list[Setting]:
    """The settings, one factor at a time around ``medium`` and the default IBL model; then the
    other models at ``medium``; then multiple scattering on, for every model."""
    from alight.core.ibl_models import DEFAULT_IBL_MODEL, IBL_MODELS

    base = QUALITY["medium"]
    lead = DEFAULT_IBL_MODEL if DEFAULT_IBL_MODEL in IBL_MODELS else next(iter(IBL_MODELS))
    models = [lead] + [m for m in IBL_MODELS if m != lead]
    out = [Setting(f"medium ({lead})", "baseline", base, lead)]

    def add(name, factor, **changes):
        out.append(Setting(name, factor, replace(base, name=name, **changes), lead))

    if quick:
        add("irradiance sh9", "irradiance", irradiance="sh9")
        add("prefilter samples 16", "prefilter samples", prefilter_samples=16)
        add("LUT 32", "LUT size", lut_size=32)
    else:
        add("irradiance sh9", "irradiance", irradiance="sh9")
        for phi, theta in ((16, 4), (32, 8), (128, 32)):
            add(f"irradiance conv {phi}x{theta} steps", "irradiance",
                irradiance_phi_steps=phi, irradiance_theta_steps=theta)
        for size in (8, 64):
            add(f"irradiance conv {size}^2 faces", "irradiance", irradiance_size=size)
        for size in (32, 64, 256):
            add(f"specular cube {size}", "specular cube", prefiltered_size=size)
        for n in (4, 16, 64, 256, 1024):
            add(f"prefilter samples {n}", "prefilter samples", prefilter_samples=n,
                prefilter_max_samples=max(base.prefilter_max_samples, n))
        add("FIS off", "FIS", filtered_importance_sampling=False)
        for size in (32, 64, 256):
            add(f"LUT {size}^2", "LUT size", lut_size=size)
        for n in (64, 256, 4096):
            add(f"LUT {n} samples", "LUT samples", lut_samples=n)
    for m in models[1:]:
        out.append(Setting(f"model {m}", "IBL model", base, m))
    for layer in LAYER_ROWS:
        out.append(Setting(f"layer {layer}", "layer", base, lead, layer=layer))
    for m in models:
        out.append(Setting(f"model {m} + MS", "multiple scattering", base, m, True))
    return out


# --- the reference -------------------------------------------------------------------------

@dataclass
class ReferenceTerms:
    """The ground truth for three basis materials per roughness, (R, S, S, 3) each:
    ``a`` a metal with F0 = 1, ``b`` a metal with F0 = 0, ``c`` a dielectric with F0 = 0 and
    base colour 1. With w = (1 - v.h)^5, F = F0 (1 - w) + w and kd = (1 - F)(1 - m) =
    (1 - F0)(1 - w)(1 - m), so for any material:

        L = F0 a + (1 - F0) b + (1 - m) base (1 - F0) (c - b) + emissive

    (a = S_spec, b = S_spec,w, c - b = the diffuse integral of (1 - w) / pi.)"""

    roughness: tuple[float, ...]
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    inside: np.ndarray          # (S, S) bool
    seconds: float = 0.0
    levels: dict = field(default_factory=dict)   # roughness -> level summed

    def combine(self, material, roughness: float) -> np.ndarray:
        """(S, S, 4) linear RGBA of docs/conventions.md's probe view for ``material``."""
        i = min(range(len(self.roughness)), key=lambda j: abs(self.roughness[j] - roughness))
        if abs(self.roughness[i] - roughness) > 1e-9:
            raise ValueError(f"roughness {roughness} was not summed")
        f0 = np.asarray(material.f0(), np.float64)
        base = np.asarray(material.base_color, np.float64)
        m = float(material.metallic)
        a, b, c = (t[i].astype(np.float64) for t in (self.a, self.b, self.c))
        rgb = f0 * a + (1.0 - f0) * b + (1.0 - m) * base * (1.0 - f0) * (c - b)
        rgb = rgb + np.asarray(material.emissive, np.float64)
        out = np.zeros(self.inside.shape + (4,), np.float32)
        out[..., :3] = np.where(self.inside[..., None], rgb, 0.0)
        out[..., 3] = self.inside
        return out


def layer_reference(ref_renderer, radiance: np.ndarray, size: int, material, roughness) -> dict:
    """The reference of one material with layers at each roughness its layers allow, (S, S, 4)
    linear RGBA by roughness: one G-buffer of those roughness values per environment level (the
    layers' factors are the scene material's, alight.accuracy.reference)."""
    from alight.accuracy.ground_truth import check_transmission_lobe
    from alight.accuracy.reference import GBUFFER, check_layer_roughness, check_roughness, probe_gbuffer
    from alight.core.scene import Scene
    from alight.errors import AlightError

    allowed = []
    for r in roughness:
        try:   # a lobe the texel sum cannot integrate has no reference, and so no case
            check_roughness(r)
            check_layer_roughness(replace(material, roughness=r))
            if {"transmission", "volume"} <= material.layers():
                check_transmission_lobe(r, material.ior)
        except (AlightError, ValueError):
            continue
        allowed.append(float(r))
    out = {}
    for level in (0, 1):
        rs = [r for r in allowed if (r >= LEVEL1_FROM) == bool(level)]
        if not rs:
            continue
        tiles = {name: np.concatenate([probe_gbuffer(size, replace(material, roughness=r))[name] for r in rs], axis=0)
                 for name in GBUFFER}
        res = ref_renderer.render_gbuffer(tiles, Scene(view="probe", material=material), radiance, env_level=level)
        for row, r in enumerate(rs):
            out[r] = res.linear[row * size:(row + 1) * size].copy()
    return out


def reference_terms(ref_renderer, radiance: np.ndarray, size: int, roughness) -> ReferenceTerms:
    """The three basis materials at every roughness, in one G-buffer per environment level."""
    from alight.accuracy.reference import GBUFFER, probe_gbuffer
    from alight.core.material import Material
    from alight.core.scene import Scene

    t0 = time.perf_counter()
    basis = (Material(base_color=(1.0, 1.0, 1.0), metallic=1.0),
             Material(base_color=(0.0, 0.0, 0.0), metallic=1.0),
             Material(base_color=(1.0, 1.0, 1.0), metallic=0.0, specular_f0=(0.0, 0.0, 0.0)))
    rs = tuple(float(r) for r in roughness)
    out = np.zeros((3, len(rs), size, size, 3), np.float32)
    inside = None
    levels = {}
    groups = {0: [i for i, r in enumerate(rs) if r < LEVEL1_FROM],
              1: [i for i, r in enumerate(rs) if r >= LEVEL1_FROM]}
    for level, idx in groups.items():
        if not idx:
            continue
        # Tiles: columns = basis materials, rows = roughness values of this level.
        tiles = {name: np.zeros((len(idx) * size, 3 * size, 4), np.float32) for name in GBUFFER}
        for row, i in enumerate(idx):
            for col, mat in enumerate(basis):
                g = probe_gbuffer(size, replace(mat, roughness=rs[i]))
                for name, arr in g.items():
                    tiles[name][row * size:(row + 1) * size, col * size:(col + 1) * size] = arr
                if inside is None:
                    inside = g["position"][..., 3] > 0.5
        res = ref_renderer.render_gbuffer(tiles, Scene(view="probe"), radiance, env_level=level)
        for row, i in enumerate(idx):
            levels[rs[i]] = res.env_level
            for col in range(3):
                out[col, i] = res.linear[row * size:(row + 1) * size, col * size:(col + 1) * size, :3]
    return ReferenceTerms(rs, out[0], out[1], out[2], inside, time.perf_counter() - t0, levels)


# --- measuring -----------------------------------------------------------------------------

@dataclass
class ChartConfig:
    envs: list[str]
    presets: list[str]
    roughness: tuple[float, ...] = ROUGHNESS
    size: int = 32                        # probe size for the errors
    frame_size: tuple[int, int] = (1280, 720)
    frame_repeats: int = FRAME_REPEATS
    settings: list[Setting] = field(default_factory=sweep)
    # The visibility rows (app/accuracy/chart_visibility.py); None: none.
    visibility: "VisibilitySettings | None" = field(default_factory=lambda: _visibility_settings())


def _visibility_settings():
    from alight.accuracy.chart_visibility import VisibilitySettings

    return VisibilitySettings()


@dataclass
class SettingResult:
    setting: Setting
    bake_seconds: list[float] = field(default_factory=list)     # per environment
    lut_seconds: float = math.nan                               # cold LUT bake, once
    frame_seconds: float = math.nan
    cases: list[tuple[str, str, float, float, float]] = field(default_factory=list)  # env, preset, r, rel, flip
    furnace: list[tuple[float, float, float, float]] = field(default_factory=list)   # r, mean, min, max

    def _over_cases(self, reduce, column: int) -> float:
        """reduce() of a column of the cases outside SUMMARY_EXCLUDED's environments; NaN if none."""
        c = [x[column] for x in self.cases if not any(e in x[0] for e in SUMMARY_EXCLUDED)]
        return float(reduce(c)) if c else math.nan

    @property
    def rel_mean(self) -> float:
        return self._over_cases(np.mean, 3)

    @property
    def rel_max(self) -> float:
        return self._over_cases(np.max, 3)

    @property
    def flip_mean(self) -> float:
        return self._over_cases(np.mean, 4)

    @property
    def bake_median(self) -> float:
        return statistics.median(self.bake_seconds) if self.bake_seconds else math.nan


def why_missing(res: SettingResult, column: str) -> str:
    """Why ``res`` has no value (NaN) in ``column`` ('rel', 'flip', 'bake', 'frame', 'furnace'),
    for the CLI's 'n/a' footnotes."""
    s = res.setting
    if column in ("rel", "flip"):
        if s.multiple_scattering:
            return ("multiple scattering rows are judged by the white furnace only (the ground truth is "
                    "single scattering)")
        if not res.cases:
            if s.layer:
                return (f"no case for the {s.layer} layer: no preset measured uses it, or its lobes are too "
                        f"narrow for the reference at the roughness values measured")
            return "no case: no preset without layers was measured"
        return f"only environments left out of the summary ({', '.join(SUMMARY_EXCLUDED)}) were measured"
    return "not measured"


class Progress:
    """'step i/N ... ETA' lines on stderr (one rewritten line on a terminal). Each step has a
    kind ('furnace', 'reference', 'setting', 'frames', 'visibility'); the ETA is the remaining
    steps' measured times: per kind, the median of its steps after the first (the first of a
    kind also compiles its shaders and bakes: 33-87 s of the first setting's, 0.1-2 s the
    others', in --quick runs), or the first's where only it ran and few of its kind are left.
    The kinds left that are not timed yet are named after the sum, which is then a lower bound
    ('ETA >0m05s (frames, visibility not timed yet)'; 'ETA unknown (...)' under a second):
    weights guessed in advance gave a first ETA of 14 s for a run of 51 s."""

    def __init__(self, kinds: list[str], stream=None, clock=time.perf_counter):
        self.kinds = list(kinds)
        self.total, self.done = len(self.kinds), 0
        self.stream = stream or sys.stderr
        self.clock = clock
        self.start = self.last = clock()
        self.seconds: dict[str, list[float]] = {}
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def typical(self, kind: str, left: int) -> float | None:
        """A step of ``kind``'s expected time, from those measured, with ``left`` of its steps
        still to run; None while it cannot be told (none ran, or only the first, with its
        one-time costs, and three or more are left: the next one comes soon)."""
        measured = self.seconds.get(kind, [])
        if len(measured) > 1:
            return statistics.median(measured[1:])
        if len(measured) == 1 and left < 3:
            return measured[0]
        return None

    def eta(self) -> tuple[float, list[str]]:
        """(seconds left for the kinds that are timed, the kinds left that are not)."""
        left = self.kinds[self.done:]
        seconds, untimed = 0.0, []
        for kind in dict.fromkeys(left):
            count = left.count(kind)
            t = self.typical(kind, count)
            if t is None:
                untimed.append(kind)
            else:
                seconds += t * count
        return seconds, untimed

    def eta_text(self) -> str:
        seconds, untimed = self.eta()
        if not untimed:
            return f"ETA {_mmss(seconds)}"
        if seconds < 1.0:
            return f"ETA unknown ({', '.join(untimed)} not timed yet)"
        return f"ETA >{_mmss(seconds)} ({', '.join(untimed)} not timed yet)"

    def step(self, what: str) -> None:
        now = self.clock()
        self.seconds.setdefault(self.kinds[self.done], []).append(now - self.last)
        self.last = now
        self.done += 1
        line = (f"alight chart: step {self.done}/{self.total} {what}  elapsed {_mmss(now - self.start)}  "
                f"{self.eta_text()}")
        if self.tty:
            self.stream.write("\r" + line[:150].ljust(150) + ("\n" if self.done == self.total else ""))
        else:
            self.stream.write(line + "\n")
        self.stream.flush()


def _mmss(s: float) -> str:
    s = max(0.0, s)
    return f"{int(s // 60)}m{int(s % 60):02d}s"


@contextlib.contextmanager
def _fresh_cache_dir():
    """ALIGHT_CACHE_DIR pointed at an empty folder for the block (to time a cold LUT bake)."""
    old = os.environ.get("ALIGHT_CACHE_DIR")
    with tempfile.TemporaryDirectory(prefix="alight-chart-lut-") as tmp:
        os.environ["ALIGHT_CACHE_DIR"] = tmp
        try:
            yield
        finally:
            if old is None:
                os.environ.pop("ALIGHT_CACHE_DIR", None)
            else:
                os.environ["ALIGHT_CACHE_DIR"] = old


def cold_lut_seconds(renderer, size: int, samples: int) -> float:
    from alight.ibl.bake import LutCache

    with _fresh_cache_dir():
        luts = LutCache(renderer.ctx, renderer.shaders)
        t = time.perf_counter()
        luts.get(size, samples)
        renderer.ctx.finish()
        seconds = time.perf_counter() - t
        luts.release()
    return seconds


def _bake(renderer, env, q: BakeQuality):
    """(maps, seconds of the environment's passes, warm; the LUT's lookup not counted)."""
    from alight.ibl.bake import bake_environment

    maps = bake_environment(renderer.ctx, renderer.shaders, env, q, renderer.luts)
    seconds = sum(v for k, v in maps.pass_seconds.items() if not k.startswith("brdf_lut"))
    return maps, seconds


def _with_lut(renderer, maps, q: BakeQuality):
    return replace(maps, brdf_lut=renderer.luts.get(q.lut_size, q.lut_samples), quality=q)


def _probe_scene(setting: Setting, material):
    from alight.core.scene import Scene

    return Scene(view="probe", material=material, ibl_model=setting.ibl_model,
                 multiple_scattering=setting.multiple_scattering)


def frame_material(setting: Setting):
    """The material ball's material for a setting's frame time: the default material, or for a
    layer row the preset that shows the layer (LAYER_FRAME_PRESET)."""
    from alight.core.material import Material
    from alight.exchange.presets import load_preset

    return load_preset(LAYER_FRAME_PRESET[setting.layer]) if setting.layer else Material()


def frame_seconds_interleaved(renderer, items, mesh, size, repeats: int) -> list[float]:
    """Median seconds of a frame of the material ball (``frame_material``, camera view, the
    environment behind it; render + finish, no read-back) for each (setting, maps) of ``items``.
    The repeats go round the settings in turn, so a burst of load from other work on the machine
    falls on all of them alike rather than on one."""
    from alight.core.scene import Scene

    w, h = size
    scenes = [Scene(mesh=mesh, material=frame_material(s), ibl_model=s.ibl_model,
                    multiple_scattering=s.multiple_scattering) for s, _ in items]
    for scene, (_, maps) in zip(scenes, items):    # compile the programs, make the targets
        renderer.render(scene, maps, w, h, read_linear=False, read_srgb=False)
    renderer.ctx.finish()
    times = [[] for _ in items]
    for _ in range(repeats):
        for k, (scene, (_, maps)) in enumerate(zip(scenes, items)):
            t = time.perf_counter()
            renderer.render(scene, maps, w, h, read_linear=False, read_srgb=False)
            renderer.ctx.finish()
            times[k].append(time.perf_counter() - t)
    return [statistics.median(t) for t in times]


def _furnace(renderer, setting: Setting, maps, size: int) -> list[tuple[float, float, float, float]]:
    from alight.core.material import Material

    rows = []
    for r in FURNACE_ROUGHNESS:
        if setting.layer:
            m = Material(roughness=r, **LAYER_FURNACE[setting.layer])
        else:
            m = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=r)
        frame = renderer.render(_probe_scene(setting, m), maps, size, size, read_srgb=False)
        inside = frame.linear[..., 3] > 0
        v = frame.linear[..., :3][inside].mean(axis=1)
        rows.append((r, float(v.mean()), float(v.min()), float(v.max())))
    return rows


def furnace_truth(ref_renderer, size: int) -> list[tuple[float, float, float, float]]:
    """docs/conventions.md's ground truth of the white furnace (metal, F0 = 1, radiance 1): per
    roughness >= FURNACE_TRUTH_FROM, (r, mean, min, max) over the probe's pixels. It is below 1:
    the single-scattering BRDF loses the energy of the rays that bounce more than once."""
    from alight.ibl.environment import constant_environment

    rs = [r for r in FURNACE_ROUGHNESS if r >= FURNACE_TRUTH_FROM]
    env = constant_environment(1.0, FURNACE_TRUTH_WIDTH)
    terms = reference_terms(ref_renderer, env.radiance, size, rs)
    rows = []
    for i, r in enumerate(rs):
        v = terms.a[i][terms.inside].mean(axis=1)
        rows.append((r, float(v.mean()), float(v.min()), float(v.max())))
    return rows


class ErrorMap:
    """sum |test - ref| and sum |ref| binned by (roughness, n.v), per IBL model."""

    def __init__(self, roughness, size: int):
        from alight.core.shading import probe_normals

        normals, inside = probe_normals(size)
        self.roughness = tuple(roughness)
        self.inside = inside
        self.bins = np.minimum((normals[..., 2] * NV_BINS).astype(int), NV_BINS - 1)
        self.num: dict[str, np.ndarray] = {}
        self.den: dict[str, np.ndarray] = {}

    def add(self, model: str, r: float, test: np.ndarray, ref: np.ndarray) -> None:
        i = self.roughness.index(r)
        num = self.num.setdefault(model, np.zeros((len(self.roughness), NV_BINS)))
        den = self.den.setdefault(model, np.zeros((len(self.roughness), NV_BINS)))
        diff = np.abs(test[..., :3] - ref[..., :3]).sum(axis=2)
        mag = np.abs(ref[..., :3]).sum(axis=2)
        b = self.bins[self.inside]
        np.add.at(num[i], b, diff[self.inside])
        np.add.at(den[i], b, mag[self.inside])

    def relative(self, model: str) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.den[model] > 0, self.num[model] / self.den[model], np.nan)


def _mosaic(tiles: list[list[np.ndarray]], pad: int = 4) -> np.ndarray:
    rows = []
    for row in tiles:
        cells = []
        for t in row:
            cells.append(np.pad(t, ((pad, pad), (pad, pad), (0, 0))))
        rows.append(np.concatenate(cells, axis=1))
    return np.concatenate(rows, axis=0)


def run_chart(config: ChartConfig, out_dir: str | os.PathLike, stream=None) -> list[SettingResult]:
    """Measure every setting of ``config`` on every environment; write the files (module
    docstring) in ``out_dir``; returns the results."""
    from alight.accuracy.metrics import flip, relative_mae, tonemapped_srgb
    from alight.accuracy.reference import ReferenceRenderer
    from alight.core.mesh import sphere
    from alight.exchange.presets import load_preset
    from alight.ibl.environment import constant_environment, load_environment
    from alight.render.renderer import ForwardRenderer

    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise AlightError(f"{out_dir}: exists and is not a folder")
    presets = [load_preset(p) for p in config.presets]
    base_presets = [p for p in presets if not p.layers()]
    layered = {layer: [p for p in presets if layer_row(p) == layer] for layer in LAYER_ROWS}
    envs = []
    for spec in config.envs:
        envs.append(load_environment(spec))
    if not envs:
        raise AlightError("--env: no environment to measure")
    for r in config.roughness:
        if r < 0.1:
            raise AlightError(f"roughness {r}: the reference starts at 0.1")
    os.makedirs(out_dir, exist_ok=True)

    settings = config.settings
    results = [SettingResult(s) for s in settings]
    visibility = _visibility_rows(config.visibility, stream)
    # The steps' kinds, for the ETA (Progress): the frame times under the first environment only.
    env_steps = ["reference"] + ["setting"] * len(settings) + (["visibility"] if visibility else [])
    progress = Progress(["furnace"] + env_steps[:1 + len(settings)] + (["frames"] if settings else []) + env_steps[1 + len(settings):]
                        + env_steps * (len(envs) - 1), stream)
    renderer = ForwardRenderer()
    ref_renderer = ReferenceRenderer(renderer)
    error_map = ErrorMap(config.roughness, config.size)
    size, pad = config.size, 4
    ball = sphere()
    try:
        # Cold LUT bakes (once per LUT in the sweep) and the white furnace (environment-free).
        lut_cold = {}
        for res in results:
            q = res.setting.quality
            key = (q.lut_size, q.lut_samples)
            if key not in lut_cold:
                lut_cold[key] = cold_lut_seconds(renderer, *key)
            res.lut_seconds = lut_cold[key]
        furnace_env = constant_environment(1.0, 64)
        furnace_bakes = {}
        for res in results:
            s = res.setting
            if s.bake_key not in furnace_bakes:
                furnace_bakes[s.bake_key] = _bake(renderer, furnace_env, s.quality)[0]
            res.furnace = _furnace(renderer, s, _with_lut(renderer, furnace_bakes[s.bake_key], s.quality), size)
        for maps in furnace_bakes.values():
            maps.release()
        truth_furnace = furnace_truth(ref_renderer, size)
        progress.step(f"white furnace and {len(lut_cold)} cold LUT bakes")

        for e, env in enumerate(envs):
            env_name = Path(env.name).stem
            terms = reference_terms(ref_renderer, env.radiance, size, config.roughness)
            progress.step(f"{env_name}: reference ({terms.seconds:.1f} s)")
            refs = {(p.name, r): terms.combine(replace(p, roughness=r), r)
                    for p in base_presets for r in config.roughness}
            for layer, ps in layered.items():
                for p in ps:
                    for r, image in layer_reference(ref_renderer, env.radiance, size, p, config.roughness).items():
                        refs[(p.name, r)] = image
            ref_srgb = {k: tonemapped_srgb(v) for k, v in refs.items()}
            bakes = {}
            frame_items = []
            for res in results:
                s = res.setting
                if s.bake_key not in bakes:
                    bakes[s.bake_key] = _bake(renderer, env, s.quality)
                maps, bake_s = bakes[s.bake_key]
                res.bake_seconds.append(bake_s)
                maps = _with_lut(renderer, maps, s.quality)
                if e == 0:
                    frame_items.append((res, maps))
                if s.judged_by_truth and (layered[s.layer] if s.layer else base_presets):
                    test_tiles, ref_tiles, cells = [], [], []
                    for p in (layered[s.layer] if s.layer else base_presets):
                        trow, rrow = [], []
                        for r in config.roughness:
                            ref = refs.get((p.name, r))
                            if ref is None:   # a layer's lobe too narrow for the texel sum: no case
                                blank = np.zeros((size, size, 3), np.float32)
                                trow.append(blank)
                                rrow.append(blank)
                                cells.append(None)
                                continue
                            frame = renderer.render(_probe_scene(s, replace(p, roughness=r)), maps, size, size,
                                                    read_srgb=False)
                            rel = relative_mae(frame.linear, ref, terms.inside)
                            cells.append((p.name, r, rel))
                            trow.append(tonemapped_srgb(frame.linear))
                            rrow.append(ref_srgb[(p.name, r)])
                            if s.factor in ("baseline", "IBL model"):
                                error_map.add(s.ibl_model, r, frame.linear, ref)
                        test_tiles.append(trow)
                        ref_tiles.append(rrow)
                    _, flip_map = flip(_mosaic(test_tiles, pad), _mosaic(ref_tiles, pad))
                    cell = size + 2 * pad
                    for k, cell_case in enumerate(cells):
                        if cell_case is None:
                            continue
                        pname, r, rel = cell_case
                        i, j = divmod(k, len(config.roughness))
                        tile = flip_map[i * cell + pad:i * cell + pad + size, j * cell + pad:j * cell + pad + size]
                        res.cases.append((env_name, pname, r, rel, float(tile[terms.inside].mean())))
                progress.step(f"{env_name}: {s.name}")
            if frame_items:
                medians = frame_seconds_interleaved(renderer, [(r.setting, m) for r, m in frame_items], ball,
                                                    config.frame_size, config.frame_repeats)
                for (res, _), seconds in zip(frame_items, medians):
                    res.frame_seconds = seconds
                progress.step("frame times")
            if visibility:
                _measure_visibility(renderer, env, env_name, bakes, results[0].setting, visibility, config,
                                    e == len(envs) - 1)
                progress.step(f"{env_name}: visibility rows")
            for maps, _ in bakes.values():
                maps.release()
        if visibility:
            from alight.accuracy.chart_visibility import add_bake_seconds

            add_bake_seconds(*visibility)
    finally:
        renderer.release()

    vis_results = visibility[1] if visibility else []
    write_outputs(results, error_map, config, out_dir, truth_furnace, vis_results)
    _remember(out_dir / "chart.csv")
    return results


def _visibility_rows(settings, stream):
    """(the scenes' meshes, a VisibilityResult per scene x configuration), or None where there are
    none to measure: none asked for, or no path tracer (one warning line)."""
    from alight.core.visibility import embree_available

    if settings is None or not settings.scenes:
        return None
    if not embree_available():
        (stream or sys.stderr).write("alight chart: no visibility rows: the path tracer needs embreex "
                                     "(pip install embreex)\n")
        return None
    from alight.accuracy.chart_visibility import new_results, scene_meshes

    return scene_meshes(settings.scenes), new_results(settings)


def _measure_visibility(renderer, env, env_name, bakes, baseline: Setting, visibility, config, last: bool) -> None:
    """The visibility rows under one environment, with the baseline setting's bake (medium, the
    default IBL model). Their frame times once: under the first environment with a sun, where the
    shadows configuration draws its shadow map (under a map without one it draws what 'off' draws,
    and its time would say nothing), or the last one where none has a sun."""
    from alight.accuracy.chart_visibility import frame_seconds_interleaved as vis_frames
    from alight.accuracy.chart_visibility import measure_environment

    meshes, vis_results = visibility
    maps = _with_lut(renderer, bakes[baseline.bake_key][0], baseline.quality)
    measure_environment(renderer, maps, env.radiance, env_name, meshes, vis_results, config.visibility)
    if math.isnan(vis_results[0].frame_seconds) and (maps.suns or last):
        vis_frames(renderer, maps, meshes, vis_results, config.frame_size, config.frame_repeats, env_name)


# --- writing -------------------------------------------------------------------------------

SUMMARY_FIELDS = ("setting", "factor", "ibl_model", "multiple_scattering", "irradiance", "irradiance_size",
                  "irradiance_steps", "specular_cube", "prefilter_samples", "fis", "lut_size", "lut_samples",
                  "bake_ms", "lut_cold_ms", "frame_ms", "rel_mae_mean", "rel_mae_max", "flip_mean",
                  "furnace_mean", "furnace_min", "furnace_max", "furnace_r1", "pareto_bake", "pareto_frame",
                  # the visibility rows' (app/accuracy/chart_visibility.py; empty on the others)
                  "scene", "occlusion", "shadows", "visibility_bake_ms", "ref_noise_mean")


def pareto(points: list[tuple[float, float]]) -> list[bool]:
    """For (time, error) points: True where no other point is at most as slow and as wrong and
    strictly better in one of them. NaN points are never on the frontier."""
    flags = []
    for i, (t, e) in enumerate(points):
        if not (math.isfinite(t) and math.isfinite(e)):
            flags.append(False)
            continue
        dominated = any(math.isfinite(t2) and math.isfinite(e2) and t2 <= t and e2 <= e and (t2 < t or e2 < e)
                        for j, (t2, e2) in enumerate(points) if j != i)
        flags.append(not dominated)
    return flags


def _csv_text(header, rows) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)
    return buf.getvalue()


def _fmt(x, digits=6):
    if isinstance(x, bool):
        return int(x)
    if isinstance(x, float):
        return "" if not math.isfinite(x) else f"{x:.{digits}g}"
    return x


def alternatives_pareto(results: list[SettingResult], seconds) -> list[bool]:
    """``pareto`` of (seconds(result), mean relMAE) among the results whose settings are
    alternatives to each other (Setting.alternative: not the layer rows, not multiple
    scattering's); False for the others."""
    pick = [i for i, r in enumerate(results) if r.setting.alternative]
    flags = [False] * len(results)
    for i, flag in zip(pick, pareto([(seconds(results[i]), results[i].rel_mean) for i in pick])):
        flags[i] = flag
    return flags


def summary_rows(results: list[SettingResult]) -> list[dict]:
    bake_front = alternatives_pareto(results, lambda r: r.bake_median)
    frame_front = alternatives_pareto(results, lambda r: r.frame_seconds)
    rows = []
    for res, pb, pf in zip(results, bake_front, frame_front):
        s, q = res.setting, res.setting.quality
        r1 = [f[1] for f in res.furnace if f[0] == 1.0]
        rows.append({
            "setting": s.name, "factor": s.factor, "ibl_model": s.ibl_model,
            "multiple_scattering": s.multiple_scattering, "irradiance": q.irradiance,
            "irradiance_size": q.irradiance_size,
            "irradiance_steps": f"{q.irradiance_phi_steps}x{q.irradiance_theta_steps}" if q.irradiance == "convolution" else "",
            "specular_cube": q.prefiltered_size, "prefilter_samples": q.prefilter_samples,
            "fis": q.filtered_importance_sampling, "lut_size": q.lut_size, "lut_samples": q.lut_samples,
            "bake_ms": res.bake_median * 1000, "lut_cold_ms": res.lut_seconds * 1000,
            "frame_ms": res.frame_seconds * 1000,
            "rel_mae_mean": res.rel_mean, "rel_mae_max": res.rel_max, "flip_mean": res.flip_mean,
            "furnace_mean": float(np.mean([f[1] for f in res.furnace])) if res.furnace else math.nan,
            "furnace_min": min((f[2] for f in res.furnace), default=math.nan),
            "furnace_max": max((f[3] for f in res.furnace), default=math.nan),
            "furnace_r1": r1[0] if r1 else math.nan,
            "pareto_bake": pb, "pareto_frame": pf,
            "scene": "", "occlusion": "", "shadows": "", "visibility_bake_ms": math.nan, "ref_noise_mean": math.nan,
        })
    return rows


def visibility_summary_rows(vis_results) -> list[dict]:
    """chart.csv's rows of the visibility results: error against frame time, the frontier per
    scene (a scene's error is not comparable with another's, nor with the probe's)."""
    rows = []
    for scene in dict.fromkeys(r.scene for r in vis_results):
        group = [r for r in vis_results if r.scene == scene]
        front = pareto([(r.frame_seconds, r.over_maps(1, excluded=SUMMARY_EXCLUDED)) for r in group])
        for res, pf in zip(group, front):
            row = {k: math.nan for k in SUMMARY_FIELDS}
            row.update({
                "setting": res.name, "factor": "visibility", "ibl_model": "", "multiple_scattering": False,
                "irradiance": "", "irradiance_steps": "", "fis": "",
                "frame_ms": res.frame_seconds * 1000,
                "rel_mae_mean": res.over_maps(1, excluded=SUMMARY_EXCLUDED),
                "rel_mae_max": res.over_maps(1, np.max, SUMMARY_EXCLUDED),
                "pareto_bake": False, "pareto_frame": pf, "scene": scene,
                "occlusion": "on" if res.baked else "off", "shadows": res.shadows_drawn,
                "visibility_bake_ms": res.bake_seconds * 1000,
                "ref_noise_mean": res.over_maps(2, excluded=SUMMARY_EXCLUDED),
            })
            rows.append(row)
    return rows


def write_outputs(results, error_map: ErrorMap, config: ChartConfig, out_dir: Path, truth_furnace=(),
                  vis_results=()) -> None:
    from alight.exchange.output import write_text_atomic

    rows = summary_rows(results) + visibility_summary_rows(vis_results)
    write_text_atomic(out_dir / "chart.csv", _csv_text(SUMMARY_FIELDS, [[_fmt(r[k]) for k in SUMMARY_FIELDS] for r in rows]))
    write_text_atomic(out_dir / "chart_cases.csv", _csv_text(
        ("setting", "environment", "preset", "roughness", "rel_mae", "flip"),
        [[res.setting.name, env, p, _fmt(r), _fmt(rel), _fmt(fl)] for res in results for env, p, r, rel, fl in res.cases]
        # the visibility rows: the scene in the preset column, the grey's roughness, no FLIP
        + [[res.name, env, res.scene, _fmt(0.5), _fmt(rel), ""] for res in vis_results for env, rel, *_ in res.cases]))
    write_text_atomic(out_dir / "furnace.csv", _csv_text(
        ("setting", "ibl_model", "multiple_scattering", "roughness", "mean", "min", "max"),
        [[res.setting.name, res.setting.ibl_model, int(res.setting.multiple_scattering), _fmt(r), _fmt(a), _fmt(b), _fmt(c)]
         for res in results for r, a, b, c in res.furnace]
        + [["ground truth", "", 0, _fmt(r), _fmt(a), _fmt(b), _fmt(c)] for r, a, b, c in truth_furnace]))
    map_rows = []
    for model in error_map.num:
        rel = error_map.relative(model)
        for i, r in enumerate(error_map.roughness):
            for b in range(NV_BINS):
                map_rows.append([model, _fmt(r), _fmt(b / NV_BINS), _fmt((b + 1) / NV_BINS), _fmt(float(rel[i, b]))])
    write_text_atomic(out_dir / "error_map.csv", _csv_text(("ibl_model", "roughness", "nv_lo", "nv_hi", "rel_mae"), map_rows))
    title = (f"{len(config.envs)} environment(s), {len(config.presets)} presets, roughness "
             f"{', '.join(f'{r:g}' for r in config.roughness)}, probe {config.size}x{config.size}")
    frame = f"material ball at {config.frame_size[0]}x{config.frame_size[1]}, median"
    meta = {"title": title, "frame": frame}
    if vis_results:
        v = config.visibility
        meta["visibility"] = (f"scene camera at {config.frame_size[0]}x{config.frame_size[1]}"
                              f" under {vis_results[0].frame_env}")
        meta["visibility_error"] = f"{v.size}x{v.size} px, {v.samples} spp"
    write_text_atomic(out_dir / "chart_meta.json", json.dumps(meta) + "\n")
    replot(out_dir)


def replot(out_dir: str | os.PathLike) -> list[Path]:
    """Draw chart.png and error_map.png from the CSVs (and chart_meta.json) in ``out_dir``."""
    from alight.accuracy.chart_plot import plot_chart, plot_error_map

    out_dir = Path(out_dir)
    try:
        meta = json.loads((out_dir / "chart_meta.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        meta = {"title": "", "frame": "material ball, median"}
    written = [plot_chart(read_summary(out_dir / "chart.csv"), read_summary(out_dir / "furnace.csv"),
                          out_dir / "chart.png", meta["title"], meta["frame"],
                          (meta.get("visibility", ""), meta.get("visibility_error", "")))]
    maps: dict[str, dict[float, dict[float, float]]] = {}
    for row in read_summary(out_dir / "error_map.csv"):
        maps.setdefault(row["ibl_model"], {}).setdefault(row["roughness"], {})[row["nv_lo"]] = row["rel_mae"]
    if maps:
        arrays = {}
        for model, by_r in maps.items():
            rs = sorted(by_r)
            arrays[model] = (rs, np.array([[by_r[r][b] for b in sorted(by_r[r])] for r in rs]))
        written.append(plot_error_map(arrays, out_dir / "error_map.png", meta["title"]))
    return written


def _remember(csv_path: Path) -> None:
    """Note where the latest chart is, for the editor's panel."""
    from alight.exchange.output import write_text_atomic
    from alight.paths import cache_dir

    try:
        os.makedirs(cache_dir(), exist_ok=True)
        write_text_atomic(cache_dir() / LATEST_FILE, str(csv_path.resolve()))
    except OSError:
        pass


def latest_chart_csv() -> Path | None:
    from alight.paths import cache_dir

    try:
        p = Path((cache_dir() / LATEST_FILE).read_text(encoding="utf-8").strip())
    except OSError:
        return None
    return p if p.is_file() else None


def read_summary(path: str | os.PathLike) -> list[dict]:
    """chart.csv's rows as dicts (numbers as float, empty as NaN)."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    out = []
    for row in rows:
        d = {}
        for k, v in row.items():
            try:
                d[k] = float(v) if v != "" else math.nan
            except (TypeError, ValueError):
                d[k] = v
        out.append(d)
    return out


# --- the environments ----------------------------------------------------------------------

def default_env_dir() -> Path | None:
    """../shared/data/env beside the checkout (or the working directory), if there."""
    for base in (Path(__file__).resolve().parents[1], Path.cwd()):
        d = base.parent / "shared" / "data" / "env"
        if d.is_dir():
            return d
    return None


def equirect_envs(directory: Path) -> tuple[list[str], list[str]]:
    """(the 2:1 .hdr/.exr maps in directory, sorted; one 'name: reason' per file skipped)."""
    import OpenImageIO as oiio

    keep, skipped = [], []
    for p in sorted(list(directory.glob("*.hdr")) + list(directory.glob("*.exr"))):
        inp = oiio.ImageInput.open(str(p))
        if inp is None:
            skipped.append(f"{p.name}: unreadable")
            continue
        spec = inp.spec()
        inp.close()
        if spec.width != 2 * spec.height:
            skipped.append(f"{p.name}: not 2:1 ({spec.width}x{spec.height})")
        else:
            keep.append(str(p))
    return keep, skipped
