"""The editor's occlusion (app/frontends/editor/occlusion_bake.py): how long its child process
takes to fill a cold bake cache (the visibility bake, the suns' pass and the sky weight, the time
the view is drawn without occlusion), and what the editor process then spends loading the baked
parts from the cache (``passes.occluded_parts``: the cache reads, the refined parts uploaded, the
sky weight read; the frame that switches to the occluded picture pays it). Per scene (the bowl,
the corner, DamagedHelmet) under the editor's default 'studio' and under quarry_01 (a map with a
sun: the suns' pass has work), the scene's own material (grey for the built scenes, the
helmet's file materials).

    .venv/bin/python benchmarks/bench_editor_occlusion.py [--rounds 7] [--scenes bowl,corner,helmet]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--scenes", default="bowl,corner,helmet")
    ap.add_argument("--envs", default="studio,quarry_01_1k.hdr")
    args = ap.parse_args(argv)
    os.environ["ALIGHT_CACHE_DIR"] = tempfile.mkdtemp(prefix="alight-bench-cache-")   # cold for the child

    from bench_occlusion import ENV_DIR, load_scene_mesh, scene_for

    from alight.frontends.editor.occlusion_bake import OcclusionJob
    from alight.frontends.editor.worker_process import WorkerProcess
    from alight.ibl.bake import QUALITY
    from alight.ibl.environment import load_environment
    from alight.render.bindings import sun_world_directions
    from alight.render.gpu_mesh import GpuPart
    from alight.render.passes import occluded_parts
    from alight.render.renderer import ForwardRenderer
    from alight.render.visibility_parts import environment_texels, light_through

    r = ForwardRenderer()
    worker = WorkerProcess("alight.frontends.editor.occlusion_bake")
    folder = Path(tempfile.mkdtemp(prefix="alight-bench-scenes-"))
    print("| scene | env | vertices | child, cold cache (s) | editor's load from the cache (ms), median [min-max] |")
    print("| --- | --- | ---: | ---: | ---: |")
    try:
        for name in args.scenes.split(","):
            mesh = load_scene_mesh(name, folder)
            scene = scene_for(mesh, name, 256, occlusion="on")
            if name == "helmet":
                scene.use_file_materials = True
            for env_name in args.envs.split(","):
                env = load_environment(env_name if env_name == "studio" else str(ENV_DIR / env_name))
                maps = r.bake(env, QUALITY["medium"])
                suns = sun_world_directions(scene, maps)
                texels, digest = environment_texels(r.shaders, maps)
                out = worker.scratch_file("bench.pickle")
                start = time.perf_counter()
                job_id = worker.submit(OcclusionJob(mesh=mesh, mesh_token=id(mesh), mode="on",
                                                    through=light_through(scene), suns=suns, texels=texels,
                                                    digest=digest, rotation_deg=0.0, out=str(out)))
                answers = worker.wait(job_id, 900.0)
                child_s = time.perf_counter() - start
                words = [w for i, w, _ in answers if i == job_id and w != "progress"]
                assert words == ["done"], answers
                loads = []
                drawn = r.meshes.parts(mesh)
                for _ in range(args.rounds):
                    r.visibility_parts.release()
                    r.visibility_parts.decide(mesh, "on", True)   # as the editor records the child's answer
                    t0 = time.perf_counter()
                    parts = occluded_parts(r, scene, drawn, suns, maps)
                    r.ctx.finish()
                    loads.append((time.perf_counter() - t0) * 1000.0)
                    assert parts is not drawn and r.visibility_parts.bakes_run == 0
                vertices = sum(len(p.positions) for p in mesh.parts)
                print(f"| {name} | {env_name.split('_1k')[0]} | {vertices} | {child_s:.1f} | "
                      f"{np.median(loads):.0f} [{min(loads):.0f}-{max(loads):.0f}] |", flush=True)
    finally:
        worker.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
