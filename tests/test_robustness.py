"""No NaN or Inf anywhere at the edges of the parameter space: roughness 0 and 1, metallic 0 and 1,
n.v -> 0 (the probe's rim and a sphere's silhouette), punctual lights at grazing angles, a very
bright sun, an all-black environment."""

import numpy as np
import pytest

from alight.core.material import Material
from alight.core.mesh import plane, sphere
from alight.core.scene import Light, Scene
from alight.ibl.environment import Environment, constant_environment, load_environment
from tests.gpu import renderer

LIGHTS = [Light("point", (0.0, 0.0, 1.05)), Light("point", (3.0, 0.0, 0.0), intensity=50.0),
          Light("directional", (0.0, 0.0, -1.0), intensity=5.0), Light("directional", (1.0, 0.0, -0.001))]


@pytest.fixture(scope="module")
def quarry(shared_data):
    return load_environment(str(shared_data / "env" / "quarry_01_1k.hdr"))   # sun peak 86,528


@pytest.mark.parametrize("roughness", [0.0, 1.0])
@pytest.mark.parametrize("metallic", [0.0, 1.0])
@pytest.mark.parametrize("view", ["probe", "camera"])
def test_finite_at_parameter_extremes(quarry, roughness, metallic, view):
    r = renderer()
    maps = r.bake(quarry, "low")
    m = Material(base_color=(1.0, 1.0, 1.0), metallic=metallic, roughness=roughness,
                 specular_f0=(1.0, 1.0, 1.0) if metallic == 0 else (0.04, 0.04, 0.04))
    frame = r.render(Scene(mesh=sphere(), material=m, view=view, lights=LIGHTS), maps, 96, 96)
    assert np.isfinite(frame.linear).all()
    assert frame.linear.min() >= 0.0
    if view == "probe":
        # The outermost ring of the disk has n.v -> 0: it must be finite and not black by accident.
        rim = frame.linear[48, 0:3, :3]
        assert np.isfinite(rim).all()


def test_grazing_plane_and_zero_roughness_lights():
    r = renderer()
    maps = r.bake(constant_environment(1.0, 64), "low")
    m = Material(roughness=0.0, metallic=1.0, base_color=(1.0, 1.0, 1.0))
    from alight.core.scene import Camera

    # The camera skims the plane: n.v is near 0 over most of the image.
    cam = Camera(position=(0.0, 0.01, 3.0), target=(0.0, 0.0, 0.0))
    frame = r.render(Scene(mesh=plane(), material=m, camera=cam, lights=LIGHTS), maps, 64, 64)
    assert np.isfinite(frame.linear).all()


def test_black_environment_gives_black_without_lights():
    r = renderer()
    black = Environment(radiance=np.zeros((32, 64, 3), np.float32), name="black", warnings=[])
    maps = r.bake(black, "low")
    frame = r.render(Scene(material=Material(roughness=0.5), view="probe"), maps, 32, 32)
    assert np.isfinite(frame.linear).all() and frame.linear[..., :3].max() == 0.0


def test_emissive_adds_exactly(quarry):
    r = renderer()
    black = Environment(radiance=np.zeros((32, 64, 3), np.float32), name="black", warnings=[])
    maps = r.bake(black, "low")
    frame = r.render(Scene(material=Material(emissive=(2.0, 0.5, 0.0)), view="probe"), maps, 16, 16)
    np.testing.assert_allclose(frame.linear[8, 8, :3], [2.0, 0.5, 0.0], atol=1e-6)


@pytest.mark.parametrize("mesh_name", ["sphere", "cube", "Duck.glb"])
def test_back_face_culling_changes_no_pixel(shared_data, monkeypatch, mesh_name):
    """Closed meshes are drawn with back faces culled; were any front face wound the wrong way,
    culling would remove it and the image would change."""
    import alight.render.gpu_mesh as gpu_mesh_module
    from alight.core.mesh import is_closed
    from alight.exchange.meshes import load_mesh

    def load():
        return load_mesh(str(shared_data / "models" / mesh_name) if mesh_name.endswith(".glb") else mesh_name)

    r = renderer()
    maps = r.bake(constant_environment(1.0, 64), "low")
    culled_mesh = load()
    assert all(is_closed(p.positions, p.indices) for p in culled_mesh.parts)
    culled = r.render(Scene(mesh=culled_mesh, lights=LIGHTS[:2]), maps, 96, 96, aa="none").linear
    monkeypatch.setattr(gpu_mesh_module, "is_closed", lambda *a: False)
    both_sides = r.render(Scene(mesh=load(), lights=LIGHTS[:2]), maps, 96, 96, aa="none").linear
    np.testing.assert_allclose(culled, both_sides, atol=1e-6)


def test_open_and_closed_meshes():
    from alight.core.mesh import is_closed

    assert is_closed(sphere().parts[0].positions, sphere().parts[0].indices)
    assert not is_closed(plane().parts[0].positions, plane().parts[0].indices)
    p = sphere().parts[0]
    assert not is_closed(p.positions, p.indices[1:])           # one triangle missing: a hole
    flipped = p.indices.copy()
    flipped[0] = flipped[0, ::-1]
    assert not is_closed(p.positions, flipped)                  # one triangle wound the wrong way
