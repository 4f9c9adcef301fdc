"""The compare view's reference process: ``python -m alight.frontends.editor.reference_worker``.

Each job (worker_process.py) is a ``ReferenceJob``: the view's scene, the environment, the view's
size and the reference's scale. The child rasterises the mesh's G-buffer in its own EGL context
and sums ``alight reference``'s exact integral (app/accuracy/reference.py) a band of rows at a
time into ``out`` (a .npy the parent maps: (h, w, 4) float32 radiance, top row first, alpha 1
where summed), answering ``progress`` after each band. A newer job stops the sum between bands.
On a 2-core llvmpipe machine the sum of an 800x720 view at scale 0.25 takes about two minutes;
the editor's frames go on meanwhile and show the rows summed so far (compare_view.py).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

# A band's time in the child: long enough that a band's fixed cost is small, short enough that
# the half fills in visibly and a newer job waits at most this long.
BAND_S = 0.25


@dataclass
class ReferenceJob:
    scene: object          # alight.core.scene.Scene (display settings unused)
    env: object            # alight.ibl.environment.Environment or None
    width: int             # the view's pixels
    height: int
    scale: float           # the sum's pixels per view pixel, each way
    out: str               # the .npy the child writes


def reference_size(width: int, height: int, scale: float) -> tuple[int, int]:
    """The sum's (width, height) for a view: ``scale`` of its pixels, at least 16 wide."""
    rw = max(16, round(width * scale))
    return rw, max(1, round(height * rw / width))


def reference_bands(renderer, scene, env, width: int, height: int, scale: float, band_s: float = BAND_S):
    """A generator: the reference of the view at ``scale`` of its pixels, one band of rows per step;
    yields (the radiance so far (h, w, 4) float32, top row first, alpha 0 where not summed yet;
    the fraction done). Errors: AlightError (a roughness or layer the reference cannot sum)."""
    from alight.accuracy.reference import (
        GBUFFER,
        ReferenceRenderer,
        check_layer_lobes,
        check_layer_roughness,
        check_roughness,
        choose_env_level,
        env_level_radiance,
    )

    rw, rh = reference_size(width, height, scale)
    rr = ReferenceRenderer(renderer)
    use_env = env is not None and scene.ibl_enabled
    radiance = None
    if use_env:
        from alight.frontends.editor.compare import control_name   # the panel's names, not the CLI's flags

        roughnesses = rr.scene_roughnesses(scene)
        for r in roughnesses:
            check_roughness(r, name=control_name)
        check_layer_roughness(rr.layered_material(scene), name=control_name)
        check_layer_lobes(rr.layered_material(scene), roughnesses, name=control_name)
        # Reduced once here (the reference's own choice of level), not per band.
        radiance = env_level_radiance(np.asarray(env.radiance, np.float32),
                                      choose_env_level(env.radiance, roughnesses))
    textures = rr.mesh_gbuffer(scene, rw, rh)
    g = {}
    for name, tex in zip(GBUFFER, textures):
        g[name] = np.frombuffer(tex.read(), np.float32).reshape(rh, rw, 4)[::-1].copy()
        tex.release()
    linear = np.zeros((rh, rw, 4), np.float32)
    covered = g["position"][..., 3] > 0.5
    yield linear, 0.0
    band, y = 1, 0
    while y < rh:
        while y < rh and not covered[y].any():   # rows without the mesh: nothing to sum
            y += 1
        if y >= rh:
            break
        y1 = min(rh, y + band)
        t0 = time.perf_counter()
        part = rr.render_gbuffer({n: g[n][y:y1] for n in GBUFFER}, scene, radiance, env_level=0)
        linear[y:y1] = part.linear
        linear[y:y1, :, 3] = covered[y:y1]
        # The next band sized to the band time from this one's.
        spent = time.perf_counter() - t0
        band = max(1, min(64, int(band * band_s / max(spent, 1e-4))))
        y = y1
        yield linear, y / rh
    yield linear, 1.0


def main() -> int:
    from alight.frontends.editor.worker_process import serve
    from alight.render.renderer import ForwardRenderer

    renderer = ForwardRenderer()

    def handle(job: ReferenceJob | None, progress, superseded) -> bool:
        if job is None:   # the parent's "stop": the job it supersedes is answered cancelled
            return True
        out = None
        for linear, fraction in reference_bands(renderer, job.scene, job.env, job.width, job.height, job.scale):
            if out is None:   # the parent maps it after the first progress line
                tmp = Path(job.out).with_suffix(".tmp.npy")
                out = np.lib.format.open_memmap(tmp, mode="w+", dtype=np.float32, shape=linear.shape)
                out[:] = linear
                out.flush()
                tmp.replace(job.out)
            else:
                out[:] = linear
                out.flush()
            progress(fraction)
            if superseded():
                return False
        return True

    return serve(handle)


if __name__ == "__main__":
    sys.exit(main())
