"""DamagedHelmet's steady frame (bench_peers_assets.py's: its own materials, royal_esplanade_1k
as light and background, 4x MSAA, 1024x1024, sRGB read back, the camera orbiting 1 degree a frame)
drawn with this checkout's shaders and with other shaders/ folders side by side; not a test.
``--sphere``: the built-in sphere instead (a check that its frame is unchanged).

    git archive HEAD shaders | tar -x -C /tmp/base          # the other side's shaders/
    .venv/bin/python benchmarks/bench_helmet_frame.py --other base=/tmp/base/shaders [--rounds 5]
        [--size 1024] [--split] [--features] [--upload]

Each side is an ``alight.Renderer`` with the defaults (shadows and occlusion ``auto``, mesh
shading ``auto``); an ``--other`` side's ForwardRenderer reads its folder (``use_shaders``), the
Python side is this checkout's, so the sides differ in their shaders only. Rounds alternate the
sides A B, B A, ...; each round takes 3 frames per side, the frame's CPU time of the process
(llvmpipe's threads included: on a shared machine wall time swings with other jobs far more than
the work itself). Printed: each side's median [min-max] of the round medians, each other side's
ratio to this one (median and range of the per-round ratios), and the largest sRGB difference
between the sides' frames at the same camera (0: the same picture).

``--split`` first prints where this side's frame goes: the scene pass, the resolve and the read
back, each between ``ctx.finish()`` calls (finishing changes the overlap, so the parts are close
to, not exactly, the whole), and the CPU time per thread (Python's and llvmpipe's).
``--upload`` prints what uploading DamagedHelmet's normal map costs with its spread in A
(NORMAL_MAP_TOKSVIG: its levels made on the CPU) against GL's own mips, alternated.
``--features`` then prints what the sun's shadows and the occlusion bake cost this side's frame:
the frame with ``set_shadows("off")``, ``set_occlusion("off")`` and both, alternated with the
defaults in the same way (other pictures: a measure of their cost, not a speed-up).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data"
HELMET = DATA / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
ENV = DATA / "env" / "royal_esplanade_1k.hdr"


def thread_cpu() -> dict[str, float]:
    """CPU seconds per thread of this process, by thread name and id (Linux /proc)."""
    out = {}
    for tid in os.listdir("/proc/self/task"):
        try:
            stat = Path(f"/proc/self/task/{tid}/stat").read_text()
            name = Path(f"/proc/self/task/{tid}/comm").read_text().strip()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        out[f"{name} {tid}"] = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    return out


def split(renderer, frames: int = 6) -> None:
    """Print the scene pass, the resolve and the read-back of ``renderer``'s frames, finished apart."""
    from alight.render import passes

    parts: dict[str, list[float]] = {}
    ctx = renderer._renderer.ctx
    originals = {name: getattr(passes, name) for name in ("draw_scene", "resolve", "read_tile")}

    def timed(name):
        def run(*args, **kwargs):
            ctx.finish()
            c = time.process_time()
            out = originals[name](*args, **kwargs)
            ctx.finish()
            parts.setdefault(name, []).append(time.process_time() - c)
            return out
        return run

    for name in originals:
        setattr(passes, name, timed(name))
    try:
        total = []
        for i in range(frames):
            renderer.set_camera(orbit_deg=float(i))
            c = time.process_time()
            renderer.render()
            total.append(time.process_time() - c)
    finally:
        for name, f in originals.items():
            setattr(passes, name, f)
    print(f"where the frame goes (CPU ms, median of {frames} frames, each part finished apart):")
    for name, values in (*parts.items(), ("whole frame", total)):
        print(f"  {name:12s} {statistics.median(values) * 1e3:7.1f}")
    before, start = thread_cpu(), time.perf_counter()
    for i in range(frames):
        renderer.set_camera(orbit_deg=float(i))
        renderer.render()
    after, wall = thread_cpu(), time.perf_counter() - start
    print(f"CPU per thread (ms a frame; wall {wall / frames * 1e3:.0f} ms a frame):")
    for key, value in after.items():
        spent = (value - before.get(key, 0.0)) / frames
        if spent > 0:
            print(f"  {key:24s} {spent * 1e3:7.1f}")
    r = renderer._renderer
    print(f"mesh shading: {'visibility buffer' if r.last_vbuffer else 'forward'} ({r.last_mesh_shading_reason}); "
          f"shadow maps: {r.shadow_maps.last_active}; anisotropy: {r.last_anisotropy}")


def upload(renderer, rounds: int) -> None:
    """Print what uploading DamagedHelmet's normal map costs with its spread in A
    (gpu_mesh.upload_normal_map: GL's mips, then the spread by a compute pass; bench_normal_spread.py
    sets it against the numpy twin's levels) and without (upload_image: GL's
    generate_mipmap), alternated; wall and CPU time, the texture finished (ctx.finish)."""
    from alight.exchange.meshes import load_mesh
    from alight.render.gpu_mesh import upload_image, upload_normal_map

    ctx, shaders = renderer._renderer.ctx, renderer._renderer.shaders
    info = next(part.material.textures()["normal"] for part in load_mesh(str(HELMET)).parts)
    ways = {"with spread": lambda: upload_normal_map(ctx, shaders, info.image, 1.0),
            "GL mips": lambda: upload_image(ctx, info.image, False)}
    wall: dict[str, list[float]] = {name: [] for name in ways}
    cpu: dict[str, list[float]] = {name: [] for name in ways}
    for k in range(rounds):
        for name in (list(ways) if k % 2 == 0 else list(ways)[::-1]):
            w, c = time.perf_counter(), time.process_time()
            tex = ways[name]()
            ctx.finish()
            wall[name].append(time.perf_counter() - w)
            cpu[name].append(time.process_time() - c)
            tex.release()
    h, w = info.image.shape[:2]
    print(f"DamagedHelmet's normal map ({w}x{h}) uploaded, {rounds} rounds alternated; ms, median [min-max]:")
    for name in ways:
        print(f"  {name:12s} wall {statistics.median(wall[name]) * 1e3:5.0f} [{min(wall[name]) * 1e3:.0f}-"
              f"{max(wall[name]) * 1e3:.0f}]  CPU {statistics.median(cpu[name]) * 1e3:5.0f} "
              f"[{min(cpu[name]) * 1e3:.0f}-{max(cpu[name]) * 1e3:.0f}]")


FEATURES = {"defaults": ("auto", "auto"), "shadows off": ("off", "auto"), "occlusion off": ("auto", "off"),
            "both off": ("off", "off")}   # name: (set_shadows, set_occlusion)


def features(renderer, rounds: int) -> None:
    """Print the frame's CPU time with the sun's shadows and/or the occlusion bake off, alternated."""
    cpu: dict[str, list[float]] = {name: [] for name in FEATURES}
    names = list(FEATURES)
    for k in range(rounds):
        for name in (names if k % 2 == 0 else names[::-1]):
            shadows, occlusion = FEATURES[name]
            renderer.set_shadows(shadows).set_occlusion(occlusion)
            renderer.render()                    # (a bake or a shadow map drawn anew stays out of the timing)
            times = []
            for j in range(3):
                renderer.set_camera(orbit_deg=float(3 * k + j))
                c = time.process_time()
                renderer.render()
                times.append(time.process_time() - c)
            cpu[name].append(statistics.median(times))
    renderer.set_shadows("auto").set_occlusion("auto")
    print(f"what the features cost ({rounds} rounds of 3 frames, alternated; CPU ms, median [min-max], / defaults per round):")
    for name in names:
        v = cpu[name]
        ratios = [a / b for a, b in zip(v, cpu["defaults"])]
        print(f"  {name:14s} {statistics.median(v) * 1e3:6.0f} [{min(v) * 1e3:.0f}-{max(v) * 1e3:.0f}]  "
              f"{statistics.median(ratios):.2f} ({min(ratios):.2f}-{max(ratios):.2f})")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--other", action="append", default=[], metavar="NAME=DIR",
                    help="another shaders/ folder to draw the same frames with (repeatable)")
    ap.add_argument("--split", action="store_true", help="first print where this side's frame goes")
    ap.add_argument("--features", action="store_true",
                    help="first print what the sun's shadows and the occlusion bake cost this side's frame")
    ap.add_argument("--upload", action="store_true",
                    help="first print what uploading the normal map with its spread costs (against GL's mips)")
    ap.add_argument("--sphere", action="store_true",
                    help="the built-in sphere (its default material, its impostor) instead of DamagedHelmet: a check that it is unchanged")
    args = ap.parse_args(argv)

    import numpy as np

    import alight
    from alight.core.gpu import ShaderLibrary

    sides = {"this": alight.Renderer(args.size, args.size, aa="msaa")}
    for item in args.other:
        name, _, folder = item.partition("=")
        if not Path(folder, "render", "pbr.frag").is_file():
            print(f"bench_helmet_frame: --other {item}: no shaders/ folder there (render/pbr.frag)", file=sys.stderr)
            return 2
        sides[name] = alight.Renderer(args.size, args.size, aa="msaa")
    for name, r in sides.items():
        if not args.sphere:
            r.set_mesh(str(HELMET))
        r.set_environment(str(ENV))
        r.open()
        if name != "this":
            folder = dict(item.partition("=")[::2] for item in args.other)[name]
            r._renderer.use_shaders(ShaderLibrary(r._renderer.ctx, Path(folder)))
    for r in sides.values():                 # programs, the bake, the shadow maps: out of the timing
        for i in range(2):
            r.set_camera(orbit_deg=float(i))
            r.render()
    if args.split:
        split(sides["this"])
    if args.features:
        features(sides["this"], args.rounds)
    if args.upload:
        upload(sides["this"], args.rounds)
    cpu: dict[str, list[float]] = {name: [] for name in sides}
    largest = {name: 0 for name in sides}
    names = list(sides)
    for k in range(args.rounds):
        images = {}
        for name in (names if k % 2 == 0 else names[::-1]):
            r, times = sides[name], []
            for j in range(3):
                r.set_camera(orbit_deg=float(3 * k + j))
                c = time.process_time()
                image = r.render()
                times.append(time.process_time() - c)
                if j == 0:
                    images[name] = image.astype(np.int16)
            cpu[name].append(statistics.median(times))
        for name in names:
            largest[name] = max(largest[name], int(np.abs(images[name] - images["this"]).max()))
        print(f"round {k + 1}: " + ", ".join(f"{name} {cpu[name][-1] * 1e3:.0f}" for name in names), flush=True)
    print(f"\n{'the built-in sphere' if args.sphere else 'DamagedHelmet'} {args.size}x{args.size}, royal_esplanade_1k, 4x MSAA, sRGB read back; "
          f"{args.rounds} rounds of 3 frames, sides alternated; CPU ms a frame, median [min-max] of round medians")
    for name in names:
        v = cpu[name]
        line = f"  {name:10s} {statistics.median(v) * 1e3:6.0f} [{min(v) * 1e3:.0f}-{max(v) * 1e3:.0f}]"
        if name != "this":
            ratios = [a / b for a, b in zip(v, cpu["this"])]
            line += (f"  {name} / this {statistics.median(ratios):.3f} (per round {min(ratios):.3f}-{max(ratios):.3f}); "
                     f"largest sRGB difference {largest[name]}/255")
        print(line)
    for r in sides.values():
        r.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
