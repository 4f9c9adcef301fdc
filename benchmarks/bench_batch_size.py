"""Batch size: one `alight batch` of N stills against N separate `alight render` processes of the
same stills (figures, not a test).

    .venv/bin/python benchmarks/bench_batch_size.py [--sizes 1,4,16,48] [--separate-max 16] [--rounds 2]

Each still is a preset ball (gold, copper, water, iron in turn) at an orbit of 15-degree steps,
128 px, `quality = "low"`, the shared venice_sunset map, no contact sheet; one local worker, so
both sides use one process at a time. Every run writes into a fresh folder with an empty
ALIGHT_CACHE_DIR of its own (the batch pays its bake once, each separate render its own, as a
script looping over `alight render` on a new machine would). The two sides alternate per size
(batch, separate, batch, separate ...). Printed per run: wall seconds, the children's CPU
seconds (user + system, steadier on a shared machine) and both per still; then per size the
median ratio separate / batch of the CPU time.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ENV = REPO.parent / "shared" / "data" / "env" / "venice_sunset_1k.hdr"
MATERIALS = ("gold", "copper", "water", "iron")
ALIGHT = [sys.executable, "-m", "alight"]


def stills(n: int) -> list[tuple[str, int]]:
    return [(MATERIALS[i % len(MATERIALS)], 15 * (i // len(MATERIALS))) for i in range(n)]


def _timed(commands: list[list[str]], env: dict) -> tuple[float, float]:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    for cmd in commands:
        out = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if out.returncode != 0:
            raise SystemExit(f"{' '.join(cmd)}: {out.stderr[-1500:]}")
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def run_batch(n: int, tmp: Path, size: int) -> tuple[float, float]:
    items = stills(n)
    mats = sorted({m for m, _ in items}, key=MATERIALS.index)
    angles = sorted({a for _, a in items})
    # The spec's product materials x angles; n is a multiple of 4 or below it.
    spec = tmp / "spec.toml"
    spec.write_text(f'out = "{tmp / "out"}"\nsize = {size}\nquality = "low"\nenvironments = ["{ENV}"]\n'
                    f'materials = [{", ".join(repr(m).replace(chr(39), chr(34)) for m in mats)}]\n'
                    f'camera_angles = [{", ".join(str(a) for a in angles)}]\ncontact_sheet = false\n')
    env = dict(os.environ, ALIGHT_CACHE_DIR=str(tmp / "cache"))
    return _timed([ALIGHT + ["batch", str(spec), "--workers", "1", "--force"]], env)


def run_separate(n: int, tmp: Path, size: int) -> tuple[float, float]:
    env = dict(os.environ, ALIGHT_CACHE_DIR=str(tmp / "cache"))
    cmds = [ALIGHT + ["render", "--preset", m, "--env", str(ENV), "--quality", "low", "--size", str(size),
                      "--orbit", str(a), "--out", str(tmp / f"{m}_{a}.png")] for m, a in stills(n)]
    return _timed(cmds, env)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="1,4,16,48")
    ap.add_argument("--separate-max", type=int, default=16, help="largest N also rendered as separate processes")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--size", type=int, default=128)
    args = ap.parse_args()
    for n in (int(x) for x in args.sizes.split(",")):
        ratios = []
        for r in range(args.rounds):
            with tempfile.TemporaryDirectory(prefix="alight-bench-batch-") as tmp:
                wall, cpu = run_batch(n, Path(tmp), args.size)
            print(f"N={n} round {r + 1} batch: wall {wall:.2f} s, CPU {cpu:.2f} s; per still {wall / n:.3f} / {cpu / n:.3f} s",
                  flush=True)
            if n <= args.separate_max:
                with tempfile.TemporaryDirectory(prefix="alight-bench-batch-") as tmp:
                    swall, scpu = run_separate(n, Path(tmp), args.size)
                print(f"N={n} round {r + 1} separate: wall {swall:.2f} s, CPU {scpu:.2f} s; per still "
                      f"{swall / n:.3f} / {scpu / n:.3f} s", flush=True)
                ratios.append(scpu / cpu)
        if ratios:
            print(f"N={n}: separate / batch CPU {statistics.median(ratios):.2f}x "
                  f"(rounds {min(ratios):.2f}-{max(ratios):.2f})", flush=True)


if __name__ == "__main__":
    main()
