"""What each glTF layer costs per frame, counted in CPU instructions by valgrind's
callgrind: on llvmpipe the shaders run on the CPU, and an instruction count, unlike a time, does
not move with the load other jobs put on a shared machine. Prints the figures; not a test.

    .venv/bin/python benchmarks/bench_layer_instructions.py              # 640x360, every variant
    .venv/bin/python benchmarks/bench_layer_instructions.py --size 320x180 --baseline HEAD~3

Each variant runs in its own process under ``valgrind --tool=callgrind`` twice, drawing 1 and
then 4 frames of the material ball (bench_layers.py's scene: the built-in sphere, camera view,
the environment as background, three point lights, royal_esplanade_1k baked at ``low``, the
default IBL model); the difference over 3 is one frame's instructions, with the start-up, the
bake and the shader compilation cancelled out (Mesa's shader cache off, so both runs compile). "no layers, <baseline>'s shaders" draws the same
material with the baseline revision's shaders (as bench_layers.py does), for "a material without
layers costs what it costs today".
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

VARIANTS = ("no layers, baseline", "no layers", "clearcoat", "sheen", "anisotropy", "transmission", "volume")


def child(variant: str, frames: int, size: str, baseline: str) -> None:
    """Draw ``frames`` frames of ``variant`` (run inside callgrind)."""
    from benchmarks.bench_layers import baseline_shaders
    from alight.core.gpu import ShaderLibrary
    from alight.core.material import Material
    from alight.core.mesh import sphere
    from alight.core.scene import Light, Scene
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    width, height = (int(x) for x in size.split("x"))
    base = dict(base_color=(0.55, 0.12, 0.08), roughness=0.45)
    materials = {
        "no layers": Material(**base), "no layers, baseline": Material(**base),
        "clearcoat": Material(**base, clearcoat=1.0, clearcoat_roughness=0.1),
        "sheen": Material(**base, sheen_color=(0.8, 0.8, 0.8), sheen_roughness=0.5),
        "anisotropy": Material(**base, anisotropy_strength=0.8),
        "transmission": Material(**base, transmission=1.0),
        "volume": Material(**base, transmission=1.0, thickness=0.5, attenuation_color=(0.8, 0.4, 0.2),
                           attenuation_distance=0.5),
    }
    renderer = ForwardRenderer()
    tmp = None
    if variant == "no layers, baseline":
        tmp = tempfile.TemporaryDirectory()
        renderer = ForwardRenderer(ctx=renderer.ctx,
                                   shaders=ShaderLibrary(renderer.ctx, baseline_shaders(baseline, Path(tmp.name))))
    env = load_environment(str(REPO.parent / "shared" / "data" / "env" / "royal_esplanade_1k.hdr"))
    maps = renderer.bake(env, "low")
    lights = [Light(vector=(2.0, 3.0, 4.0)), Light(vector=(-3.0, 1.0, 2.0), color=(0.6, 0.7, 1.0)),
              Light(vector=(0.0, -2.0, 3.0), intensity=4.0)]
    scene = Scene(mesh=sphere(), material=materials[variant], lights=lights)
    if variant in ("transmission", "volume"):
        renderer.transmission_lut()   # read from the cache before the frames, in both runs
    for _ in range(frames):
        renderer.render(scene, maps, width, height, aa="none", read_linear=False, read_srgb=False)
        renderer.ctx.finish()
    if tmp is not None:
        tmp.cleanup()


def instructions(variant: str, frames: int, size: str, baseline: str, cache: str) -> int:
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "callgrind.out"
        # Mesa's on-disk shader cache would let the second run skip the compiles the first one paid
        # for (the difference then goes negative); the hash seed keeps Python's own work alike.
        env = dict(os.environ, ALIGHT_CACHE_DIR=cache, LP_NUM_THREADS="1", MESA_SHADER_CACHE_DISABLE="true",
                   PYTHONHASHSEED="0")
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable, __file__,
               "--child", variant, "--frames", str(frames), "--size", size, "--baseline", baseline]
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if proc.returncode != 0:
            raise SystemExit(f"{variant}: callgrind run failed:\n{proc.stderr[-2000:]}")
        m = re.search(r"Collected\s*:\s*(\d+)", proc.stderr) or re.search(r"summary:\s*(\d+)", out.read_text())
        return int(m.group(1))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--baseline", default="main", help="git revision for 'no layers, baseline' (default: main)")
    ap.add_argument("--variants", default=",".join(VARIANTS))
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("--frames", type=int, default=1, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        child(args.child, args.frames, args.size, args.baseline)
        return 0
    variants = args.variants.split(",")
    with tempfile.TemporaryDirectory() as cache:
        # Bake the BRDF and transmission LUTs into the cache first, so that no counted run does.
        subprocess.run([sys.executable, __file__, "--child", "volume", "--frames", "1", "--size", "16x16"],
                       env=dict(os.environ, ALIGHT_CACHE_DIR=cache), check=True)
        per_frame = {}
        for v in variants:
            one = instructions(v, 1, args.size, args.baseline, cache)
            four = instructions(v, 4, args.size, args.baseline, cache)
            per_frame[v] = (four - one) / 3
            print(f"  {v}: {per_frame[v] / 1e9:.3f} G instructions per frame", flush=True)
    ref = per_frame.get("no layers, baseline") or per_frame[variants[0]]
    print(f"\nmaterial ball {args.size}, 3 point lights, royal_esplanade_1k (low bake), LP_NUM_THREADS=1; "
          f"instructions per frame (callgrind, 4 frames minus 1 over 3)")
    for v, n in per_frame.items():
        print(f"{v:24s} {n / 1e9:8.3f} G   {n / ref:6.3f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
