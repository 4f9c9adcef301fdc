"""Measure app/accuracy/auto_quality.py's table: every candidate bake on every shared environment (and the
built-in studio), the probe's implementation error against app/accuracy/converged.py's converged split
sum for two archetypes (grey dielectric, gold) at ROUGHNESS_POINTS, and each candidate's bake
time (the fastest of --runs fresh bakes, LUT cached, and their median) on a map with a compact source and one without.

    .venv/bin/python tools/measure_auto_quality.py            # writes app/accuracy/auto_quality_table.json

Takes a few minutes on 2 cores. The error is sum |render - converged| / sum |converged| over a
48x48 probe (tests/test_probe_accuracy.py's metric), per channel, and the worst channel is kept:
a material of another colour weights the channels differently, and its error cannot exceed the
worst channel's.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from alight.accuracy.auto_quality import (
    CANDIDATES,
    ROUGHNESS_POINTS,
    TABLE_PATH,
    environment_features,
)
from alight.accuracy.converged import (
    brdf_lut_converged,
    downsample_equirect,
    irradiance_converged,
    prefiltered_converged,
)
from alight.core import shading
from alight.core.material import Material
from alight.core.scene import Scene
from alight.exchange.output import atomic_path
from alight.ibl.bake import bake_environment
from alight.ibl.environment import load_environment
from alight.render.renderer import ForwardRenderer

SHARED_ENV = Path(__file__).resolve().parents[2] / "shared" / "data" / "env"
WIDTH = 48
ARCHETYPES = {
    "dielectric": Material(base_color=(0.8, 0.8, 0.8), metallic=0.0),
    "metal": Material(base_color=(1.0, 0.71, 0.29), metallic=1.0),
}


def environments(only: list[str] | None):
    names = sorted(p.name for p in SHARED_ENV.iterdir() if p.suffix in (".hdr", ".exr")) + ["studio"]
    for name in names:
        if only and name not in only:
            continue
        try:
            env = load_environment(name if name == "studio" else str(SHARED_ENV / name))
        except Exception as exc:  # e.g. memorial.exr, which is not 2:1
            print(f"skip {name}: {exc}", file=sys.stderr)
            continue
        yield name, env


def converged_parts(env, normals, luts):
    rad = env.radiance
    coarse = downsample_equirect(rad, 2) if rad.shape[0] % 2 == 0 and rad.shape[1] >= 1024 else rad
    irr = irradiance_converged(coarse, normals)
    reflected = shading.reflect(-np.array([0.0, 0.0, 1.0]), normals)
    # Below r = 0.25 the lobe spans few texels: the full-resolution map (see app/accuracy/converged.py).
    pre = {r: prefiltered_converged(rad if r < 0.25 else coarse, reflected, r) for r in ROUGHNESS_POINTS}
    return irr, pre


def ideal(m: Material, r: float, normals, irr, pre, luts):
    n_dot_v = np.maximum(normals[:, 2], 0.0)
    f0 = shading.f0_of(m.base_color, m.metallic, m.specular_f0)
    F = shading.F_SchlickRoughness(n_dot_v, f0, r)
    kd = (1 - F) * (1 - m.metallic)
    a, b = luts[r]
    return kd * np.array(m.base_color) * irr + pre[r] * (F * a[:, None] + b[:, None])


def timed_bakes(renderer, env, runs):
    out = {}
    for name, q in CANDIDATES.items():
        totals, prefilters = [], []
        for _ in range(runs):
            start = time.perf_counter()
            maps = bake_environment(renderer.ctx, renderer.shaders, env, q, renderer.luts)
            totals.append(time.perf_counter() - start)
            prefilters.append(maps.pass_seconds["prefilter"])
            maps.release()
        # The fastest run is the one least disturbed by other jobs on a shared machine: the cost
        # model uses it; the median is kept beside it.
        best = int(np.argmin(totals))
        total, pre = totals[best], prefilters[best]
        out[name] = {"total": round(total, 4), "prefilter": round(pre, 4), "other": round(total - pre, 4),
                     "median_total": round(statistics.median(totals), 4), "runs": runs}
        print(f"  bake {name}: fastest {total * 1000:.0f} ms (prefilter {pre * 1000:.0f} ms), median "
              f"{statistics.median(totals) * 1000:.0f} ms", file=sys.stderr)
    return out


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default=str(TABLE_PATH))
    p.add_argument("--runs", type=int, default=5, help="timed bakes per candidate (the fastest is kept)")
    p.add_argument("--only", nargs="*", help="environment file names (default: all, and studio)")
    p.add_argument("--errors-only", action="store_true", help="keep the bake times of --out, measure the errors")
    p.add_argument("--timings-only", action="store_true",
                   help="keep the errors of --out and measure the bake times again (on a quiet machine)")
    args = p.parse_args()

    renderer = ForwardRenderer()
    n, inside = shading.probe_normals(WIDTH)
    normals = n[inside]
    n_dot_v = np.maximum(normals[:, 2], 0.0)
    luts = {r: brdf_lut_converged(n_dot_v, np.full_like(n_dot_v, r)) for r in ROUGHNESS_POINTS}
    # Warm the LUT caches so the timings are of warm bakes.
    for q in {(q.lut_size, q.lut_samples) for q in CANDIDATES.values()}:
        renderer.luts.get(*q)

    table = {"about": "app/accuracy/auto_quality.py's measured table; written by tools/measure_auto_quality.py",
             "metric": f"max over RGB of sum|probe - converged| / sum|converged|, {WIDTH}x{WIDTH} probe, "
                       "lecture IBL model",
             "machine": f"{platform.machine()} {platform.node()}, {renderer.ctx.info['GL_RENDERER']}",
             "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
             "roughness": list(ROUGHNESS_POINTS), "archetypes": {k: str(v) for k, v in ARCHETYPES.items()},
             "environments": {}, "bake_seconds": {}}
    timing_envs = {}
    if args.timings_only:
        old = json.loads(Path(args.out).read_text())
        table["environments"] = old["environments"]
        for kind, name in old["timing_environments"].items():
            timing_envs[kind] = load_environment(name if name == "studio" else str(SHARED_ENV / name))
    for name, env in ([] if args.timings_only else environments(args.only)):
        t0 = time.perf_counter()
        features = environment_features(env.radiance)
        irr, pre = converged_parts(env, normals, luts)
        errors = {}
        for cname, q in CANDIDATES.items():
            maps = bake_environment(renderer.ctx, renderer.shaders, env, q, renderer.luts)
            errors[cname] = {}
            for arch, base in ARCHETYPES.items():
                row = []
                for r in ROUGHNESS_POINTS:
                    m = replace(base, roughness=r)
                    got = renderer.render(Scene(material=m, view="probe", ibl_model="lecture"), maps, WIDTH, WIDTH,
                                          read_srgb=False).linear[..., :3][inside]
                    want = ideal(m, r, normals, irr, pre, luts)
                    # The worst channel: a material of any colour mixes the channels' errors with
                    # its own weights, so its error is at most the worst channel's.
                    denom = np.abs(want).sum(axis=0)
                    err = float((np.abs(got - want).sum(axis=0) / denom).max()) if (denom > 0).all() else float("inf")
                    row.append(round(err, 5) if np.isfinite(err) else None)   # None: no signal to compare
                errors[cname][arch] = row
            maps.release()
        table["environments"][name] = {"has_compact_source": features.has_compact_source,
                                       "sh9_residual": round(features.sh9_residual, 5), "errors": errors}
        timing_envs.setdefault("sun" if features.has_compact_source else "no_sun", env)
        print(f"{name}: {features.describe()}; {time.perf_counter() - t0:.0f} s", file=sys.stderr)
        for cname in CANDIDATES:
            print(f"  {cname:11s} " + "  ".join(
                f"{a[:4]} " + "/".join("-" if e is None else f"{e * 100:.1f}" for e in errors[cname][a]) for a in ARCHETYPES), file=sys.stderr)
    if args.errors_only:
        old = json.loads(Path(args.out).read_text())
        table["bake_seconds"], table["timing_environments"] = old["bake_seconds"], old["timing_environments"]
        timing_envs = {}
    for kind, env in timing_envs.items():
        print(f"timing on {env.name} ({kind})", file=sys.stderr)
        for cname, t in timed_bakes(renderer, env, args.runs).items():
            table["bake_seconds"].setdefault(cname, {})[kind] = t
    for cname in CANDIDATES:   # a class not timed borrows the other's figures
        row = table["bake_seconds"].setdefault(cname, {})
        for kind in ("sun", "no_sun"):
            row.setdefault(kind, row.get("no_sun" if kind == "sun" else "sun"))
    if not args.errors_only:
        table["timing_environments"] = {k: Path(env.name).name for k, env in timing_envs.items()}
    with atomic_path(args.out) as tmp:
        Path(tmp).write_text(json.dumps(table, indent=1) + "\n")
    print(args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
