"""The chart's layer rows (``alight chart``'s ``layer ...`` settings, app/accuracy/chart.py) beside
its baseline, run on their own: for each material layer, the presets that use it against the
layer's exact answer (``alight reference``), relMAE and FLIP over the probe cases, the layer's
white furnace and the material ball's frame time (1280x720, median of 7, round-robin with the
baseline's default material in the same run). Writes results/chart_layers/ (the chart's CSVs
and PNGs) and prints the table. Not a test.

    python benchmarks/bench_chart_layers.py                  # royal_esplanade, venice_sunset, quarry_01
    python benchmarks/bench_chart_layers.py --env A --env B  # other maps
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.bench_render import RESULTS  # noqa: E402

ENV_DIR = REPO.parent / "shared" / "data" / "env"
DEFAULT_ENVS = ("royal_esplanade_1k.hdr", "venice_sunset_1k.hdr", "quarry_01_1k.hdr")


def main() -> int:
    from alight.accuracy.chart import ChartConfig, layer_row, run_chart, sweep
    from alight.exchange.presets import list_presets, load_preset

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--env", action="append", help="an environment (repeatable)")
    ap.add_argument("--out", default=str(RESULTS / "chart_layers"))
    args = ap.parse_args()
    envs = args.env or [str(ENV_DIR / name) for name in DEFAULT_ENVS]
    settings = [s for s in sweep() if s.factor in ("baseline", "layer")]
    presets = [p for p in list_presets() if layer_row(load_preset(p))] + ["gold", "plastic_high"]
    config = ChartConfig(envs=envs, presets=presets, settings=settings, visibility=None)   # the layers only
    start = time.perf_counter()
    results = run_chart(config, args.out)
    print(f"{len(results)} settings x {len(envs)} environment(s) ({', '.join(Path(e).stem for e in envs)}), "
          f"presets {', '.join(presets)}, in {time.perf_counter() - start:.0f} s")
    base_frame = results[0].frame_seconds
    print(f"{'setting':30s} {'presets':34s} {'cases':>5s} {'relMAE %':>9s} {'max %':>7s} {'FLIP':>6s} "
          f"{'frame ms':>9s} {'x base':>6s} {'furnace r=0':>11s} {'r=1':>6s}")
    for res in results:
        names = sorted({c[1] for c in res.cases})
        f0 = [f[3] for f in res.furnace if f[0] == 0.0]
        f1 = [f[3] for f in res.furnace if f[0] == 1.0]
        print(f"{res.setting.name:30s} {','.join(names)[:34]:34s} {len(res.cases):5d} {res.rel_mean * 100:9.2f} "
              f"{res.rel_max * 100:7.1f} {res.flip_mean:6.3f} {res.frame_seconds * 1000:9.1f} "
              f"{res.frame_seconds / base_frame:6.2f} {f0[0]:11.3f} {f1[0]:6.3f}")
    print("(furnace columns: the probe's max under radiance 1; relMAE/FLIP: mean over the cases, spot1Lux excluded)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
