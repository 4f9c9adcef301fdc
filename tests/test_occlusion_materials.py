"""What the occluded directions see is the occluders' own material (alight.core.visibility.
bake_occluder_materials; occlusion.glsl's recorded_occluder_albedo): a grey floor beside a red box
is lit red by it, no brighter than the open sky, and an emissive box brightens the floor beside
it. Before, every occluder was taken to be the shaded surface's own material (one material per
scene): OrientationTest's grey box lent its light albedo to the red arrows on it (a bluish-white
halo where the path tracer has a faint red glow), and emissive parts lit nothing. The new terms
against their numpy twins, and the pass's cache."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("embreex")

from alight.core import visibility as vis  # noqa: E402
from alight.core.mesh import FileMaterial, Mesh  # noqa: E402
from alight.core.scene import Camera, Scene  # noqa: E402
from alight.ibl.environment import constant_environment  # noqa: E402
from tests.gpu import evaluate, renderer  # noqa: E402
from tests.quad_meshes import box_quads, quad_part  # noqa: E402

GREY = 0.7
RED = (0.8, 0.05, 0.05)
BOX = ((-0.3, 0.0, -0.3), (0.3, 0.6, 0.3))


def _floor_and_box(box: FileMaterial) -> Mesh:
    """A grey floor y = 0 over [-1, 1]^2 (diffuse, albedo GREY) and a box of material ``box`` in
    its middle: two parts of one file, as a glTF with two materials loads."""
    floor = FileMaterial(base_color=(GREY,) * 3, metallic=0.0, roughness=1.0, specular_f0=(0.0, 0.0, 0.0))
    return Mesh([quad_part([((-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1))], "floor", floor),
                 quad_part(box_quads(*BOX), "box", box)], "floor-and-box")


def _render(mesh, mode: str, maps, size: int = 96) -> np.ndarray:
    """Straight down, orthographic, over the floor (row 0 at -z)."""
    camera = Camera(position=(0.0, 5.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0), near=1.0, far=10.0,
                    ortho_half_height=1.0)
    scene = Scene(mesh=mesh, camera=camera, occlusion=mode)
    return renderer().render(scene, maps, size, size, aa="none", read_linear=True, read_srgb=False).linear


def _beside_box(size: int = 96) -> np.ndarray:
    """(size, size) bool: the floor within 0.15 of the box's sides (not under or on it)."""
    j, i = np.mgrid[0:size, 0:size]
    x = 2.0 * (i + 0.5) / size - 1.0
    z = 2.0 * (j + 0.5) / size - 1.0
    d = np.maximum(np.abs(x), np.abs(z))
    return (d > 0.33) & (d < 0.45)


def test_the_floor_beside_a_red_box_is_lit_red_and_no_brighter_than_the_sky():
    """Under a uniform white sky (E/pi = 1) nothing the floor sees is brighter than the sky (every
    albedo is below 1), so with occlusion no channel may exceed the render without it (up to the
    small specular and interpolation slack, 2%); and what the box hides is red: the blue channel
    loses more than the red. Before, the blocked share was lit with the grey floor's own albedo:
    both channels lost the same."""
    r = renderer()
    maps = r.bake(constant_environment(1.0), "low")
    mesh = _floor_and_box(FileMaterial(base_color=RED, metallic=0.0, roughness=1.0))
    off, on = _render(mesh, "off", maps), _render(mesh, "on", maps)
    ring = _beside_box()
    ratio = on[ring] / off[ring]                      # (P, 3): what occlusion leaves of each channel
    assert ratio.max() < 1.02
    red, blue = ratio[:, 0].mean(), ratio[:, 2].mean()
    assert blue < 0.9                                 # the box hides a good share of the sky here
    assert red - blue > 0.05, (red, blue)
    # The red channel: the box's recorded albedo (about 0.8) through the series, the blue nearly
    # nothing: red keeps at least a third of what blue loses.
    assert (1.0 - red) < (2.0 / 3.0) * (1.0 - blue)


def test_an_emissive_box_lights_the_floor_beside_it():
    """A black box emitting radiance 2 (its factor times KHR_materials_emissive_strength, as the
    file gives it): the floor beside it gains about albedo x (1 - V) x 2 (what the box hides of
    the sky now shines instead), against the same box not emitting; the far corners, which see
    little of it, gain far less."""
    r = renderer()
    maps = r.bake(constant_environment(0.25), "low")
    dark = _render(_floor_and_box(FileMaterial(base_color=(0.0,) * 3, metallic=0.0, roughness=1.0)), "on", maps)
    lit = _render(_floor_and_box(FileMaterial(base_color=(0.0,) * 3, metallic=0.0, roughness=1.0,
                                              emissive=(2.0, 2.0, 2.0))), "on", maps)
    off = _render(_floor_and_box(FileMaterial(base_color=(0.0,) * 3, metallic=0.0, roughness=1.0)), "off", maps)
    ring = _beside_box()
    gain = (lit - dark)[ring].mean()
    hidden = 1.0 - (dark[ring] / off[ring]).mean()    # 1 - V there: a black box reflects nothing
    assert hidden > 0.1
    assert 0.6 * GREY * hidden * 2.0 < gain < 1.4 * GREY * hidden * 2.0, (gain, hidden)
    size = lit.shape[0]
    corners = np.zeros((size, size), bool)
    corners[:6, :6] = corners[:6, -6:] = corners[-6:, :6] = corners[-6:, -6:] = True
    assert (lit - dark)[corners].mean() < 0.3 * gain


def test_the_pass_records_each_hit_material_and_is_cached(tmp_path):
    """A floor vertex beside the red box records the box's albedo (red) and emission; a vertex
    whose rays hit nothing records none (w 0: the shader keeps its own albedo); the second call
    loads from the cache, a new colour is a new entry."""
    from alight.ibl.bake_cache import BakeCache
    from alight.render.visibility_parts import cached_occluder_materials, cached_visibility

    mesh = _floor_and_box(FileMaterial(base_color=RED, metallic=0.0, roughness=1.0, emissive=(0.0, 0.5, 0.0)))
    cache = BakeCache(tmp_path)
    baked = cached_visibility(mesh, cache, rays=32)
    red = (vis.OccluderMaterial((GREY,) * 3, 0.0, (0.0,) * 3), vis.OccluderMaterial(RED, 0.0, (0.04,) * 3,
                                                                                      (0.0, 0.5, 0.0)))
    values, loaded = cached_occluder_materials(mesh, baked, red, cache, rays=32)
    assert not loaded
    floor = baked.parts[0]
    near = (np.abs(floor.positions[:, 1]) < 1e-6) & (np.max(np.abs(floor.positions[:, [0, 2]]), axis=1) > 0.32) \
        & (np.max(np.abs(floor.positions[:, [0, 2]]), axis=1) < 0.4)
    assert near.any()
    v = values[0][near]
    assert (v[:, 3] == 1.0).all()
    np.testing.assert_allclose(v[:, :3], vis.occluder_base_albedo(RED, 0.0, 0.04)[None].repeat(len(v), 0), atol=1e-4)
    np.testing.assert_allclose(v[:, 4:7], [[0.0, 0.5, 0.0]] * len(v), atol=1e-5)
    assert (values[0][:, 7] <= 1.0).all() and v[:, 7].mean() > 0.1
    top = (baked.parts[1].normals[:, 1] > 0.9)        # the box's top sees only the sky
    assert (values[1][top, 3] == 0.0).all() and (values[1][top, :3] == 0.0).all()
    again, loaded = cached_occluder_materials(mesh, baked, red, cache, rays=32)
    assert loaded and all(np.array_equal(a, b) for a, b in zip(values, again))
    blue = (red[0], vis.OccluderMaterial((0.05, 0.05, 0.8), 0.0, (0.04,) * 3))
    other, loaded = cached_occluder_materials(mesh, baked, blue, cache, rays=32)
    assert not loaded and other[0][near][:, 2].mean() > other[0][near][:, 0].mean()


def test_the_material_terms_match_their_numpy_twins():
    rng = np.random.default_rng(5)
    n = 400
    rows = np.column_stack([rng.uniform(0, 1, (n, 3)), rng.uniform(0, 1, n)])
    gpu = evaluate(10, rows, shader="accuracy/evaluate_occlusion.comp")[:, :3]
    np.testing.assert_allclose(gpu, vis.occluder_base_albedo(rows[:, :3], rows[:, 3], 0.04), atol=1e-5)
    rows = np.column_stack([rng.uniform(0, 1, (n, 3)), rng.uniform(0, 2, n)])
    own, own_recorded = np.array([0.3, 0.5, 0.7]), np.array([0.25, 0.45, 0.6])
    gpu = evaluate(11, rows, shader="accuracy/evaluate_occlusion.comp")[:, :3]
    expected = vis.recorded_occluder_albedo(rows[:, 3:4] * own, own_recorded[None], rows[:, :3])
    np.testing.assert_allclose(gpu, expected, atol=1e-5)
    # The same material recorded at the hit and here gives this surface's own albedo back (grey).
    grey = np.full((1, 3), 0.55)
    mine = vis.occluder_base_albedo(grey, np.array([0.0]), 0.04)
    np.testing.assert_allclose(vis.recorded_occluder_albedo(grey * 1.07, mine, mine), grey * 1.07, rtol=1e-6)
