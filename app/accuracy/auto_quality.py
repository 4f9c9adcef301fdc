"""``--quality auto``: the cheapest bake whose predicted implementation error fits a budget.

The implementation error is the probe view's sum |render - converged| / sum |converged|, the
converged result being app/accuracy/converged.py's split sum of the same formulas (what the bake tends to
with infinite samples and resolution). It is not the distance to the ground truth.

Three parts:
- ``CANDIDATES``: bake settings from cheap to expensive, each derived from app/ibl/bake.py's QUALITY;
- ``auto_quality_table.json`` (beside this file): the error of every candidate on every shared
  environment for two material archetypes (grey dielectric, gold) at a few roughness values,
  with each candidate's bake time, measured by ``tools/measure_auto_quality.py`` (not typed);
- ``choose_quality``: pure. The environment's class (does it hold a compact source, app/ibl/sun.py;
  is its irradiance smooth enough for 9 spherical harmonics) picks the measured maps it is
  compared with; the scene's materials pick the archetypes and the roughness band. Predicted
  error = the worst measured error over those; the choice is the candidate of least predicted
  bake time under the budget, with ``max_roughness`` set to the roughest material (grid steps
  beyond it are not sampled). No environment (or intensity 0): no bake at all.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path

import numpy as np

from alight.ibl.bake import QUALITY, BakeQuality

TABLE_PATH = Path(__file__).with_name("auto_quality_table.json")
DEFAULT_ERROR_BUDGET = 0.02          # 2% on the probe, the default
# Irradiance is "smooth" when 9 spherical harmonics reproduce the converged irradiance (E/pi,
# suns included as the bake adds them) within this relative error (environment_features).
SH9_SMOOTH_RESIDUAL = 0.02
# Roughness values the table is measured at; a material between two takes the worse of the two.
ROUGHNESS_POINTS = (0.0, 0.15, 0.25, 0.5, 0.75, 1.0)
ARCHETYPES = ("dielectric", "metal")   # grey 0.8 dielectric (F0 0.04), gold
# Measured but left out of the predictions, with the reason.
EXCLUDED = {"spot1Lux.hdr": "one spot on black: the converged value is ~0 over most of the probe, "
                            "so a relative error means little (as the ground truth's definition says)"}


def _lut_of(q: BakeQuality, like: BakeQuality) -> BakeQuality:
    return replace(q, lut_size=like.lut_size, lut_samples=like.lut_samples)


def _convolution(q: BakeQuality) -> BakeQuality:
    m = QUALITY["medium"]
    return replace(q, irradiance="convolution", irradiance_size=m.irradiance_size,
                   irradiance_phi_steps=m.irradiance_phi_steps, irradiance_theta_steps=m.irradiance_theta_steps)


def _candidates() -> dict[str, BakeQuality]:
    low, medium, high = QUALITY["low"], QUALITY["medium"], QUALITY["high"]
    low = _lut_of(low, medium)                                   # one cached LUT for the cheap rows
    rough = replace(low, prefiltered_size=32)                   # first grid step at r = 0.5
    mirror = replace(rough, cube_size=512)                      # mirror detail, little prefilter
    rows = {
        "rough-sh9": rough,
        "rough": _convolution(rough),
        "low": low,
        "low-conv": _convolution(low),
        "mirror-sh9": mirror,
        "mirror": _convolution(mirror),
        "medium-sh9": replace(medium, irradiance="sh9"),
        "medium": medium,
        "medium-512": replace(medium, cube_size=512),
        "medium-fine": replace(medium, cube_size=512, prefiltered_size=256),  # first step r = 0.18
        "high": high,
    }
    return {name: replace(q, name=f"auto:{name}") for name, q in rows.items()}


CANDIDATES: dict[str, BakeQuality] = _candidates()


# --------------------------------------------------------------------------------------------
# What the choice reads from a scene and an environment
# --------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class MaterialNeed:
    """One material as the table sees it: which archetypes it mixes and its roughness range."""

    archetypes: tuple[str, ...]
    roughness_min: float
    roughness_max: float


@dataclass(frozen=True)
class EnvironmentFeatures:
    has_compact_source: bool     # app/ibl/sun.py found a source with >= 5% of the power
    sh9_residual: float          # relative error of SH9 irradiance against the texel sum

    @property
    def smooth(self) -> bool:
        return self.sh9_residual <= SH9_SMOOTH_RESIDUAL

    def describe(self) -> str:
        return (f"{'a compact source' if self.has_compact_source else 'no compact source'}, "
                f"irradiance {'smooth' if self.smooth else 'detailed'} (SH9 residual {self.sh9_residual * 100:.1f}%)")


@dataclass(frozen=True)
class Choice:
    quality: BakeQuality | None  # None: no image-based lighting, nothing baked
    name: str
    predicted_error: float       # fraction; 0 when nothing is baked
    predicted_seconds: float
    meets_budget: bool
    reason: str

    def line(self, budget: float) -> str:
        if self.quality is None:
            return f"quality auto: no bake ({self.reason})"
        verdict = "within" if self.meets_budget else "OVER"
        return (f"quality auto: {self.name} (max roughness {self.quality.max_roughness:.2f}): predicted error "
                f"{self.predicted_error * 100:.2f}% {verdict} the {budget * 100:g}% budget, predicted bake "
                f"{self.predicted_seconds * 1000:.0f} ms; {self.reason}")


def material_need(metallic: float, roughness: float, *, metallic_map: bool = False,
                  roughness_map: bool = False) -> MaterialNeed:
    """A material's archetypes and roughness range; texture maps multiply the factors, so a
    map makes anything from 0 up to the factor possible."""
    m, r = float(metallic), float(roughness)
    lo_m = 0.0 if metallic_map else m
    kinds = tuple(k for k, ok in (("dielectric", lo_m < 1.0), ("metal", m > 0.0)) if ok)
    return MaterialNeed(kinds or ("dielectric",), 0.0 if roughness_map else r, r)


def scene_needs(scene) -> list[MaterialNeed]:
    """The MaterialNeeds of a Scene's visible materials (app/render/renderer.py's choice of material
    per part), plus the background blur's roughness when the background reads the grid."""
    needs = []
    if scene.view == "probe" or scene.mesh is None:
        needs.append(material_need(scene.material.metallic, scene.material.roughness))
    else:
        for part in scene.mesh.parts:
            fm = part.material
            if fm is None or not scene.use_file_materials:
                needs.append(material_need(scene.material.metallic, scene.material.roughness))
                continue
            over = scene.material_overrides
            mr_map = fm.metallic_roughness_texture is not None
            needs.append(material_need(over.get("metallic", fm.metallic), over.get("roughness", fm.roughness),
                                       metallic_map=mr_map, roughness_map=mr_map))
    if scene.display.background == "blur":
        r = float(scene.display.blur_roughness)
        needs.append(MaterialNeed((), r, r))   # the grid must reach it; no error attached
    return needs


def _fibonacci_sphere(count: int) -> np.ndarray:
    i = np.arange(count) + 0.5
    y = 1.0 - 2.0 * i / count
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    s = np.sqrt(1.0 - y * y)
    return np.stack([s * np.cos(phi), y, s * np.sin(phi)], axis=1)


def _reduced(radiance: np.ndarray, max_width: int) -> np.ndarray:
    from alight.core.equirect import box_reduce

    h, w = radiance.shape[:2]
    f = max(1, w // max_width)
    while h % f:
        f -= 1
    return box_reduce(radiance, f)


def environment_features(radiance: np.ndarray) -> EnvironmentFeatures:
    """The class of an environment: compact sources (app/ibl/sun.py, on the map reduced to at most
    1024 wide) and how far 9 spherical harmonics are from the converged irradiance (on the map
    reduced to at most 128 wide, 256 normals; suns added in closed form to the texel sum and as
    SH9 to the harmonics, as the bake does). About 0.1 s for a 1k map."""
    from alight.accuracy.converged import irradiance_converged
    from alight.core.shading import texel_directions
    from alight.ibl.bake import sh9_basis
    from alight.ibl.sun import extract_suns

    _, suns = extract_suns(_reduced(radiance, 1024))
    small = _reduced(radiance, 128)
    lighting, small_suns = extract_suns(small)
    normals = _fibonacci_sphere(256)
    exact = irradiance_converged(small, normals)            # the map as it is, suns as texels
    dirs, omega = texel_directions(*small.shape[:2])
    coeffs = _sh9_rows(dirs.reshape(-1, 3)).T @ (lighting.reshape(-1, 3).astype(np.float64) * omega.reshape(-1, 1))
    for sun in small_suns:
        coeffs += sh9_basis(sun.direction)[:, None] * sun.power[None, :]
    # Irradiance / pi from SH9 (Ramamoorthi and Hanrahan 2001): band factors pi, 2pi/3, pi/4.
    band = np.array([math.pi] + [2.0 * math.pi / 3.0] * 3 + [math.pi / 4.0] * 5) / math.pi
    approx = _sh9_rows(normals) @ (coeffs * band[:, None])
    denom = float(np.abs(exact).sum())
    residual = float(np.abs(approx - exact).sum() / denom) if denom > 0 else 0.0
    return EnvironmentFeatures(bool(suns), residual)


def _sh9_rows(d: np.ndarray) -> np.ndarray:
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    return np.stack([np.full_like(x, 0.282095), 0.488603 * y, 0.488603 * z, 0.488603 * x,
                     1.092548 * x * y, 1.092548 * y * z, 0.315392 * (3.0 * z * z - 1.0),
                     1.092548 * x * z, 0.546274 * (x * x - y * y)], axis=1)


# --------------------------------------------------------------------------------------------
# The measured table and the choice
# --------------------------------------------------------------------------------------------

@lru_cache(maxsize=1)
def load_table(path: str | None = None) -> dict:
    with open(path or TABLE_PATH) as f:
        return json.load(f)


def prefilter_work(q: BakeQuality) -> float:
    """Texel-samples of the prefilter (its cost is about proportional to them)."""
    levels = q.prefiltered_levels
    work = 0.0
    for step in range(2 * levels - 1):
        size = (q.prefiltered_size if step % 2 == 0 else q.prefiltered_size // 2) >> (step // 2)
        work += 6 * size * size * q.prefilter_samples_at(step)
    return work


def predicted_seconds(table: dict, name: str, max_roughness: float, has_compact_source: bool) -> float:
    """The measured bake time of a candidate (the fastest of several runs; with a compact source
    the bake makes a second source cube), its prefilter scaled by the work left at
    ``max_roughness``."""
    t = table["bake_seconds"][name]["sun" if has_compact_source else "no_sun"]
    full = CANDIDATES[name]
    trimmed = replace(full, max_roughness=max_roughness)
    return t["other"] + t["prefilter"] * prefilter_work(trimmed) / prefilter_work(full)


def _band(points: list[float], lo: float, hi: float) -> list[int]:
    """Indices of the table's roughness points a range [lo, hi] needs: those inside it and the
    nearest on either side (a value between two points takes the worse of the two)."""
    idx = [i for i, p in enumerate(points) if lo <= p <= hi]
    below = [i for i, p in enumerate(points) if p <= lo]
    above = [i for i, p in enumerate(points) if p >= hi]
    if below:
        idx.append(below[-1])
    if above:
        idx.append(above[0])
    return sorted(set(idx))


def predicted_error(table: dict, name: str, needs: list[MaterialNeed], env: EnvironmentFeatures) -> tuple[float, str]:
    """The worst measured error of candidate ``name`` over the environments of env's class and
    the archetypes and roughness points the needs cover; and which environments those were."""
    rows = {e: row for e, row in table["environments"].items() if e not in EXCLUDED}
    same = [e for e, row in rows.items()
            if row["has_compact_source"] == env.has_compact_source and
            (row["sh9_residual"] <= SH9_SMOOTH_RESIDUAL) == env.smooth]
    if not same:   # a class the table has never seen: every measured environment
        same = list(rows)
    points = table["roughness"]
    worst = 0.0
    for need in needs:
        for arch in need.archetypes:
            for i in _band(points, need.roughness_min, need.roughness_max):
                for e in same:
                    measured = rows[e]["errors"][name][arch][i]
                    worst = max(worst, math.inf if measured is None else measured)
    return worst, ", ".join(sorted(same))


def choose_quality(needs: list[MaterialNeed], env: EnvironmentFeatures | None,
                   budget: float = DEFAULT_ERROR_BUDGET, table: dict | None = None,
                   off_reason: str = "") -> Choice:
    """The candidate of least predicted bake time whose predicted error is within ``budget``
    (a fraction); if none is, the one of least predicted error. ``env`` None: the environment
    is off, nothing is baked (``off_reason`` says why)."""
    if env is None:
        return Choice(None, "none", 0.0, 0.0, True,
                      "the environment is off" + (f" ({off_reason})" if off_reason else ""))
    table = table or load_table()
    max_r = max([n.roughness_max for n in needs] or [1.0])
    max_r = min(1.0, max_r)
    scored = []
    for name in CANDIDATES:
        err, envs = predicted_error(table, name, needs, env)
        secs = predicted_seconds(table, name, max_r, env.has_compact_source)
        scored.append((err, secs, name, envs))
    fitting = [s for s in scored if s[0] <= budget]
    meets = bool(fitting)
    err, secs, name, envs = min(fitting, key=lambda s: (s[1], s[0])) if fitting else min(scored)
    q = replace(CANDIDATES[name], max_roughness=max_r)
    kinds = sorted({a for n in needs for a in n.archetypes})
    lo = min([n.roughness_min for n in needs if n.archetypes] or [max_r])
    reason = (f"{'/'.join(kinds) or 'no'} materials at roughness {lo:.2f}-{max_r:.2f}; environment: "
              f"{env.describe()}; errors predicted from the table's runs on the environments with these "
              f"features ({envs}), not measured on this one")
    if not meets:
        reason += "; no candidate meets the budget, so the most accurate one"
    return Choice(q, name, err, secs, meets, reason)
