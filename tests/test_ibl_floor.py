"""A flat floor and oblique views under the default IBL model, against the exact reference
(alight reference --integrator exact: the texel sum of docs/conventions.md's BRDF), rendered on
the GPU as `alight render` draws them (benchmarks/results/oblique_ibl.md holds every model, map and
elevation).

What is expected, and why:
- Rough gold (r 0.7) on the built-in plane under royal_esplanade: the round prefiltered lobe at
  the lobe's mean direction (`alight`) made the floor 21-33% off from 10, 30 and 60 degrees of
  elevation (too bright toward the horizon, too dark under the camera): the real lobe seen
  obliquely is narrower across the plane of incidence and reaches further toward n. The default
  (`stretched`: two round fetches fitted to the real lobe) is within 6%.
- At r 0.3 the two fetches drew a ghost on the floor from 60 degrees (21.7% where one fetch read
  2.2%, the lecture 4.5%). It was two cells of the lobe table whose far fetch of 1% weight the
  bilinear lookup carried into the next cell's 12-28% weight; with them set by hand the two
  fetches read 3.4% there (benchmarks/results/stretched_pair_from_r02.md). The bound is the
  ghost's: a fetch that draws a bright feature twice is many times the single fetch's error and
  above the lecture's; the pair's own lobe is allowed up to twice the single fetch.
"""

from dataclasses import replace

import numpy as np
import pytest

from alight.accuracy.binned import binned_relative_mae
from alight.accuracy.reference import ReferenceRenderer
from alight.core.ibl_models import DEFAULT_IBL_MODEL
from alight.core.scene import Scene, orbit_camera
from alight.exchange.meshes import load_mesh
from alight.exchange.presets import load_preset
from alight.ibl.bake import quality_named
from alight.ibl.environment import load_environment

SIZE = 32
_state: dict = {}


def _setup(shared_data):
    if not _state:
        from tests.gpu import renderer

        r = renderer()
        env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
        _state.update(r=r, env=env, maps=r.bake(env, quality_named("medium")), exact=ReferenceRenderer(r),
                      plane=load_mesh("plane"))
    return _state


def floor_error(shared_data, roughness: float, elevation: float, model: str) -> float:
    s = _setup(shared_data)
    mesh = s["plane"]
    centre, radius = mesh.bounding_sphere()
    camera = orbit_camera(centre, radius, 1.0, 0.0, elevation, None, 35.0, None, corners=mesh.corners())
    scene = Scene(mesh=mesh, material=replace(load_preset("gold"), roughness=roughness), camera=camera,
                  view="camera", ibl_model=model)
    exact = s["exact"].render(scene, s["env"].radiance, SIZE, SIZE).linear
    image = s["r"].render(scene, s["maps"], SIZE, SIZE, aa="none", read_linear=True, read_srgb=False).linear
    assert (exact[..., 3] > 0).sum() > 50, "the floor must cover part of the image"
    return binned_relative_mae(image, exact, 1)


def test_the_default_is_the_stretched_lobe():
    assert DEFAULT_IBL_MODEL == "stretched"


@pytest.mark.parametrize("elevation", [10.0, 30.0, 60.0])
def test_a_rough_gold_floor_is_within_ten_percent(shared_data, elevation):
    default = floor_error(shared_data, 0.7, elevation, DEFAULT_IBL_MODEL)
    round_lobe = floor_error(shared_data, 0.7, elevation, "alight")
    print(f"elevation {elevation:g}: default {100 * default:.1f}%, alight {100 * round_lobe:.1f}%")
    assert default < 0.10
    assert round_lobe > 0.15      # what the round lobe left (so the floor tests the lobe's shape)


def test_no_ghost_of_a_lamp_at_low_roughness(shared_data):
    default = floor_error(shared_data, 0.3, 60.0, DEFAULT_IBL_MODEL)
    single = floor_error(shared_data, 0.3, 60.0, "alight")
    lecture = floor_error(shared_data, 0.3, 60.0, "lecture")
    print(f"r 0.3 from 60 degrees: default {100 * default:.1f}%, single fetch {100 * single:.1f}%, "
          f"lecture {100 * lecture:.1f}%")
    assert default < 2.0 * single + 0.005
    assert default < lecture
