"""A glTF file's first render with Mesa's shader cache empty against warm, and where the first
frame's time goes: compiling and linking the GL programs (``ShaderLibrary.program``) or the
draws themselves (llvmpipe compiles each shader variant with LLVM at its first draw). Rounds
alternate empty and warm (A B A B ...) in fresh processes; asserts nothing.

    .venv/bin/python benchmarks/bench_compile.py [--model PATH] [--rounds 3] [--against REF]

"empty": ``MESA_SHADER_CACHE_DISABLE=true``; "warm": Mesa's cache in a private folder
(``MESA_SHADER_CACHE_DIR``) filled by one run first, so the user's own cache is never touched.
alight's bake cache is warm in both (a shared temporary ``ALIGHT_CACHE_DIR``). The default model
is the Khronos TextureTransformTest (``../shared/data/models/khronos/``), 512x512, 4x MSAA.
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
sys.path.insert(0, str(REPO / "benchmarks"))
from bench_gltf import export  # noqa: E402

MODEL = REPO.parent / "shared" / "data" / "models" / "khronos" / "TextureTransformTest" / "glTF" / "TextureTransformTest.gltf"

PROBE = r"""
import json, sys, time
t0 = time.perf_counter()
from alight.core import gpu
compile_seconds = [0.0, 0]
original = gpu.ShaderLibrary.program
def program(self, vertex, fragment, defines=None):
    key = ("program", vertex, fragment, tuple(sorted((defines or {}).items())))
    new = key not in self._programs
    t = time.perf_counter()
    out = original(self, vertex, fragment, defines)
    if new:
        compile_seconds[0] += time.perf_counter() - t
        compile_seconds[1] += 1
    return out
gpu.ShaderLibrary.program = program
from alight.exchange.meshes import load_mesh
from alight.core.scene import Scene
from alight.render.renderer import ForwardRenderer
from alight.ibl.environment import load_environment
mesh = load_mesh(sys.argv[1])
r = ForwardRenderer()
maps = r.bake(load_environment("studio"), "medium")
scene = Scene(mesh=mesh)
t = time.perf_counter()
r.render(scene, maps, 512, 512, aa="msaa")
first = time.perf_counter() - t
t = time.perf_counter()
r.render(scene, maps, 512, 512, aa="msaa")
second = time.perf_counter() - t
print(json.dumps({"process": time.perf_counter() - t0, "first": first, "second": second,
                  "compile": compile_seconds[0], "programs": compile_seconds[1]}))
"""


def run(model: Path, env_extra: dict, pythonpath: str | None, cache: str) -> dict:
    env = dict(os.environ, ALIGHT_CACHE_DIR=cache, **env_extra)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    else:
        env.pop("PYTHONPATH", None)
    done = subprocess.run([sys.executable, "-c", PROBE, str(model)], env=env, capture_output=True, text=True,
                          cwd=tempfile.gettempdir())
    if done.returncode != 0:
        raise SystemExit(done.stderr[-600:])
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", type=Path, default=MODEL)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--against", default=None, help="another git ref, alternated with this tree")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="alight-compile-") as tmp:
        folder = Path(tmp)
        cache = str(folder / "alight-cache")
        trees = {"this tree": None}
        if args.against:
            trees[args.against] = str(export(args.against, folder / "other"))
        modes = {}
        for tree, path in trees.items():
            mesa = str(folder / f"mesa-{len(modes)}")
            run(args.model, {"MESA_SHADER_CACHE_DIR": mesa}, path, cache)   # fills the bake and Mesa's cache
            modes[f"{tree}, empty"] = ({"MESA_SHADER_CACHE_DISABLE": "true"}, path)
            modes[f"{tree}, warm"] = ({"MESA_SHADER_CACHE_DIR": mesa}, path)
        results: dict[str, list[dict]] = {name: [] for name in modes}
        for r in range(args.rounds):
            for name, (extra, path) in modes.items():
                out = run(args.model, extra, path, cache)
                results[name].append(out)
                print(f"round {r + 1} {name:22s} process {out['process']:.2f} s first frame {out['first']:.2f} s "
                      f"(compile+link {out['compile']:.2f} s, {out['programs']} programs) second {out['second']:.2f} s",
                      flush=True)

    def med(name, key):
        values = [o[key] for o in results[name]]
        return f"{statistics.median(values):.2f} s ({min(values):.2f}-{max(values):.2f})"

    print(f"\n{args.model.name}, 512x512 4x MSAA, {args.rounds} rounds alternated")
    print("| run | process | first frame | of which compile+link | second frame |")
    print("| --- | --- | --- | --- | --- |")
    for name in modes:
        print(f"| {name} | {med(name, 'process')} | {med(name, 'first')} | {med(name, 'compile')} | {med(name, 'second')} |")
    for tree in trees:
        ratios = [e["process"] / w["process"] for e, w in zip(results[f"{tree}, empty"], results[f"{tree}, warm"])]
        first = [e["first"] / w["first"] for e, w in zip(results[f"{tree}, empty"], results[f"{tree}, warm"])]
        print(f"{tree}: empty / warm, process {statistics.median(ratios):.2f}x ({min(ratios):.2f}-{max(ratios):.2f}), "
              f"first frame {statistics.median(first):.2f}x ({min(first):.2f}-{max(first):.2f})")


if __name__ == "__main__":
    main()
