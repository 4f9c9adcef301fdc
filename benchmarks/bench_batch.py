"""Wall time of one batch with 1 and 2 local worker processes (figures, not a test).

    .venv/bin/python benchmarks/bench_batch.py [--executor local] [--items 24] [--size 128]

Each run renders into a fresh folder (--force), so nothing is skipped; the spec uses the
shared venice_sunset environment so every worker pays its own bake, as in real batches.
"""

from __future__ import annotations

import argparse
import io
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

from alight.frontends.batch import plan, run

ENV = REPO.parent / "shared" / "data" / "env" / "venice_sunset_1k.hdr"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--executor", default="local")
    ap.add_argument("--items", type=int, default=24)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--workers", default="1,2")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        spec = Path(tmp) / "bench.toml"
        angles = ", ".join(str(15 * i) for i in range(args.items // 4))
        spec.write_text(f'size = {args.size}\nquality = "low"\nenvironments = ["{ENV}"]\n'
                        f'materials = ["gold", "copper", "water", "iron"]\ncamera_angles = [{angles}]\n'
                        f'contact_sheet = false\n')
        p = plan(spec)
        times = {}
        if args.executor == "ray":
            import ray

            # One local cluster for both runs, so neither pays Ray's start-up.
            ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
        for n in (int(x) for x in args.workers.split(",")):
            p.out_dir = Path(tmp) / f"out{n}"
            for item in p.stills:
                item.out = str(p.out_dir / item.name)
            start = time.perf_counter()
            result = run(p, args.executor, n, force=True, log=io.StringIO())
            times[n] = time.perf_counter() - start
            print(f"{args.executor} {n} worker(s): {len(result.rendered)} images {args.size}px in {times[n]:.2f}s "
                  f"({len(result.failed)} failed)")
        if args.executor == "ray":
            ray.shutdown()
        if 1 in times and 2 in times:
            print(f"speed-up 2 vs 1 workers: {times[1] / times[2]:.2f}x")


if __name__ == "__main__":
    main()
