"""The `stretched` IBL model against the lecture's with its blend range and lobe table overridable:
the probe's gold (the issue's goal table, `bench_ibl_models.py`'s errors) and the 270 oblique rows
(`bench_scene_reference.py --part oblique`, 32 px), only these two models, so that a candidate is
measured against today's in minutes. Prints and writes a CSV; asserts nothing.

    .venv/bin/python benchmarks/bench_stretched_pair.py probe results/x_probe.csv
    .venv/bin/python benchmarks/bench_stretched_pair.py oblique results/x_oblique.csv [--only royal,piz]
    .venv/bin/python benchmarks/bench_stretched_pair.py oblique out.csv --start 0.3 --full 0.5   # main's blend before 2026-12-07
    .venv/bin/python benchmarks/bench_stretched_pair.py oblique out.csv --table other_lobe.json

--start/--full replace app/core/stretched_lobe.py's ROUGHNESS_START/_FULL (read by
app/render/variants.py at each render), --table its lobe table (read once, at the first render).
The exact references (`alight reference --integrator exact` for the oblique rows, the texel sum over
the map reduced by 2 for the probe) take most of the time and do not depend on either, so they are
kept in --cache (default: a folder under the system's temp) and reused by the next run. Results:
results/stretched_pair_from_r02.md.
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))

from bench_scene_reference import camera_for, materials  # noqa: E402

import alight.core.stretched_lobe as stretched_lobe  # noqa: E402
from alight.accuracy.binned import binned_relative_mae  # noqa: E402
from alight.accuracy.chart import default_env_dir, equirect_envs  # noqa: E402
from alight.accuracy.converged import downsample_equirect  # noqa: E402
from alight.accuracy.ground_truth import ground_truth_terms, probe_points  # noqa: E402
from alight.accuracy.reference import ReferenceRenderer  # noqa: E402
from alight.core.scene import Scene  # noqa: E402
from alight.exchange.meshes import load_mesh  # noqa: E402
from alight.exchange.presets import load_preset  # noqa: E402
from alight.ibl.bake import quality_named  # noqa: E402
from alight.ibl.environment import load_environment  # noqa: E402
from alight.render.renderer import ForwardRenderer  # noqa: E402

MODELS = ("lecture", "stretched")
OBLIQUE_MATERIALS = ("gold r0.3", "gold r0.4", "gold r0.5", "gold r0.7", "red dielectric r0.5")
PROBE_ROUGHNESS = (0.3, 0.4, 0.5, 0.7, 1.0)


def oblique_rows(renderer, exact, env, name, maps, cache: Path, only_materials):
    mats, size = materials(), (32, 32)
    for mesh_name, elevations in (("plane", (10.0, 30.0, 60.0)), ("sphere", (0.0, 30.0, 60.0))):
        mesh = load_mesh(mesh_name)
        for elevation in elevations:
            camera = camera_for(mesh, size, 0.0, elevation)
            for mat_name in [m for m in OBLIQUE_MATERIALS if not only_materials or m in only_materials]:
                scene = Scene(mesh=mesh, material=mats[mat_name], camera=camera, view="camera")
                path = cache / f"oblique_{name}_{mesh_name}_{elevation:g}_{mat_name.replace(' ', '_')}.npy"
                if path.exists():
                    reference = np.load(path)
                else:
                    reference = exact.render(scene, env.radiance, *size).linear
                    np.save(path, reference)
                errors = [binned_relative_mae(renderer.render(replace(scene, ibl_model=m), maps, *size, aa="none",
                                                              read_linear=True, read_srgb=False).linear, reference, 1)
                          for m in MODELS]
                yield [mesh_name, f"{elevation:g}", name, mat_name, *[f"{100 * e:.2f}" for e in errors]]


def probe_rows(renderer, env, name, maps, cache: Path):
    points, inside = probe_points(32)
    gold = load_preset("gold")
    path = cache / f"probe_{name}.npz"
    if path.exists():
        stored = np.load(path)
        truths = {r: stored[f"r{r}"] for r in PROBE_ROUGHNESS}
    else:
        terms = ground_truth_terms(downsample_equirect(env.radiance, 2), points, (0.0, 0.0, 1.0), PROBE_ROUGHNESS)
        truths = {}
        for r in PROBE_ROUGHNESS:
            m = replace(gold, roughness=r)
            truths[r] = terms.combine(m.base_color, m.metallic, m.specular_f0, m.emissive, roughness=r)
        np.savez(path, **{f"r{r}": t for r, t in truths.items()})
    for r in PROBE_ROUGHNESS:
        m = replace(gold, roughness=r)
        den = float(np.abs(truths[r]).sum())
        errors = []
        for model in MODELS:
            got = renderer.render(Scene(material=m, view="probe", ibl_model=model), maps, 32, 32,
                                  read_srgb=False).linear[..., :3][inside]
            errors.append(float(np.abs(got - truths[r]).sum()) / den)
        yield ["probe", f"{r:g}", name, "gold", *[f"{100 * e:.2f}" for e in errors]]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("part", choices=("probe", "oblique"))
    ap.add_argument("out", type=Path, help="the CSV to write (relMAE %% per row: lecture, stretched)")
    ap.add_argument("--start", type=float, help="ROUGHNESS_START (the single fetch below it)")
    ap.add_argument("--full", type=float, help="ROUGHNESS_FULL (the two fetches only above it)")
    ap.add_argument("--table", type=Path, help="a lobe table in app/core/stretched_lobe.json's form")
    ap.add_argument("--only", metavar="A,B", help="only the maps whose names contain one of these")
    ap.add_argument("--materials", metavar="A,B", help="oblique: only these of " + ", ".join(OBLIQUE_MATERIALS))
    ap.add_argument("--cache", type=Path, default=Path(tempfile.gettempdir()) / "alight-stretched-pair-refs")
    args = ap.parse_args()
    if (args.start is None) != (args.full is None):
        ap.error("--start and --full go together")
    if args.start is not None:
        stretched_lobe.ROUGHNESS_START, stretched_lobe.ROUGHNESS_FULL = args.start, args.full
    if args.table is not None:
        stretched_lobe.TABLE_PATH = args.table
        stretched_lobe.lobe_table.cache_clear()
    env_dir = default_env_dir()
    if env_dir is None:
        print("no ../shared/data/env", file=sys.stderr)
        return 1
    envs, _ = equirect_envs(env_dir)
    if args.only:
        envs = [e for e in envs if any(k in Path(e).name for k in args.only.split(","))]
    args.cache.mkdir(parents=True, exist_ok=True)
    only_materials = set(args.materials.split(",")) if args.materials else None
    renderer = ForwardRenderer()
    exact = ReferenceRenderer(renderer)
    rows, start = [], time.perf_counter()
    for env_path in envs:
        env, name = load_environment(env_path), Path(env_path).stem
        maps = renderer.bake(env, quality_named("medium"))
        found = (oblique_rows(renderer, exact, env, name, maps, args.cache, only_materials) if args.part == "oblique"
                 else probe_rows(renderer, env, name, maps, args.cache))
        for row in found:
            rows.append(row)
            print(" | ".join(row), flush=True)
        maps.release()
        with open(args.out, "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(["mesh", "elevation", "environment", "material", *MODELS])
            writer.writerows(rows)
    print(f"{args.out}: {len(rows)} rows in {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
