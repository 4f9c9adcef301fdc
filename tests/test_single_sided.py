"""Single-sided glTF parts (material doubleSided false) are one-way for light, as the camera pass
draws them (alight.core.mesh.single_sided): a wall behind a quad that faces away from the camera
and from the light, rendered with shadow maps and the occlusion bake on (and path traced), is
the wall without the quad; the same quad marked doubleSided shadows and occludes it.

The files are written here (tests/gltf_builder.py): one with the wall only, one with the wall and
the quad, one with the quad doubleSided."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("embreex", reason="the occlusion bake and the path tracer need embreex")

from alight.core import visibility as vis  # noqa: E402
from alight.core.material import Material  # noqa: E402
from alight.core.mesh import single_sided  # noqa: E402
from alight.core.scene import Camera, Light, Scene  # noqa: E402
from alight.exchange.meshes import load_mesh  # noqa: E402
from alight.ibl.environment import studio_environment  # noqa: E402

from gltf_builder import Gltf  # noqa: E402
from gpu import renderer  # noqa: E402

SIZE = 96
CAMERA = Camera(position=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0))
# From behind the camera and from its right: the quad's shadow falls left of the quad, partly
# where the camera sees the wall past the quad's edge.
LIGHT = Light(kind="directional", vector=tuple(np.array([-1.0, 0.0, -1.0]) / np.sqrt(2.0)), intensity=3.0)


def _quad(half: float, z: float, facing: float):
    """A square of side 2 ``half`` at depth ``z``, its front (counter-clockwise winding, normal)
    toward +Z (``facing`` 1) or -Z (-1): positions, normals, indices."""
    p = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]], np.float32)
    idx = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    if facing < 0:
        idx = idx[:, ::-1].copy()
    n = np.tile(np.float32([0.0, 0.0, facing]), (4, 1))
    return p, n, idx


def _write(path, quad: str | None):
    """The wall (4 x 4 at z = 0 facing the camera), and with ``quad`` 'single' or 'double' a 1 x 1
    quad at z = 0.5 facing the wall (away from the camera and the light)."""
    g = Gltf()
    grey = g.material(pbrMetallicRoughness={"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0,
                                            "roughnessFactor": 0.6})
    pieces = [(_quad(2.0, 0.0, 1.0), grey)]
    if quad is not None:
        m = g.material(pbrMetallicRoughness={"baseColorFactor": [0.8, 0.2, 0.2, 1.0], "metallicFactor": 0.0,
                                             "roughnessFactor": 0.6}, doubleSided=quad == "double")
        pieces.append((_quad(0.5, 0.5, -1.0), m))
    for (p, n, idx), m in pieces:
        g.mesh([{"attributes": {"POSITION": g.accessor(p, bounds=True), "NORMAL": g.accessor(n)},
                 "indices": g.accessor(idx.reshape(-1), component=5125), "material": m}])
    return g.save(path)


@pytest.fixture(scope="module")
def meshes(tmp_path_factory):
    d = tmp_path_factory.mktemp("single_sided")
    return {k: load_mesh(str(_write(d / f"{k}.glb", None if k == "none" else k))) for k in ("none", "single", "double")}


def _render(mesh, shadows="on", occlusion="on", maps=None):
    scene = Scene(mesh=mesh, camera=CAMERA, lights=[LIGHT], shadows=shadows, occlusion=occlusion,
                  material=Material(base_color=(0.8, 0.8, 0.8), roughness=0.6))
    return renderer().render(scene, maps, SIZE, SIZE, aa="none", read_linear=True, read_srgb=False).linear[..., :3]


def test_the_files_say_which_part_is_single_sided(meshes):
    assert [single_sided(p) for p in meshes["single"].parts] == [True, True]
    assert [single_sided(p) for p in meshes["double"].parts] == [True, False]


def test_bake_lets_light_through_a_single_sided_quad_from_its_back(tmp_path):
    """The wall's rays toward the quad meet its front (light coming back meets its back): V of
    the wall's vertices under the quad is the bare wall's; doubleSided, the quad occludes them."""
    def wall_v(path):
        part = vis.bake_visibility(load_mesh(str(path)), rays=64).parts[0]
        under = (np.abs(part.positions[:, 0]) < 0.4) & (np.abs(part.positions[:, 1]) < 0.4)
        assert under.any()
        return float(part.visibility[under].mean())
    single = wall_v(_write(tmp_path / "s.glb", "single"))
    double = wall_v(_write(tmp_path / "d.glb", "double"))
    assert single > 0.99, single
    assert double < 0.8, double


def _footprint(a, b):
    """Where two pictures differ, grown by a pixel."""
    f = np.abs(a - b).max(axis=-1) > 1e-4
    return f | np.roll(f, 1, 0) | np.roll(f, -1, 0) | np.roll(f, 1, 1) | np.roll(f, -1, 1)


def _darker(a, b):
    """Where ``b`` is darker than ``a`` by more than a tenth."""
    return (a - b).mean(axis=-1) > 0.1 * a.mean(axis=-1)


def test_single_sided_quad_facing_away_is_the_wall_without_it(meshes):
    maps = renderer().bake(studio_environment(256), "low")
    none = _render(meshes["none"], maps=maps)
    single = _render(meshes["single"], maps=maps)
    assert none.mean() > 0.05
    # Shadows and occlusion on: the single-sided quad changes nothing.
    diff = np.abs(single - none).max(axis=-1)
    assert float(diff.mean() / none.mean()) < 0.01, float(diff.mean() / none.mean())
    assert float(np.quantile(diff, 0.99)) < 0.03 * float(none.max()), float(np.quantile(diff, 0.99))
    # The double-sided quad darkens the wall where the camera sees it past the quad (outside its
    # footprint: where it changes the picture with neither shadows nor occlusion).
    footprint = _footprint(_render(meshes["double"], "off", "off", maps), _render(meshes["none"], "off", "off", maps))
    double = _render(meshes["double"], maps=maps)
    assert (_darker(none, double) & ~footprint).sum() > 150
    # ... by its shadow, left of it (the light comes from the right) ...
    shadowed = _darker(_render(meshes["none"], "on", "off", maps),
                       _render(meshes["double"], "on", "off", maps)) & ~footprint
    assert shadowed.sum() > 100 and np.median(np.nonzero(shadowed)[1]) < SIZE / 2, int(shadowed.sum())
    np.testing.assert_allclose(_render(meshes["single"], "on", "off", maps), _render(meshes["none"], "on", "off", maps),
                               atol=0.02 * float(none.max()))
    # ... and by occlusion
    occluded = _darker(_render(meshes["none"], "off", "on", maps),
                       _render(meshes["double"], "off", "on", maps)) & ~footprint
    assert occluded.sum() > 50, int(occluded.sum())


def test_path_tracer_lets_light_through_a_single_sided_quad_from_its_back(meshes):
    from alight.accuracy.path_trace import TraceSettings, trace

    radiance = np.full((16, 32, 3), 0.5, np.float32)

    def traced(mesh, visibility=True):
        scene = Scene(mesh=mesh, camera=CAMERA, lights=[LIGHT],
                      material=Material(base_color=(0.8, 0.8, 0.8), roughness=0.6))
        return trace(scene, radiance, 32, 32, TraceSettings(samples=16, max_bounces=2, seed=0, jitter=False,
                                                            visibility=visibility)).linear[..., :3]

    none, single, double = (traced(meshes[k]) for k in ("none", "single", "double"))
    assert float(np.abs(single - none).mean() / none.mean()) < 0.03
    footprint = np.abs(traced(meshes["double"], False) - traced(meshes["none"], False)).max(axis=-1) > 0.05 * none.max()
    footprint |= np.roll(footprint, 1, 0) | np.roll(footprint, -1, 0) | np.roll(footprint, 1, 1)
    footprint |= np.roll(footprint, -1, 1)
    darker = ((none - double).mean(axis=-1) > 0.15 * none.mean(axis=-1)) & ~footprint
    assert darker.sum() > 15, int(darker.sum())
