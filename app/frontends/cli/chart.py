"""``alight chart``: the IBL settings swept against the ground truth (app/accuracy/chart.py)."""

from __future__ import annotations

import math
import sys
import time

from alight.errors import AlightError
from alight.frontends.cli.arguments import Command


def add_parser(sub) -> None:
    ch = sub.add_parser("chart", help="sweep the IBL settings: bake time, frame time, error against the ground truth",
                        description="Measure, one factor at a time around the medium quality, every IBL setting "
                                    "(irradiance method and size, specular cube size, sample counts, filtered "
                                    "importance sampling, LUT size and samples, every IBL model, multiple "
                                    "scattering judged by the white furnace) against the GPU ground truth on the "
                                    "presets x roughness x environments; and the visibility features (occlusion, "
                                    "shadows) on test scenes against the path tracer. Writes CSVs and PNG charts "
                                    "(app/accuracy/chart.py, app/accuracy/chart_visibility.py).")
    ch.add_argument("--quick", action="store_true",
                    help="a small sweep: royal_esplanade only, 3 presets, 3 roughness values, a few settings")
    ch.add_argument("--env", action="append", metavar="MAP",
                    help="an environment (repeatable; default: every 2:1 map in ../shared/data/env, else studio)")
    ch.add_argument("--presets", metavar="A,B,...", help="presets to measure (default: all; --quick: gold, "
                                                          "plastic_high and one preset per layer)")
    ch.add_argument("--size", type=int, default=32, metavar="N", help="probe size for the errors (default: 32)")
    ch.add_argument("--visibility", metavar="A,B,...|none",
                    help="scenes of the visibility rows (corner, bowl, product: each with occlusion and shadows "
                         "off / on / auto against the path tracer; default: all three; --quick: bowl; none: no rows)")
    ch.add_argument("--out", default="alight-chart", metavar="DIR", help="output folder (default: alight-chart)")


def run(args) -> int:
    from pathlib import Path

    from alight.accuracy.chart import (
        QUICK_PRESETS,
        QUICK_ROUGHNESS,
        ChartConfig,
        default_env_dir,
        equirect_envs,
        run_chart,
        sweep,
        why_missing,
    )
    from alight.accuracy.chart_visibility import QUICK_VISIBILITY_SCENES, VISIBILITY_SCENES, VisibilitySettings
    from alight.exchange.presets import list_presets

    if args.size < 8 or args.size > 256:
        raise AlightError(f"--size: {args.size} must be from 8 to 256")
    if args.env:
        envs = list(args.env)
    else:
        env_dir = default_env_dir()
        if env_dir is None:
            envs = ["studio"]
        else:
            envs, skipped = equirect_envs(env_dir)
            for line in [] if args.quick else skipped:
                print(f"alight chart: skipped {line}", file=sys.stderr)
            if args.quick:
                pick = [e for e in envs if "royal_esplanade" in e]
                envs = pick or envs[:1] or ["studio"]
    presets = list(QUICK_PRESETS) if args.quick else list_presets()
    if args.presets:
        presets = [p.strip() for p in args.presets.split(",") if p.strip()]
    scenes = QUICK_VISIBILITY_SCENES if args.quick else VISIBILITY_SCENES
    if args.visibility:
        scenes = tuple(s.strip() for s in args.visibility.split(",") if s.strip() and s.strip() != "none")
        unknown = [s for s in scenes if s not in VISIBILITY_SCENES]
        if unknown:
            raise AlightError(f"--visibility: unknown scene '{unknown[0]}' (one of {', '.join(VISIBILITY_SCENES)}, none)")
    config = ChartConfig(envs=envs, presets=presets, size=args.size,
                         roughness=QUICK_ROUGHNESS if args.quick else ChartConfig.__dataclass_fields__["roughness"].default,
                         frame_size=(320, 180) if args.quick else (1280, 720),
                         frame_repeats=3 if args.quick else 7, settings=sweep(args.quick),
                         visibility=VisibilitySettings(scenes=scenes) if scenes else None)
    start = time.perf_counter()
    results = run_chart(config, args.out)
    out = Path(args.out)
    print(f"{len(results)} settings x {len(envs)} environment(s) in {time.perf_counter() - start:.0f} s")
    print(f"{'setting':34s} {'bake ms':>8s} {'frame ms':>9s} {'relMAE %':>9s} {'max %':>7s} {'FLIP':>6s} "
          f"{'furnace r=1':>11s}")
    notes = Notes()
    for res in results:
        fr = [f[1] for f in res.furnace if f[0] == 1.0]

        def cell(value, spec, column, res=res):
            return notes.cell(value, spec, lambda: why_missing(res, column))

        print(f"{res.setting.name:34s} {cell(res.bake_median * 1000, '8.0f', 'bake')} "
              f"{cell(res.frame_seconds * 1000, '9.1f', 'frame')} {cell(res.rel_mean * 100, '9.2f', 'rel')} "
              f"{cell(res.rel_max * 100, '7.1f', 'rel')} {cell(res.flip_mean, '6.3f', 'flip')} "
              f"{cell(fr[0] if fr else math.nan, '11.3f', 'furnace')}")
    notes.print()
    _print_visibility(out / "chart.csv", notes)
    for name in ("chart.csv", "chart_cases.csv", "furnace.csv", "error_map.csv", "chart.png", "error_map.png"):
        if (out / name).exists():
            print(out / name)
    return 0


def _print_visibility(csv_path, notes: "Notes") -> None:
    """The visibility rows of the chart just written (chart.csv: factor 'visibility')."""
    from alight.accuracy.chart import read_summary

    rows = [r for r in read_summary(csv_path) if r["factor"] == "visibility"]
    if not rows:
        return
    print(f"{'visibility row':34s} {'bake ms':>8s} {'frame ms':>9s} {'relMAE %':>9s} {'max %':>7s} {'noise %':>8s} "
          f"drawn")
    printed = len(notes.reasons)
    for r in rows:
        def cell(value, spec, why="not measured"):
            return notes.cell(value, spec, lambda: why)

        bake_why = "no visibility bake: occlusion is off in this configuration" if r["occlusion"] == "off" \
            else "not measured"
        print(f"{r['setting']:34s} {cell(r['visibility_bake_ms'], '8.0f', bake_why)} {cell(r['frame_ms'], '9.1f')} "
              f"{cell(r['rel_mae_mean'] * 100, '9.2f')} {cell(r['rel_mae_max'] * 100, '7.1f')} "
              f"{cell(r['ref_noise_mean'] * 100, '8.2f')} occlusion {r['occlusion']}, shadows {r['shadows']}")
    notes.print(printed)


class Notes:
    """The tables' missing values: 'n/a(k)' in the cell, and footnote k saying why, once per
    reason (a NaN is never printed unexplained)."""

    def __init__(self):
        self.reasons: list[str] = []

    def cell(self, value, spec: str, why) -> str:
        """``value`` formatted by ``spec`` (e.g. '9.2f'), or 'n/a(k)' as wide, k the footnote of
        ``why()``."""
        if isinstance(value, (int, float)) and math.isfinite(value):
            return format(value, spec)
        reason = why()
        if reason not in self.reasons:
            self.reasons.append(reason)
        return f"n/a({self.reasons.index(reason) + 1})".rjust(int(spec.split(".")[0]))

    def print(self, start: int = 0) -> None:
        """The footnotes from number ``start`` + 1 on (those under an earlier table printed)."""
        for k, reason in enumerate(self.reasons[start:], start + 1):
            print(f"  n/a({k}): {reason}")


COMMAND = Command("chart", add_parser, run)
