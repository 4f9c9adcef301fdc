"""``alight chart``'s visibility rows: what each way of blocking light costs and how much error
it removes, against the whole-scene path tracer (app/accuracy/path_trace.py).

For each scene of app/accuracy/scenes.py (``VISIBILITY_SCENES``; --quick: the bowl only) and each
environment of the run, the scene's camera view (``SCENE_VIEWS``) is rendered with each
configuration of ``VISIBILITY_CONFIGS``:

    off        occlusion off, shadows off
    occlusion  the per-vertex visibility bake on (Scene.occlusion 'on'), shadows off
    shadows    the sun's shadow map on (Scene.shadows 'on'; nothing to draw where the map has no sun)
    auto       both 'auto': what `alight render` does by default

and judged against the path-traced reference of that scene and map (traced once per scene x map,
seed 0, ``TraceSettings`` defaults otherwise: 8 bounces), as benchmarks/bench_occlusion.py does:
binned 4x4 linear relMAE (app/accuracy/binned.py), grey dielectric (0.7, roughness 0.5) on every
part. The reference's own noise is measured beside it: a second trace with seed 1, its binned
relMAE against seed 0's (an error below that is not resolved).

Cost: the steady frame at the chart's frame size (scene camera, median of a few, every scene x
configuration interleaved, under the first environment with a sun, so that the shadows are
drawn (the first environment where none has one); the
shadow map is drawn once and kept while nothing moves, so a steady frame holds its lookups, not
its drawing) and the one-off visibility bake (alight.core.visibility.bake_visibility, never from
the disk cache) for the configurations that bake.
"""

from __future__ import annotations

import math
import statistics
import tempfile
import time
from dataclasses import dataclass, field

import numpy as np

from alight.accuracy.scenes import SCENE_VIEWS

VISIBILITY_SCENES = ("corner", "bowl", "product")
QUICK_VISIBILITY_SCENES = ("bowl",)   # the scene where occlusion matters most (bench_occlusion)
VISIBILITY_CONFIGS = {   # name -> (Scene.occlusion, Scene.shadows)
    "off": ("off", "off"),
    "occlusion": ("on", "off"),
    "shadows": ("off", "on"),
    "auto": ("auto", "auto"),
}
GREY = dict(base_color=(0.7, 0.7, 0.7), metallic=0.0, roughness=0.5)
BIN = 4
REFERENCE_SEED, NOISE_SEED = 0, 1


@dataclass(frozen=True)
class VisibilitySettings:
    scenes: tuple[str, ...] = VISIBILITY_SCENES
    size: int = 64            # the error's image (square), as benchmarks/results/occlusion-*.md
    samples: int = 128        # path-traced samples a pixel


@dataclass
class VisibilityResult:
    scene: str
    config: str
    baked: bool = False                       # whether the configuration drew the visibility bake
    bake_seconds: float = math.nan            # the uncached visibility bake, where it bakes
    frame_seconds: float = math.nan
    frame_env: str = ""                       # the map the frame was timed under
    # env, binned relMAE, reference noise, whether a shadow map was drawn (a map without a sun has none)
    cases: list[tuple[str, float, float, bool]] = field(default_factory=list)

    @property
    def name(self) -> str:
        return f"visibility {self.scene}: {self.config}"

    @property
    def shadows_drawn(self) -> str:
        """'on', 'off', or under how many of the maps the shadow map was drawn."""
        n = sum(1 for c in self.cases if c[3])
        return "off" if n == 0 else "on" if n == len(self.cases) else f"{n}/{len(self.cases)} maps"

    def over_maps(self, column: int, reduce=np.mean, excluded=()) -> float:
        """``reduce`` of a case column (1: the error, 2: the reference's noise) over the maps whose
        names hold none of ``excluded``; NaN where none is left."""
        c = [x[column] for x in self.cases if not any(e in x[0] for e in excluded)]
        return float(reduce(c)) if c else math.nan


def scene_meshes(names) -> dict:
    """The scenes as alight meshes (written as OBJ to a temporary folder and loaded, the way
    `alight render` would see them)."""
    from alight.accuracy.scenes import write_scene
    from alight.exchange.meshes import load_mesh

    with tempfile.TemporaryDirectory(prefix="alight-chart-scenes-") as tmp:
        return {name: load_mesh(str(write_scene(name, tmp))) for name in names}


def scene_view(mesh, name: str, width: int, height: int, config: str = "off"):
    """The scene's camera view (SCENE_VIEWS) at width x height under one configuration."""
    from alight.core.material import Material
    from alight.core.scene import Scene, orbit_camera

    centre, radius = mesh.bounding_sphere()
    orbit, elevation = SCENE_VIEWS[name]
    camera = orbit_camera(centre, radius, width / height, orbit, elevation, None, 35.0, None, corners=mesh.corners())
    occlusion, shadows = VISIBILITY_CONFIGS[config]
    return Scene(mesh=mesh, material=Material(**GREY), use_file_materials=False, camera=camera,
                 occlusion=occlusion, shadows=shadows)


def traced(mesh, name: str, radiance, settings: VisibilitySettings, seed: int) -> np.ndarray:
    from alight.accuracy.path_trace import TraceSettings, trace

    scene = scene_view(mesh, name, settings.size, settings.size)
    return trace(scene, radiance, settings.size, settings.size, TraceSettings(samples=settings.samples, seed=seed)).linear


def bake_seconds(mesh) -> float:
    """The visibility bake's wall time, traced here (no cache)."""
    from alight.core.visibility import bake_visibility

    return float(bake_visibility(mesh).seconds)


def measure_environment(renderer, maps, radiance, env_name: str, meshes: dict, results: list[VisibilityResult],
                        settings: VisibilitySettings) -> None:
    """Add each scene x configuration's error under one environment (``maps``: its bake) to
    ``results`` (one per scene x configuration, in that order)."""
    from alight.accuracy.binned import binned_relative_mae

    size = settings.size
    by_scene = {}
    for res in results:
        by_scene.setdefault(res.scene, []).append(res)
    for name, rows in by_scene.items():
        mesh = meshes[name]
        ref = traced(mesh, name, radiance, settings, REFERENCE_SEED)
        noise = binned_relative_mae(traced(mesh, name, radiance, settings, NOISE_SEED), ref, BIN)
        for res in rows:
            scene = scene_view(mesh, name, size, size, res.config)
            image = renderer.render(scene, maps, size, size, read_linear=True, read_srgb=False).linear
            res.cases.append((env_name, binned_relative_mae(image, ref, BIN), noise,
                              renderer.shadow_maps.wanted(scene, maps)))


def frame_seconds_interleaved(renderer, maps, meshes: dict, results: list[VisibilityResult], size,
                              repeats: int, env_name: str = "") -> None:
    """Each scene x configuration's steady frame (render + finish, no read-back), median over
    ``repeats`` rounds that go round all of them in turn (chart.frame_seconds_interleaved's
    reason: a burst of load falls on all alike). The first draw of each (bake, shadow map,
    programs) is left out."""
    w, h = size
    scenes = [scene_view(meshes[r.scene], r.scene, w, h, r.config) for r in results]
    for res, scene in zip(results, scenes):
        renderer.render(scene, maps, w, h, read_linear=False, read_srgb=False)
        res.baked = renderer.visibility_parts.wanted(scene.mesh, scene.occlusion)
    renderer.ctx.finish()
    times = [[] for _ in results]
    for _ in range(repeats):
        for k, scene in enumerate(scenes):
            t = time.perf_counter()
            renderer.render(scene, maps, w, h, read_linear=False, read_srgb=False)
            renderer.ctx.finish()
            times[k].append(time.perf_counter() - t)
    for res, t in zip(results, times):
        res.frame_seconds = statistics.median(t)
        res.frame_env = env_name


def new_results(settings: VisibilitySettings) -> list[VisibilityResult]:
    return [VisibilityResult(scene, config) for scene in settings.scenes for config in VISIBILITY_CONFIGS]


def add_bake_seconds(meshes: dict, results: list[VisibilityResult]) -> None:
    """The uncached bake's time on the rows that drew the bake (once per scene; the rows of a
    scene share it)."""
    seconds = {}
    for res in results:
        if res.baked:
            if res.scene not in seconds:
                seconds[res.scene] = bake_seconds(meshes[res.scene])
            res.bake_seconds = seconds[res.scene]
