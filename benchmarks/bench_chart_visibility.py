"""The chart's visibility rows (``alight chart``'s ``visibility ...`` rows,
app/accuracy/chart_visibility.py) run on their own beside the baseline IBL setting: the corner,
the bowl and the product with occlusion and shadows off / on / auto, each against the path
tracer under every 2:1 map of ../shared/data/env; the scene camera's steady frame at 1280x720
under the first map with a sun (median of 5, ChartConfig's default, round-robin); the uncached
visibility bake. The full `alight chart` measures the same rows after its ~40 IBL settings (its
ETA was 40+ minutes on the loaded 2-core machine); this keeps only its baseline, one preset and
one roughness so the rows can be rerun in minutes. Writes results/chart_visibility/ (the chart's
CSVs and PNGs) and prints the rows. Not a test.

    python benchmarks/bench_chart_visibility.py                  # every 2:1 map
    python benchmarks/bench_chart_visibility.py --env A --env B  # other maps
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.bench_render import RESULTS  # noqa: E402


def main() -> int:
    from alight.accuracy.chart import ChartConfig, default_env_dir, equirect_envs, read_summary, run_chart, sweep
    from alight.accuracy.chart_visibility import VISIBILITY_SCENES, VisibilitySettings

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--env", action="append", help="an environment (repeatable)")
    ap.add_argument("--scenes", default=",".join(VISIBILITY_SCENES))
    ap.add_argument("--out", default=str(RESULTS / "chart_visibility"))
    args = ap.parse_args()
    envs = args.env or equirect_envs(default_env_dir())[0]
    config = ChartConfig(envs=envs, presets=["gold"], roughness=(0.5,), settings=sweep()[:1],
                         visibility=VisibilitySettings(scenes=tuple(s for s in args.scenes.split(",") if s)))
    start = time.perf_counter()
    run_chart(config, args.out)
    print(f"{len(envs)} environment(s) ({', '.join(Path(e).stem for e in envs)}) in "
          f"{time.perf_counter() - start:.0f} s")
    print(f"{'row':30s} {'drawn':24s} {'bake ms':>8s} {'frame ms':>9s} {'relMAE %':>9s} {'max %':>7s} {'noise %':>8s}")
    for r in read_summary(Path(args.out) / "chart.csv"):
        if r["factor"] != "visibility":
            continue
        drawn = f"occl {r['occlusion']}, shadows {r['shadows']}"
        print(f"{r['setting']:30s} {drawn:24s} {r['visibility_bake_ms']:8.0f} {r['frame_ms']:9.1f} "
              f"{r['rel_mae_mean'] * 100:9.2f} {r['rel_mae_max'] * 100:7.1f} {r['ref_noise_mean'] * 100:8.2f}")
    print("(relMAE, noise: mean over the maps, spot1Lux excluded; per map in chart_cases.csv)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
