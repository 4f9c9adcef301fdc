"""How far the specular lookup should lean from R toward n: the `dominant` / `stretched` models'
lookup direction moved part of the way back toward R, on flat faces and the sphere, every map,
against the exact texel sum. Numpy twins only (no GL); prints and writes a table, asserts nothing.

    .venv/bin/python benchmarks/bench_dominant_shift.py                 # every 2:1 map (~10 min on 2 cores)
    .venv/bin/python benchmarks/bench_dominant_shift.py --only piz,royal

The models fetch the prefiltered map at d(t) = normalize(mix(n, R, t)) with t the lobe's mean
direction (brdf_lut.comp's t_A / t_B, mixed by the material's weights). Here the shift from R is
scaled by s: t_s = 1 - s (1 - t); s = 1 is today's model, s = 0 fetches at R (Karis' split). For
`stretched` (above r 0.3 its two fitted fetches blended in, app/core/stretched_lobe.py) the whole
fitted pair moves with d; `pair-fixed` is `stretched` with only its single fetch moved (to
normalize(mix(R, mean, s))) and the pair left about the mean it was fitted to. Points: a flat face (n = +Y) seen from elevations 10/30/60 degrees
(+-6 degrees, +-15 degrees of azimuth, as the built-in plane fills a 35-degree view), and the probe's
normals at 12 x 12 pixel centres (112) of the sphere seen from 0 and 30 degrees. Gold (metal: specular only), compact sources
taken out as the `alight` model does (they are shaded exactly in both). The map is reduced 4x
(area-weighted) for time; relMAE over the points, specular of the converged bake against the exact
sum. Results: results/dominant_shift.md (the reading: results/oblique_ibl.md, "Why the default loses
on flat faces").
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"

from alight.accuracy.chart import default_env_dir, equirect_envs  # noqa: E402
from alight.accuracy.converged import (brdf_lut_converged, downsample_equirect, lobe_directions_converged,  # noqa: E402
                                       prefiltered_converged, prefiltered_converged_each)
from alight.accuracy.ground_truth import ground_truth_terms  # noqa: E402
from alight.core.stretched_lobe import blend_weight, stretched_fetches  # noqa: E402
from alight.ibl.environment import load_environment  # noqa: E402
from alight.ibl.sun import extract_suns  # noqa: E402

GOLD_F0 = np.array([1.0, 0.766, 0.336])
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
SCALES = (1.0, 0.75, 0.5, 0.0)
# single: one round fetch at d; stretched: the default model with its fetches all moved with d;
# pair-fixed: the default model with only its single fetch moved (the fitted pair about the mean)
MODELS = (("single", (0.3, 0.4)), ("stretched", (0.4, 0.5, 0.7)), ("pair-fixed", (0.3, 0.4)))


def unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def point_sets():
    """(name, normals, views) for the plane at 10/30/60 degrees and the sphere at 0/30."""
    sets = []
    for elev in (10, 30, 60):
        e, z = np.meshgrid(np.radians(elev + np.linspace(-6, 6, 5)), np.radians(np.linspace(-15, 15, 4)))
        e, z = e.ravel(), z.ravel()
        v = np.stack([np.cos(e) * np.sin(z), np.sin(e), np.cos(e) * np.cos(z)], -1)
        sets.append((f"plane {elev}", np.broadcast_to([0.0, 1.0, 0.0], v.shape).copy(), v))
    # the probe view's pixel centres (docs/conventions.md) of a 12 x 12 image, inside the disk
    c = 2 * (np.arange(12) + 0.5) / 12 - 1
    xy = np.stack(np.meshgrid(c, c), -1).reshape(-1, 2)
    xy = xy[np.sum(xy ** 2, -1) < 1.0]
    n = np.concatenate([xy, np.sqrt(1 - np.sum(xy ** 2, -1))[:, None]], -1)
    for elev in (0, 30):
        c, s = np.cos(np.radians(elev)), np.sin(np.radians(elev))
        rot = np.array([[1, 0, 0], [0, c, s], [0, -s, c]])
        sets.append((f"sphere {elev}", n @ rot.T, np.broadcast_to(np.array([0, 0, 1.0]) @ rot.T, n.shape).copy()))
    return sets


def errors(radiance, n, v, roughness, model):
    """relMAE of the specular at each scale in SCALES, and of the fetch at R (Karis)."""
    nv = np.sum(n * v, -1)
    R = 2 * nv[:, None] * n - v
    A, B = brdf_lut_converged(nv, roughness)
    t_a, t_b = lobe_directions_converged(nv, roughness)
    weight_a = float(GOLD_F0 @ LUMINANCE) * A
    t = (weight_a * t_a + B * t_b) / np.maximum(weight_a + B, 1e-6)
    weight = GOLD_F0[None] * A[:, None] + B[:, None]
    exact = ground_truth_terms(radiance, n, v, roughness).combine(GOLD_F0, 1.0, (0.04,) * 3, parts=True)[1]

    def rel(pre):
        return float(np.mean(np.abs(weight * pre - exact)) / np.mean(exact))

    out = [rel(prefiltered_converged(radiance, R, roughness))]
    share = float(blend_weight(roughness)) if model == "stretched" else 0.0
    d_mean = unit(n + t[:, None] * (R - n))
    for s in SCALES:
        if model == "pair-fixed":
            # a candidate (not in the shader): only the single fetch moves, along the chord
            # from R to the lobe mean; the fitted pair stays about the mean it was fitted to
            d = unit(R + s * (d_mean - R))
            share = float(blend_weight(roughness))
        else:
            d = unit(n + (1.0 - s * (1.0 - t))[:, None] * (R - n))
        pre = prefiltered_converged(radiance, d, roughness)
        if share > 0.0:
            d_lo, d_hi, w_hi, fetch_r = stretched_fetches(n, v, d_mean if model == "pair-fixed" else d,
                                                          GOLD_F0, A, B, roughness)
            two = ((1 - w_hi)[:, None] * prefiltered_converged_each(radiance, d_lo, fetch_r)
                   + w_hi[:, None] * prefiltered_converged_each(radiance, d_hi, fetch_r))
            pre = (1 - share) * pre + share * two
        out.append(rel(pre))
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", metavar="A,B", help="only the maps whose names contain one of these")
    ap.add_argument("--models", help="only these of single,stretched,pair-fixed (comma-separated)")
    ap.add_argument("--out", type=Path, default=RESULTS / "dominant_shift.md")
    args = ap.parse_args()
    env_dir = default_env_dir()
    if env_dir is None:
        print("no ../shared/data/env", file=sys.stderr)
        return 1
    envs, _ = equirect_envs(env_dir)
    if args.only:
        envs = [e for e in envs if any(k in Path(e).name for k in args.only.split(","))]
    global MODELS
    if args.models:
        MODELS = tuple(m for m in MODELS if m[0] in args.models.split(","))
    header = ["environment", "points", "model", "r", "R (karis)", *[f"s {s:g}" for s in SCALES]]
    rows = []
    for env_path in envs:
        radiance, _ = extract_suns(np.asarray(load_environment(env_path).radiance, np.float32))
        radiance = downsample_equirect(radiance, 4)
        if not np.any(radiance > 0):   # all of it compact sources (spot1Lux): shaded exactly, nothing to fetch
            print(f"{Path(env_path).stem}: no light left after the compact sources", flush=True)
            continue
        for name, n, v in point_sets():
            for model, rough in MODELS:
                for r in rough:
                    e = errors(radiance, n, v, r, model)
                    row = [Path(env_path).stem, name, model, f"{r:g}", *[f"{100 * x:.1f}" for x in e]]
                    rows.append(row)
                    print(" | ".join(row), flush=True)
    notes = ["relMAE % of the specular (gold) against the exact texel sum; `single`: one round fetch at d "
             "(the `dominant`/`alight` lookup, and `stretched` at r 0.3); `stretched`: the default model "
             "(at r 0.4 half single, half the fitted pair), all its fetches moved; `pair-fixed`: only its "
             "single fetch moved, to normalize(mix(R, mean, s)). s: the share of the lobe-mean shift from R kept "
             "(1 today, 0 at R). `benchmarks/bench_dominant_shift.py`, 4x-reduced maps, compact sources out."]
    lines = ["# The lookup direction's shift from R toward n, scaled", "", *notes, "",
             "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    args.out.write_text("\n".join(lines) + "\n")
    print(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
