"""What the glTF layers cost per frame: a material without layers against the same
material drawn by another revision's shaders (it must cost what it cost before the layers, within
3%), and each layer's own frame cost.

The scene is the material ball at 1280x720 (the built-in sphere, camera view, the environment as
background, three point lights), lit by royal_esplanade_1k baked at `medium`, with the default
IBL model. Every variant is drawn once to compile, then the variants take turns (A B C ... A B C
...) so that load spikes from other jobs fall on all of them alike; each time is render + finish.
The medians and ranges are printed; nothing is asserted.

    .venv/bin/python benchmarks/bench_layers.py                    # baseline: main's shaders/
    .venv/bin/python benchmarks/bench_layers.py --baseline HEAD~3 --repeats 31
    .venv/bin/python benchmarks/bench_layers.py --instructions     # callgrind: load-independent

The baseline's shaders are taken from git (`git archive REF shaders`) into a temporary folder and
compiled by a second shader library on the same GL context; the Python side is this checkout's
(it passes no layer define for a material without layers, so both draw the same program's
source of their own revision).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))


def baseline_shaders(ref: str, into: Path) -> Path:
    archive = subprocess.run(["git", "archive", ref, "shaders"], cwd=REPO, capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    return into / "shaders"


def layered_materials():
    """The material ball's material without layers, and with each layer on (the same base)."""
    from alight.core.material import Material

    base = Material(base_color=(0.55, 0.12, 0.08), roughness=0.45, name="red_dielectric")
    return base, {
        "clearcoat": Material(base_color=base.base_color, roughness=base.roughness, clearcoat=1.0, clearcoat_roughness=0.1),
        "sheen": Material(base_color=base.base_color, roughness=base.roughness, sheen_color=(0.8, 0.8, 0.8), sheen_roughness=0.5),
        "anisotropy": Material(base_color=base.base_color, roughness=base.roughness, anisotropy_strength=0.8),
        "transmission": Material(base_color=base.base_color, roughness=base.roughness, transmission=1.0),
        "volume": Material(base_color=base.base_color, roughness=base.roughness, transmission=1.0, thickness=0.5,
                           attenuation_color=(0.8, 0.4, 0.2), attenuation_distance=0.5),
    }


def child(variant: str, frames: int, shaders_root: str | None) -> None:
    """Draw the material ball ``frames`` times at 640x360 (royal_esplanade_1k, low bake): the
    process callgrind counts (``instructions``)."""
    from alight.core.gpu import ShaderLibrary
    from alight.core.mesh import sphere
    from alight.core.scene import Light, Scene
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    r = ForwardRenderer()
    if shaders_root:
        r = ForwardRenderer(ctx=r.ctx, shaders=ShaderLibrary(r.ctx, Path(shaders_root)))
    maps = r.bake(load_environment(str(REPO.parent / "shared" / "data" / "env" / "royal_esplanade_1k.hdr")), "low")
    base, layered = layered_materials()
    scene = Scene(mesh=sphere(), material=layered.get(variant, base),
                  lights=[Light(vector=(2.0, 3.0, 4.0)), Light(vector=(-3.0, 1.0, 2.0), color=(0.6, 0.7, 1.0)),
                          Light(vector=(0.0, -2.0, 3.0), intensity=4.0)])
    for _ in range(frames):
        r.render(scene, maps, 640, 360, aa="none", read_linear=False, read_srgb=False)
        r.ctx.finish()


def instructions(baseline: str, variants: list[str], frames: int) -> None:
    """Instructions per frame by callgrind (repeatable whatever the machine's load): each variant
    drawn 1 and 1 + ``frames`` times in fresh processes, llvmpipe on one thread
    (LP_NUM_THREADS=0) and Mesa's shader cache off, so both runs compile alike and the difference
    over ``frames`` is one frame's work."""
    import os
    import re

    tmp = tempfile.TemporaryDirectory()
    old_root = baseline_shaders(baseline, Path(tmp.name))
    env = dict(os.environ, LP_NUM_THREADS="0", MESA_SHADER_CACHE_DISABLE="true")
    rows = []
    for variant in variants:
        counts = []
        for n in (1, 1 + frames):
            command = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", sys.executable, __file__,
                       "--child", variant, "--frames", str(n)]
            if variant == "baseline":
                command += ["--shaders", str(old_root)]
            run = subprocess.run(command, capture_output=True, text=True, env=env, cwd=REPO)
            found = re.search(r"Collected\s*:\s*(\d+)", run.stderr)
            if run.returncode != 0 or not found:
                raise SystemExit(f"callgrind run failed for {variant}: {run.stderr[-500:]}")
            counts.append(int(found.group(1)))
        rows.append((variant, (counts[1] - counts[0]) / frames))
        print(f"  {variant:14s} {rows[-1][1] / 1e6:9.1f} M instructions per frame", flush=True)
    ref = dict(rows).get("no layers") or rows[0][1]
    print(f"\nmaterial ball 640x360, 3 point lights, royal_esplanade_1k low; callgrind, {frames} frames minus 1")
    for variant, per_frame in rows:
        print(f"{variant:14s} {per_frame / 1e6:9.1f} M  {per_frame / ref:6.3f}x no layers")
    tmp.cleanup()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", default="main", help="git revision whose shaders/ the no-layer material is "
                                                            "compared with (default: main)")
    parser.add_argument("--repeats", type=int, default=21, help="interleaved rounds (default: 21)")
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--instructions", nargs="*", metavar="VARIANT",
                        help="count instructions per frame with callgrind instead of timing: 'baseline' (the "
                             "--baseline revision's shaders), 'no layers', or layer names (default: baseline, "
                             "no layers, clearcoat, sheen)")
    parser.add_argument("--frames", type=int, default=3, help="with --instructions: frames counted (default: 3)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--shaders", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.child, args.frames, args.shaders)
        return 0
    if args.instructions is not None:
        instructions(args.baseline, args.instructions or ["baseline", "no layers", "clearcoat", "sheen"], args.frames)
        return 0
    width, height = (int(x) for x in args.size.split("x"))

    from alight.core.gpu import ShaderLibrary
    from alight.core.mesh import sphere
    from alight.core.scene import Light, Scene
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    env = load_environment(str(REPO.parent / "shared" / "data" / "env" / "royal_esplanade_1k.hdr"))
    renderer = ForwardRenderer()
    maps = renderer.bake(env, "medium")
    tmp = tempfile.TemporaryDirectory()
    old = ForwardRenderer(ctx=renderer.ctx, shaders=ShaderLibrary(renderer.ctx, baseline_shaders(args.baseline, Path(tmp.name))))
    lights = [Light(vector=(2.0, 3.0, 4.0)), Light(vector=(-3.0, 1.0, 2.0), color=(0.6, 0.7, 1.0)),
              Light(vector=(0.0, -2.0, 3.0), intensity=4.0)]
    mesh = sphere()
    base, layered = layered_materials()
    variants = {f"no layers, {args.baseline}'s shaders": (old, base), "no layers, this checkout": (renderer, base)}
    variants.update({f"{name}": (renderer, m) for name, m in layered.items()})
    scenes = {k: (r, Scene(mesh=mesh, material=m, lights=lights)) for k, (r, m) in variants.items()}

    def draw(r, scene):
        r.render(scene, maps, width, height, aa="none", read_linear=False, read_srgb=False)
        r.ctx.finish()

    for r, scene in scenes.values():
        draw(r, scene)   # compile and allocate first
    times = {k: [] for k in scenes}
    for _ in range(args.repeats):
        for k, (r, scene) in scenes.items():
            t = time.perf_counter()
            draw(r, scene)
            times[k].append(time.perf_counter() - t)
    ref = statistics.median(times[next(iter(times))])
    print(f"material ball {width}x{height}, 3 point lights, royal_esplanade_1k medium, {args.repeats} interleaved rounds")
    print(f"{'variant':34s} {'median':>9s} {'range':>19s} {'/ baseline':>10s}")
    for k, ts in times.items():
        med = statistics.median(ts)
        print(f"{k:34s} {1000 * med:7.1f} ms {1000 * min(ts):7.1f}-{1000 * max(ts):7.1f} ms {med / ref:9.3f}x")
    # The pairwise ratio per round is steadier than the ratio of medians under changing load.
    keys = list(times)
    pair = [b / a for a, b in zip(times[keys[0]], times[keys[1]])]
    print(f"this checkout / baseline, per round: median {statistics.median(pair):.3f}, "
          f"range {min(pair):.3f}-{max(pair):.3f}")
    old.shaders.reload()
    renderer.release()
    tmp.cleanup()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
