"""Light through transmissive and blended parts (alight.render.visibility_parts.light_through):
the visibility bake counts a see-through part's share of a ray, the shadow maps leave out parts
that let most light through (and say so), and the path tracer's thin walls, which the
benchmark (benchmarks/bench_transmissive_occlusion.py) measures them against."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("embreex")

from alight.core import visibility as vis  # noqa: E402
from alight.core.mesh import FileMaterial, Mesh, MeshPart  # noqa: E402
from alight.core.scene import Camera, Display, Light, Scene  # noqa: E402
from tests.gpu import renderer  # noqa: E402

BOX_FACES = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],
             [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]


def _flat(corners, faces, name, material) -> MeshPart:
    tri = np.asarray(corners, np.float32)[np.asarray(faces)]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = tri.reshape(-1, 3)
    count = len(v)
    return MeshPart(name, v, np.repeat(n, 3, axis=0).astype(np.float32), np.zeros((count, 2), np.float32),
                    np.tile(np.float32([1, 0, 0, 1]), (count, 1)), np.arange(count, dtype=np.uint32).reshape(-1, 3),
                    material)


def glass_over_floor(transmission: float) -> Mesh:
    """A 4 x 4 floor and a 1.2 x 0.2 x 1.2 slab 0.4 above it with the given transmission."""
    floor = FileMaterial(base_color=(0.7, 0.7, 0.7), metallic=0.0, roughness=0.5, name="floor")
    glass = FileMaterial(base_color=(1.0, 1.0, 1.0), metallic=0.0, roughness=0.2, name="glass",
                         layers={"transmission": transmission} if transmission else {})
    lo, hi = (-0.6, 0.4, -0.6), (0.6, 0.6, 0.6)
    box = [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    plane = _flat([[-2, 0, -2], [2, 0, -2], [2, 0, 2], [-2, 0, 2]], [[0, 2, 1], [0, 3, 2]], "floor", floor)
    return Mesh([plane, _flat(box, BOX_FACES, "glass", glass)], "glass_over_floor")


def _floor_visibility_under_the_slab(light_through) -> float:
    baked = vis.bake_visibility(glass_over_floor(0.9), rays=256, light_through=light_through)
    part = baked.parts[0]
    under = (np.abs(part.positions[:, 0]) < 0.3) & (np.abs(part.positions[:, 2]) < 0.3)
    assert under.sum() >= 3
    return float(part.visibility[under].mean())


def test_the_bake_lets_a_see_through_part_pass_its_share():
    from alight.render.visibility_parts import light_through

    scene = Scene(mesh=glass_over_floor(0.9))
    through = light_through(scene)
    assert through == pytest.approx((0.0, 0.9))
    assert light_through(Scene(mesh=glass_over_floor(0.0))) is None
    opaque = _floor_visibility_under_the_slab(None)
    clear = _floor_visibility_under_the_slab(through)
    assert opaque < 0.4          # the slab hides most of the sky right under it
    # a ray into the slab counts 0.9 of a free one: V = 1 - 0.1 (1 - V_opaque), within the noise
    assert clear == pytest.approx(1.0 - 0.1 * (1.0 - opaque), abs=0.03)
    # and the key differs, so an opaque bake is never reused for it
    m = glass_over_floor(0.9)
    assert vis.visibility_key(m, 192, 0.02, 1000, through)[0] != vis.visibility_key(m, 192, 0.02, 1000)[0]
    assert vis.visibility_key(m, 192, 0.02, 1000, (0.0, 0.0))[0] == vis.visibility_key(m, 192, 0.02, 1000)[0]


def _floor_under_light(transmission: float) -> tuple[float, float]:
    """Mean radiance of the floor in the slab's shadow and far from it, seen from straight above
    under a directional light 45 degrees from the vertical (the shadow falls beside the slab)."""
    scene = Scene(mesh=glass_over_floor(transmission), ibl_enabled=False, occlusion="off",
                  lights=[Light(kind="directional", vector=(0.0, -1.0, 1.0), intensity=3.0)],
                  camera=Camera(position=(0.0, 10.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0),
                                ortho_half_height=2.0, near=1.0, far=20.0),
                  display=Display(background="color"))
    img = renderer().render(scene, None, 64, 64).linear[..., :3].mean(axis=2)
    c = (np.arange(64) + 0.5) / 64 * 4.0 - 2.0
    x, z = np.meshgrid(c, c)
    shadow = (np.abs(x) < 0.4) & (z > 0.55) & (z < 0.9)      # the slab's shadow: 0.4-0.6 up, moved by +z
    far = (np.abs(x) > 1.2) & (np.abs(z) > 1.2)
    return float(img[shadow].mean()), float(img[far].mean())


def test_a_clear_part_casts_no_shadow_map_and_says_so():
    from tests.warned import alight_warnings

    with alight_warnings() as said:
        dark, lit = _floor_under_light(0.0)
    assert dark < 0.2 * lit          # opaque: the slab's shadow
    assert not [x for x in said if "cast no shadow" in x], said
    with alight_warnings() as said:
        through, lit = _floor_under_light(0.9)
    assert through == pytest.approx(lit, rel=0.02)
    err = "\n".join(said)
    assert err.count("glass cast no shadow") == 1 and "transmission" in err


def test_path_tracer_thin_walls_carry_their_share():
    from alight.accuracy.path_trace import _Rays, scene_geometry

    geom, _ = scene_geometry(Scene(mesh=glass_over_floor(0.5)))
    rays = _Rays(geom)
    through = geom.table["through"][geom.material]
    origins = np.array([[0.0, 0.01, 0.0], [1.5, 0.01, 1.5]])
    up = np.array([[0.0, 1.0, 0.0]] * 2)
    seen = rays.transmittance(origins, up, np.full(2, np.inf), through, 1e-5)
    assert seen == pytest.approx([0.25, 1.0])     # two walls of 0.5 over the first point, none over the second
