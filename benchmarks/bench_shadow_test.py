"""The ``--shadows auto`` decision alone (alight.render.shadows.ShadowMaps.mesh_can_shadow_itself,
as a render calls it once per mesh) and ``is_closed`` (the culling test), for trees alternated.

Each figure is one fresh process per tree and mesh (the first call, as in a cold render), the
mesh loaded first and not timed; rounds alternate the trees (A B, then B A). Asserts nothing.

    .venv/bin/python benchmarks/bench_shadow_test.py --meshes DIR --tree before=/tmp/base_py \\
        --tree after=/tmp/this_py --sizes 10000,1000000,4000000 --rounds 3

``--tree NAME=PYTHONPATH``: a folder whose ``alight`` is the tree to run; ``--meshes DIR`` holds
sphere_<N>.glb (bench_assets.bumpy_sphere).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

CHILD = """
import json, sys, time
from alight.exchange.meshes import load_mesh
from alight.core.mesh import is_closed
from alight.render.shadows import ShadowMaps
mesh = load_mesh(sys.argv[1])
start = time.perf_counter()
answer = ShadowMaps(None).mesh_can_shadow_itself(mesh)
decision = time.perf_counter() - start
start = time.perf_counter()
closed = all(is_closed(p.positions, p.indices) for p in mesh.parts)
print(json.dumps({"decision": decision, "answer": answer, "is_closed": time.perf_counter() - start, "closed": closed}))
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", required=True)
    ap.add_argument("--tree", action="append", required=True, metavar="NAME=PYTHONPATH")
    ap.add_argument("--sizes", default="10000,1000000")
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    trees = dict(t.split("=", 1) for t in args.tree)
    names = list(trees)
    sizes = [int(s) for s in args.sizes.split(",")]
    got: dict = {}
    for r in range(args.rounds):
        for tree in (names if r % 2 == 0 else names[::-1]):
            for size in sizes:
                done = subprocess.run([sys.executable, "-c", CHILD, os.path.join(args.meshes, f"sphere_{size}.glb")],
                                      env=dict(os.environ, PYTHONPATH=trees[tree]), capture_output=True, text=True,
                                      check=True)
                row = json.loads(done.stdout.strip().splitlines()[-1])
                got.setdefault((tree, size), []).append(row)
                print(f"round {r + 1} {tree:>8} {size:>8}: decision {row['decision']:.3f} s ({row['answer']}), "
                      f"is_closed {row['is_closed']:.3f} s ({row['closed']})", flush=True)
    print()
    for size in sizes:
        for tree in names:
            d = [x["decision"] for x in got[(tree, size)]]
            c = [x["is_closed"] for x in got[(tree, size)]]
            print(f"{size:>8} {tree:>8}: decision {statistics.median(d):.3f} s ({min(d):.3f}-{max(d):.3f}), "
                  f"is_closed {statistics.median(c):.3f} s ({min(c):.3f}-{max(c):.3f})")


if __name__ == "__main__":
    main()
