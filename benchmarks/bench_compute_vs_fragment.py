"""The prefilter pass (the bake's most expensive) as a compute shader and as a fragment shader:
the same GLSL function (shaders/common/prefilter.glsl), the same samples, the same texels.
Prints the median time of each per roughness step and their ratio, and checks that both give
the same radiance.

    python benchmarks/bench_compute_vs_fragment.py [--env PATH] [--quality medium] [--repeats 5]
"""

import argparse
import statistics
import time
from pathlib import Path

import moderngl
import numpy as np

from alight.core.gpu import describe
from alight.ibl.bake import QUALITY, grid_roughness, prefilter_sample_set, read_cube
from alight.ibl.environment import load_environment
from alight.render.renderer import ForwardRenderer

DEFAULT_ENV = Path(__file__).resolve().parents[2] / "shared" / "data" / "env" / "royal_esplanade_1k.hdr"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--env", default=str(DEFAULT_ENV))
    ap.add_argument("--quality", default="medium")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()

    r = ForwardRenderer()
    ctx = r.ctx
    q = QUALITY[args.quality]
    maps = r.bake(load_environment(args.env), q)
    source = maps.environment
    compute = r.shaders.compute("ibl/prefilter.comp")
    fragment = r.shaders.program("render/fullscreen.vert", "ibl/prefilter.frag")
    vao = ctx.vertex_array(fragment, [])
    levels = q.prefiltered_levels
    print(f"{describe(ctx)}; quality {q.name}; median of {args.repeats}")
    print(f"{'step':>4} {'r':>6} {'face':>5} {'samples':>7} {'compute ms':>11} {'fragment ms':>12} {'frag/comp':>9} {'max |diff|':>10}")
    totals = [0.0, 0.0]
    for step in range(2 * levels - 1):
        cube = maps.prefiltered_radiance if step % 2 == 0 else maps.prefiltered_radiance_mid
        mip = step // 2
        size = cube.size[0] >> mip
        samples = prefilter_sample_set(grid_roughness(step, levels), q.prefilter_samples_at(step), q.cube_size,
                                       q.lod_bias, q.filtered_importance_sampling)
        buffer = ctx.buffer(samples.tobytes())
        buffer.bind_to_storage_buffer(1)
        source.use(0)
        target = ctx.texture_cube((size, size), 4, dtype="f4")
        stacked = ctx.texture((size, 6 * size), 4, dtype="f4")
        fbo = ctx.framebuffer([stacked])
        for prog in (compute, fragment):
            prog["u_environment"] = 0
            prog["u_size"] = size
            prog["u_sample_count"] = len(samples)

        def run_compute():
            target.bind_to_image(0, read=False, write=True, level=0)
            compute.run((size + 7) // 8, (size + 7) // 8, 6)
            ctx.finish()

        def run_fragment():
            fbo.use()
            ctx.viewport = (0, 0, size, 6 * size)
            vao.render(moderngl.TRIANGLES, vertices=3)
            ctx.finish()

        times = []
        for run in (run_compute, run_fragment):
            run()  # warm-up: first use compiles and allocates
            samples_s = []
            for _ in range(args.repeats):
                t = time.perf_counter()
                run()
                samples_s.append(time.perf_counter() - t)
            times.append(statistics.median(samples_s))
        from_compute = read_cube(r.shaders, target)[..., :3]
        from_fragment = np.frombuffer(stacked.read(), np.float32).reshape(6, size, size, 4)[..., :3]
        diff = float(np.abs(from_compute - from_fragment).max() / max(1e-12, np.abs(from_compute).max()))
        totals[0] += times[0]
        totals[1] += times[1]
        print(f"{step:4d} {grid_roughness(step, levels):6.3f} {size:5d} {len(samples):7d} {times[0] * 1e3:11.2f} "
              f"{times[1] * 1e3:12.2f} {times[1] / times[0]:9.2f} {diff:10.1e}")
        for obj in (buffer, target, fbo, stacked):
            obj.release()
    print(f"all steps: compute {totals[0] * 1e3:.1f} ms, fragment {totals[1] * 1e3:.1f} ms, "
          f"fragment/compute {totals[1] / totals[0]:.2f}")


if __name__ == "__main__":
    main()
