"""The built-in sphere as an impostor against its tessellation, alternated in one process. Not a test.

    .venv/bin/python benchmarks/bench_impostor.py                        # 1920x1080, 4x MSAA and no AA
    .venv/bin/python benchmarks/bench_impostor.py --size 860x720 --rounds 6 --out /tmp/impostor

One renderer draws the same orbiting frames (gold r = 0.3; royal_esplanade_1k.hdr where
../shared/data is beside the checkout, else the built-in studio) with
``ForwardRenderer.sphere_impostor`` on and off in turn (A B A B ...), so load from other work
falls on both alike. Each frame is read back as 8-bit sRGB (``Renderer.render()``), after
``glFinish``. Prints the GL renderer, the medians and ranges of wall and CPU time (CPU: the
process with all its threads, so llvmpipe's workers count) and of the GL time the frame's
commands took (a GL_TIME_ELAPSED query: on a GPU, the GPU's time, without Python's), the
ratios impostor / tessellated
(below 1: the impostor is faster), and how the two pictures differ (outline pixels only: the
impostor's coverage is the true sphere's). ``--out`` keeps both pictures as PNG.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
ENV = REPO.parent / "shared" / "data" / "env" / "royal_esplanade_1k.hdr"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="1920x1080")
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--frames", type=int, default=5, help="frames per round and variant (default: 5)")
    parser.add_argument("--aa", default="msaa,none", help="anti-aliasing modes to run (default: msaa,none)")
    parser.add_argument("--out", help="a folder for the last frame of each variant, as PNG")
    args = parser.parse_args()
    w, h = (int(x) for x in args.size.lower().split("x"))

    import alight
    from alight.exchange.output import write_image

    env = str(ENV) if ENV.exists() else "studio"
    for aa in args.aa.split(","):
        with alight.Renderer(w, h, aa=aa) as r:
            r.set_mesh("sphere").set_environment(env).set_material("gold", roughness=0.3)
            forward = r.open()._renderer
            print(f"{forward.ctx.info['GL_RENDERER']}; {w}x{h}, aa={aa}, {Path(env).name}")
            times = {True: [], False: []}
            cpu = {True: [], False: []}
            gpu = {True: [], False: []}
            query = forward.ctx.query(time=True)
            last = {}
            frame = 0
            for variant in (True, False):       # warm-up: compile both variants' programs, bake
                forward.sphere_impostor = variant
                r.render()
            for _ in range(args.rounds):
                for variant in (True, False):
                    forward.sphere_impostor = variant
                    for _ in range(args.frames):
                        frame += 1
                        r.set_camera(orbit_deg=float(frame % 360))
                        forward.ctx.finish()
                        t, c = time.perf_counter(), time.process_time()
                        with query:
                            r.render()
                        times[variant].append(time.perf_counter() - t)
                        cpu[variant].append(time.process_time() - c)
                        gpu[variant].append(query.elapsed * 1e-9)
                    assert forward.last_sphere_impostor == ({"msaa": 4}.get(aa, 1) if variant else None)
            for variant in (True, False):
                forward.sphere_impostor = variant
                r.set_camera(orbit_deg=0.0)
                last[variant] = r.render()
            forward.sphere_impostor = True
        for variant, label in ((True, "impostor"), (False, "tessellated")):
            for name, v in (("wall", times[variant]), ("CPU", cpu[variant]), ("GL time", gpu[variant])):
                print(f"  {label:11s} {name:7s} median {statistics.median(v) * 1000:8.3f} ms "
                      f"({min(v) * 1000:.3f}-{max(v) * 1000:.3f}), n={len(v)}")
        m = statistics.median
        print(f"  impostor / tessellated: wall {m(times[True]) / m(times[False]):.2f}, "
              f"CPU {m(cpu[True]) / m(cpu[False]):.2f}, GL time {m(gpu[True]) / m(gpu[False]):.2f}")
        d = np.abs(last[True][..., :3].astype(int) - last[False][..., :3].astype(int)).max(axis=2)
        print(f"  pictures: {int((d > 0).sum())} pixels differ ({100.0 * (d > 0).mean():.3f}%), "
              f"{int((d > 2).sum())} by more than 2 LSB, at most {int(d.max())} LSB")
        if args.out:
            out = Path(args.out)
            out.mkdir(parents=True, exist_ok=True)
            for variant, label in ((True, "impostor"), (False, "tessellated")):
                write_image(out / f"{label}_{aa}.png", last[variant][..., :3].copy(), linear=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
