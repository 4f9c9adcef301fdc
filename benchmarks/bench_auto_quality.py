"""--quality auto against high at the same error budget: bake time and the error achieved.

For a few scenes (a rough-only material, a mirror, the environment off, ...) this prints what
`--quality auto` chooses, the median bake time of that choice and of `high` (interleaved runs,
warm process, LUTs cached; auto's time includes its environment analysis), the speed-up, and the
probe's implementation error of both against app/accuracy/converged.py's converged split sum, next to
the budget. Nothing is asserted: the figures go in the README.

    .venv/bin/python benchmarks/bench_auto_quality.py [--runs 3] [--budget 2]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-"))

from alight.accuracy.auto_quality import (
    choose_quality,
    environment_features,
    scene_needs,
)
from alight.accuracy.converged import downsample_equirect, split_sum_converged
from alight.core import shading
from alight.core.material import Material
from alight.core.scene import Scene
from alight.ibl.bake import QUALITY, bake_environment
from alight.ibl.environment import load_environment
from alight.render.renderer import ForwardRenderer

ENV = Path(__file__).resolve().parents[2] / "shared" / "data" / "env"
WIDTH = 48
SCENES = [
    # label, environment (None: off), material
    ("rough copper r=0.8, royal_esplanade", "royal_esplanade_1k.hdr", Material(base_color=(0.95, 0.64, 0.54), metallic=1.0, roughness=0.8)),
    ("rough dielectric r=0.7, venice_sunset", "venice_sunset_1k.hdr", Material(base_color=(0.8, 0.2, 0.2), roughness=0.7)),
    ("rough dielectric r=0.6, studio", "studio", Material(base_color=(0.8, 0.8, 0.8), roughness=0.6)),
    ("mirror (silver r=0), studio", "studio", Material(base_color=(0.95, 0.93, 0.88), metallic=1.0, roughness=0.0)),
    ("mirror (silver r=0), quarry_01", "quarry_01_1k.hdr", Material(base_color=(0.95, 0.93, 0.88), metallic=1.0, roughness=0.0)),
    ("gold r=0.3, royal_esplanade", "royal_esplanade_1k.hdr", Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=0.3)),
    ("environment off (--no-ibl)", None, Material(roughness=0.5)),
]


def probe_error(renderer, maps, env, m) -> float:
    n, inside = shading.probe_normals(WIDTH)
    rad = env.radiance
    # converged split sum; the map halved for r >= 0.25 (app/accuracy/converged.py: <= 6e-4 added)
    src = downsample_equirect(rad, 2) if m.roughness >= 0.25 and rad.shape[1] >= 1024 else rad
    want = split_sum_converged(src, n[inside], (0.0, 0.0, 1.0), m.base_color, m.metallic, m.roughness, m.specular_f0)
    got = renderer.render(Scene(material=m, view="probe", ibl_model="lecture"), maps, WIDTH, WIDTH, read_srgb=False).linear[..., :3][inside]
    return float(np.abs(got - want).sum() / np.abs(want).sum())


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--budget", type=float, default=2.0, help="percent (default 2)")
    args = p.parse_args()
    budget = args.budget / 100.0
    r = ForwardRenderer()
    for q in (QUALITY["medium"], QUALITY["high"]):
        r.luts.get(q.lut_size, q.lut_samples)
    rows = []
    for label, env_name, m in SCENES:
        env = None if env_name is None else load_environment(env_name if env_name == "studio" else str(ENV / env_name))
        scene = Scene(material=m, view="probe", ibl_enabled=env is not None)
        auto_t, high_t = [], []
        for _ in range(args.runs):
            start = time.perf_counter()
            features = None if env is None else environment_features(env.radiance)
            choice = choose_quality(scene_needs(scene), features, budget)
            maps = None if choice.quality is None else bake_environment(r.ctx, r.shaders, env, choice.quality, r.luts)
            auto_t.append(time.perf_counter() - start)
            if maps is not None:
                maps.release()
            if env is not None:
                start = time.perf_counter()
                bake_environment(r.ctx, r.shaders, env, QUALITY["high"], r.luts).release()
                high_t.append(time.perf_counter() - start)
        a = statistics.median(auto_t)
        h = statistics.median(high_t) if high_t else float("nan")
        if env is None:
            err_auto = err_high = 0.0
            note = "no bake either way when the environment is off; high's time is its bake of the studio"
            s = load_environment("studio")
            h = statistics.median([_time_bake(r, s, QUALITY["high"]) for _ in range(args.runs)])
        else:
            err_auto = probe_error(r, r.bake(env, choice.quality), env, m)
            err_high = probe_error(r, r.bake(env, QUALITY["high"]), env, m)
            note = ""
        rows.append((label, choice, a, h, err_auto, err_high, note))
        print(f"{label}: {choice.line(budget)}", file=sys.stderr)
        print(f"  auto {a * 1000:.0f} ms, high {h * 1000:.0f} ms, speed-up {h / a:.1f}x; error auto "
              f"{err_auto * 100:.2f}% (predicted {choice.predicted_error * 100:.2f}%), high {err_high * 100:.2f}%"
              + (f"; {note}" if note else ""), file=sys.stderr)
    print("\n| scene | auto's choice | auto bake (median) | high bake | speed-up | error auto (predicted) | error high |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for label, choice, a, h, ea, eh, _ in rows:
        name = choice.name if choice.quality is None else f"{choice.name}, max r {choice.quality.max_roughness:g}"
        speed = "no bake" if choice.quality is None else f"{h / a:.0f}x"
        print(f"| {label} | {name} | {a * 1000:.0f} ms | {h * 1000:.0f} ms | {speed} | "
              f"{ea * 100:.2f}% ({choice.predicted_error * 100:.2f}%) | {eh * 100:.2f}% |")
    return 0


def _time_bake(r, env, q) -> float:
    start = time.perf_counter()
    bake_environment(r.ctx, r.shaders, env, q, r.luts).release()
    return time.perf_counter() - start


if __name__ == "__main__":
    raise SystemExit(main())
