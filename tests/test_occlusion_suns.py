"""The suns' light on the occluders (alight.core.visibility.bake_sun_bounce): a wall lit only by a
box's sunlit side under a map whose light is all in one compact source, against the path
tracer; the shader's term against its numpy twin; the pass cached beside the bake and rerun
(alone) when the suns move."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("embreex")
trimesh = pytest.importorskip("trimesh")

from alight.core import visibility as vis  # noqa: E402
from alight.core.material import Material  # noqa: E402
from alight.core.scene import Camera, Scene  # noqa: E402
from alight.core.shading import equirect_uv_to_direction  # noqa: E402
from alight.exchange.meshes import load_mesh  # noqa: E402
from alight.ibl.environment import Environment  # noqa: E402
from tests.gpu import evaluate, renderer  # noqa: E402
from tests.test_occlusion import _box_quads, _flat_obj, _quad  # noqa: E402

SUN = np.array([0.0, 2.0, -1.0]) / np.sqrt(5.0)    # 63 degrees up, behind the box: over the wall


def _sun_only_map(direction, radiance: float = 2000.0, height: int = 128) -> Environment:
    """Black but for a disk 1.5 degrees wide around ``direction`` (app/ibl/sun.py takes it out)."""
    rows = (np.arange(height) + 0.5) / height
    cols = (np.arange(2 * height) + 0.5) / (2 * height)
    dirs = equirect_uv_to_direction(np.stack(np.meshgrid(cols, rows), axis=-1))
    disk = dirs @ direction > np.cos(np.radians(1.5))
    rad = np.zeros((height, 2 * height, 3), np.float32)
    rad[disk] = radiance
    return Environment(rad, "sun-only")


@pytest.fixture(scope="module")
def wall_and_box(tmp_path_factory):
    """A wall z = -1 (0.8 high, facing +Z) and a box 0.3 in front of it, 0.6 high, with no floor.
    The sun is behind the box, so the wall's face and the box's front see it edge-on or not at all:
    what lights the wall is the box's sunlit back."""
    quads = [_quad((-1, 0, -1), (1, 0, -1), (1, 0.8, -1), (-1, 0.8, -1)),
             *_box_quads((-0.3, 0.0, -0.7), (0.3, 0.6, -0.3))]
    return load_mesh(str(_flat_obj(quads, tmp_path_factory.mktemp("wall") / "wall_box.obj")))


def test_the_wall_gets_the_sunlit_box_side_as_the_path_tracer_does(wall_and_box):
    """Seen from the front (orthographic), the wall beside the box against the path tracer
    (binned relMAE): with the suns' light on the occluders it is within 25%; without it (the
    render before: the bounce saw the map without its sun, black) the wall was black, 100% off."""
    from alight.accuracy.binned import binned_relative_mae
    from alight.accuracy.path_trace import TraceSettings, trace

    env = _sun_only_map(SUN)
    r = renderer()
    maps = r.bake(env, "low")
    assert len(maps.suns) == 1 and maps.suns[0].fraction > 0.99
    camera = Camera(position=(0.0, 0.4, 4.0), target=(0.0, 0.4, -1.0), up=(0.0, 1.0, 0.0), near=1.0, far=10.0,
                    ortho_half_height=0.5)
    material = Material(base_color=(0.8, 0.8, 0.8), metallic=0.0, roughness=1.0)
    scene = Scene(mesh=wall_and_box, material=material, camera=camera, occlusion="on")
    size = 64
    ref = trace(scene, env.radiance, size, size, TraceSettings(samples=256, seed=0, max_bounces=4)).linear
    images = {}
    for sun_bounce in (False, True):
        r.visibility_parts.sun_bounce = sun_bounce
        images[sun_bounce] = r.render(scene, maps, size, size, read_linear=True, read_srgb=False).linear
    r.visibility_parts.sun_bounce = True
    # The wall's blocks: the columns left and right of the box (x beyond +-0.35 of the 0.5 half width).
    cols = (np.arange(size // 4) + 0.5) * 4 / size * 2.0 - 1.0      # -1..1 across the image
    wall = np.broadcast_to(np.abs(cols * 0.5) > 0.35, (size // 4, size // 4))
    assert ref[..., :3].mean() > 0.0
    before = binned_relative_mae(images[False], ref, 4, wall)
    after = binned_relative_mae(images[True], ref, 4, wall)
    assert before > 0.9, before
    assert after < 0.25, after


def test_the_shader_term_matches_its_numpy_twin():
    rng = np.random.default_rng(5)
    n = 300
    rows = np.column_stack([rng.uniform(0, 1, (n, 3)), rng.uniform(0, 1, n)])
    gpu = evaluate(6, rows, shader="accuracy/evaluate_occlusion.comp")[:, :3]
    np.testing.assert_allclose(gpu, vis.suns_on_occluders(rows[:, :3], rows[:, 3], np.ones((n, 3)), np.ones((n, 3))),
                               rtol=1e-4, atol=1e-5)


def test_the_sun_pass_is_cached_and_rerun_alone_when_the_suns_move(wall_and_box, tmp_path):
    from alight.ibl.bake_cache import BakeCache
    from alight.render.visibility_parts import cached_sun_bounce, cached_visibility

    cache = BakeCache(tmp_path / "cache")
    baked = cached_visibility(wall_and_box, cache, rays=32)
    first, loaded_first = cached_sun_bounce(wall_and_box, baked, SUN[None], cache, rays=32)
    second, loaded_second = cached_sun_bounce(wall_and_box, baked, SUN[None], cache, rays=32)
    assert not loaded_first and loaded_second
    for a, b in zip(first, second):
        np.testing.assert_array_equal(a, b)
    # The box's back (which faces the wall) is sunlit: the wall's vertices see it.
    wall_values = first[0][np.abs(baked.parts[0].positions[:, 2] + 1.0) < 1e-6]
    assert wall_values[:, 0].max() > 0.05
    moved = SUN * np.array([-1.0, 1.0, -1.0])                  # the sun in front: another key
    _, loaded_moved = cached_sun_bounce(wall_and_box, baked, moved[None], cache, rays=32)
    assert not loaded_moved
    assert cached_visibility(wall_and_box, cache, rays=32).from_cache    # the bake itself is kept
    cache.close()
