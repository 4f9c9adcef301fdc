"""DamagedHelmet's load and an opaque frame: this working tree against another git ref (default
``main``), run alternately (A B A B ...) in fresh processes so that load on a shared machine
falls on both alike. Prints medians and ranges; asserts nothing.

    .venv/bin/python benchmarks/bench_gltf.py [--ref main] [--rounds 5]

Per process: ``load cold`` is the first ``load_mesh`` of DamagedHelmet.gltf (imports included:
what one ``alight render --mesh`` pays), ``load warm`` the median of three more; ``frame`` is
``ForwardRenderer.draw_display`` (the editor's path: no anti-aliasing, tone mapped as drawn) at
1280x720 plus ``finish()``, the median of 15 after 3 warm-up frames, for the material ball (studio
IBL, 3 lights) and for DamagedHelmet. The other ref is exported with ``git archive`` into a
temporary folder and imported from there; this tree through a symlink to its app/ (``this_tree``).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
HELMET = REPO.parent / "shared" / "data" / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"

PROBE = r"""
import json, sys, time
t0 = time.perf_counter()
from alight.exchange.meshes import load_mesh
helmet = load_mesh(sys.argv[1])
cold = time.perf_counter() - t0
warm = []
for _ in range(3):
    t = time.perf_counter(); load_mesh(sys.argv[1]); warm.append(time.perf_counter() - t)
import numpy as np
from alight.core.scene import Display, Light, Scene
from alight.ibl.environment import load_environment
from alight.render.renderer import ForwardRenderer
r = ForwardRenderer()
maps = r.bake(load_environment("studio"), "medium")
lights = [Light("point", (2.0, 3.0, 4.0), intensity=30.0), Light("directional", (-1.0, -1.0, -1.0), intensity=2.0),
          Light("point", (-3.0, 1.0, 2.0), intensity=10.0)]
out = {"load_cold": cold, "load_warm": sorted(warm)[1]}
for name, mesh in (("ball", load_mesh("sphere")), ("helmet", helmet)):
    scene = Scene(mesh=mesh, lights=lights, display=Display())
    targets = r._targets_for(1280, 720, "none", 0)
    times = []
    for i in range(18):
        t = time.perf_counter(); r.draw_display(scene, maps, targets); r.ctx.finish()
        if i >= 3:
            times.append(time.perf_counter() - t)
    out[f"frame_{name}"] = sorted(times)[len(times) // 2]
print(json.dumps(out))
"""


def export(ref: str, into: Path) -> Path:
    """The ref's app/, shaders/ and presets/ under ``into``; returns a folder to put on PYTHONPATH."""
    src = into / "src"
    src.mkdir(parents=True)
    archive = subprocess.run(["git", "-C", str(REPO), "archive", ref, "app", "shaders", "presets"],
                             check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(src)], input=archive, check=True)
    pkg = into / "pkg"
    pkg.mkdir()
    (pkg / "alight").symlink_to(src / "app")
    return pkg


def this_tree(into: Path) -> Path:
    """A folder to put on PYTHONPATH that imports this checkout's app/ as ``alight`` (the venv's
    editable install may point at another checkout: a worktree shares the venv)."""
    pkg = into / "pkg"
    pkg.mkdir(parents=True)
    (pkg / "alight").symlink_to(REPO / "app")
    return pkg


def run(pythonpath: str, cache: str) -> dict:
    env = dict(os.environ, ALIGHT_CACHE_DIR=cache, PYTHONPATH=pythonpath)
    done = subprocess.run([sys.executable, "-c", PROBE, str(HELMET)], env=env, capture_output=True, text=True,
                          cwd=tempfile.gettempdir())
    if done.returncode != 0:
        raise SystemExit(done.stderr)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", default="main", help="the git ref to compare with (default: main)")
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        pkg = export(args.ref, Path(tmp) / "ref")
        mine = this_tree(Path(tmp) / "this")
        cache = str(Path(tmp) / "cache")
        results: dict[str, list[dict]] = {args.ref: [], "this tree": []}
        for k in range(args.rounds):
            for label, path in ((args.ref, str(pkg)), ("this tree", str(mine))):
                results[label].append(run(path, cache))
                print(f"round {k + 1}/{args.rounds} {label}: " +
                      ", ".join(f"{m} {v * 1000:.0f} ms" for m, v in results[label][-1].items()), file=sys.stderr)
    try:
        load = os.getloadavg()
        print(f"load average at the end: {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}")
    except OSError:
        pass
    print(f"{'measure':14s} {args.ref + ' median (range)':>28s} {'this tree median (range)':>28s} {'ratio':>7s}")
    for measure in results[args.ref][0]:
        a = [r[measure] * 1000 for r in results[args.ref]]
        b = [r[measure] * 1000 for r in results["this tree"]]
        ma, mb = statistics.median(a), statistics.median(b)
        print(f"{measure:14s} {ma:10.1f} ms ({min(a):.0f}-{max(a):.0f}) {mb:12.1f} ms ({min(b):.0f}-{max(b):.0f}) "
              f"{mb / ma:7.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
