"""Trials at a faster first render with Mesa's shader cache empty (issue 21), none kept; prints
figures, asserts nothing (``results/compile.md``, "tried, not kept").

    .venv/bin/python benchmarks/bench_compile_trials.py split [--rounds 3]
    .venv/bin/python benchmarks/bench_compile_trials.py knobs [--rounds 2]
    .venv/bin/python benchmarks/bench_compile_trials.py nopt-frame [--rounds 2]

All on ``bench_compile.py --scene multi``'s nine-material file and its probe (studio, 512x512,
4x MSAA, alight's bake cached), fresh processes, modes alternated in every round:

- **split**: an upper bound of a helper process that fills Mesa's on-disk cache while the main
  process draws. "disabled": ``MESA_SHADER_CACHE_DISABLE=true``; "fresh": the cache on in a new
  empty folder; "fresh+child": the same, with a second process started at the same moment that
  draws the same file with its materials in the opposite order (so the two meet in the middle
  of the variants) into the same new folder, killed when the main process is done; "warm": a
  folder filled before. Only the main process's times count.
- **knobs**: llvmpipe's own settings that make its code generation cheaper, with the cache off:
  ``GALLIVM_PERF=nopt`` (no LLVM optimisation passes), ``LP_NATIVE_VECTOR_WIDTH=128`` (4-wide
  instead of 8-wide code).
- **nopt-frame**: what ``GALLIVM_PERF=nopt`` costs DamagedHelmet's steady 1024x1024 4x MSAA
  frame under royal_esplanade_1k (``alight.Renderer`` defaults, 4 frames after 2, CPU time).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
sys.path.insert(0, str(REPO))
import bench_compile  # noqa: E402

DATA = REPO.parent / "shared" / "data"
HELMET = DATA / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
ENV = DATA / "env" / "royal_esplanade_1k.hdr"

HELMET_FRAMES = r'''
import sys, time, json, alight
with alight.Renderer(1024, 1024, aa="msaa") as r:
    r.set_mesh(sys.argv[1]).set_environment(sys.argv[2])
    cpu = []
    for i in range(6):
        r.set_camera(orbit_deg=float(i))
        t = time.process_time()
        r.render()
        cpu.append(time.process_time() - t)
print(json.dumps(cpu[2:]))
'''


def start(code: str, args: list[str], env: dict, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", code, *args], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=str(cwd))


def result(p: subprocess.Popen):
    out, err = p.communicate()
    if p.returncode:
        raise SystemExit(err[-800:])
    return json.loads(out.strip().splitlines()[-1])


def spread(values) -> str:
    return f"{statistics.median(values):.2f} ({min(values):.2f}-{max(values):.2f})"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trial", choices=("split", "knobs", "nopt-frame"))
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    with open("/proc/loadavg") as f:
        print("load average at the start:", " ".join(f.read().split()[:3]))
    tmp = Path(tempfile.mkdtemp(prefix="alight-compile-trials-"))
    base = dict(os.environ, ALIGHT_CACHE_DIR=str(tmp / "alight-cache"))
    try:
        forward = bench_compile.multi_scene(tmp / "forward.glb")
        bench_compile.MULTI_MATERIALS = tuple(reversed(bench_compile.MULTI_MATERIALS))
        backward = bench_compile.multi_scene(tmp / "backward.glb")
        probe = bench_compile.PROBE

        def multi(model, extra):
            return start(probe, [str(model)], dict(base, **extra), tmp)

        if args.trial == "nopt-frame":
            modes = {"default": {}, "GALLIVM_PERF=nopt": {"GALLIVM_PERF": "nopt"}}
            result(start(HELMET_FRAMES, [str(HELMET), str(ENV)], base, tmp))   # the bakes cached
            frames = {m: [] for m in modes}
            for r in range(args.rounds):
                for m, extra in modes.items():
                    cpu = result(start(HELMET_FRAMES, [str(HELMET), str(ENV)], dict(base, **extra), tmp))
                    frames[m].append(statistics.median(cpu))
                    print(f"round {r + 1} {m:18s} CPU {frames[m][-1] * 1000:.0f} ms a frame", flush=True)
            ratios = [a / b for a, b in zip(frames["GALLIVM_PERF=nopt"], frames["default"])]
            print(f"nopt / default, steady frame CPU: {spread(ratios)}")
            return
        result(multi(forward, {"MESA_SHADER_CACHE_DIR": str(tmp / "filled")}))   # the bake, a warm Mesa cache
        if args.trial == "knobs":
            off = {"MESA_SHADER_CACHE_DISABLE": "true"}
            modes = {"default": off, "GALLIVM_PERF=nopt": {**off, "GALLIVM_PERF": "nopt"},
                     "LP_NATIVE_VECTOR_WIDTH=128": {**off, "LP_NATIVE_VECTOR_WIDTH": "128"}}
        else:
            modes = {"disabled": {"MESA_SHADER_CACHE_DISABLE": "true"}, "fresh": None, "fresh+child": None,
                     "warm": {"MESA_SHADER_CACHE_DIR": str(tmp / "filled")}}
        out = {m: [] for m in modes}
        n = 0
        for r in range(args.rounds):
            for m, extra in modes.items():
                n += 1
                child = None
                if extra is None:
                    extra = {"MESA_SHADER_CACHE_DIR": str(tmp / f"fresh-{n}")}
                    if m == "fresh+child":
                        child = multi(backward, extra)
                o = result(multi(forward, extra))
                if child is not None:
                    child.kill()
                    child.communicate()
                out[m].append(o)
                print(f"round {r + 1} {m:26s} process {o['process']:.2f} s first frame {o['first']:.2f} s "
                      f"second {o['second']:.3f} s ({o['mesh_variants']} of pbr.frag)", flush=True)
        for m in modes:
            print(f"{m:26s} process {spread([o['process'] for o in out[m]])} s, "
                  f"first frame {spread([o['first'] for o in out[m]])} s")
        ref = "warm" if args.trial == "split" else "default"
        for m in modes:
            if m == ref:
                continue
            process = [a["process"] / b["process"] for a, b in zip(out[m], out[ref])]
            first = [a["first"] / b["first"] for a, b in zip(out[m], out[ref])]
            second = [a["second"] / b["second"] for a, b in zip(out[m], out[ref])]
            print(f"{m} / {ref}: process {spread(process)}, first frame {spread(first)}, second frame {spread(second)}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        with open("/proc/loadavg") as f:
            print("load average at the end:", " ".join(f.read().split()[:3]))


if __name__ == "__main__":
    main()
