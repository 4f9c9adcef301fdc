"""The equirectangular mapping, the environment rotation and the probe view against docs/conventions.md,
in numpy and through the whole GPU path (bake -> cube -> forward pass -> read-back)."""

import numpy as np
import pytest

from alight.core import shading
from alight.core.material import Material
from alight.core.scene import Display, Scene
from alight.ibl.environment import Environment
from tests.gpu import renderer


def test_equirect_landmarks():
    uv = shading.direction_to_equirect_uv
    np.testing.assert_allclose(uv([0, 0, -1]), [0.5, 0.5])       # image centre is -Z
    np.testing.assert_allclose(uv([1, 0, 0]), [0.75, 0.5])       # u = 0.75 is +X
    np.testing.assert_allclose(uv([-1, 0, 0]), [0.25, 0.5])
    assert uv([0, 1, 0])[1] == 0.0 and uv([0, -1, 0])[1] == 1.0  # top row straight up
    assert uv([1e-9, 0, 1])[0] == pytest.approx(1.0, abs=1e-6)    # +Z is the seam at the edges
    assert uv([-1e-9, 0, 1])[0] == pytest.approx(0.0, abs=1e-6)


def test_texel_solid_angles_cover_the_sphere():
    dirs, omega = shading.texel_directions(256, 512)
    assert omega.sum() == pytest.approx(4 * np.pi, rel=1e-5)
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=-1), 1.0, atol=1e-12)
    # Pixel (col, row) covers (2 pi / W)(pi / H) sin(theta) of the row centre.
    theta = (10 + 0.5) / 256 * np.pi
    assert omega[10, 3] == pytest.approx((2 * np.pi / 512) * (np.pi / 256) * np.sin(theta))


def test_rotation_carries_map_x_to_world_minus_z():
    # +90 degrees carries the map's +X direction to world -Z: so world -Z reads the map's +X.
    np.testing.assert_allclose(shading.rotate_world_to_map([0, 0, -1], 90.0), [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(shading.rotate_world_to_map([0, 1, 0], 37.0), [0, 1, 0], atol=1e-12)


def test_probe_normals_formula():
    w = 8
    n, inside = shading.probe_normals(w)
    i, j = 5, 2
    x, y = 2 * (i + 0.5) / w - 1, 1 - 2 * (j + 0.5) / w
    np.testing.assert_allclose(n[j, i], [x, y, np.sqrt(1 - x * x - y * y)])
    assert inside[j, i] and not inside[0, 0]
    assert inside.sum() == sum((2 * (a + 0.5) / w - 1) ** 2 + (1 - 2 * (b + 0.5) / w) ** 2 < 1
                               for a in range(w) for b in range(w))


def direction_coded_environment(width=512) -> Environment:
    """Radiance that encodes its own direction smoothly: L(d) = 1.5 + d (per channel)."""
    dirs, _ = shading.texel_directions(width // 2, width)
    return Environment(radiance=(1.5 + dirs).astype(np.float32), name="direction-coded", warnings=[])


MIRROR = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0)


@pytest.mark.parametrize("rotation", [0.0, 90.0, -35.0])
def test_probe_mirror_reflects_the_environment_at_r(rotation):
    """A perfect mirror (F0 = 1, r = 0) shows L(R) with R = reflect(-v, n): this checks the probe
    normals, v = +Z, the equirect mapping through the bake, and the rotation, end to end."""
    r = renderer()
    env = direction_coded_environment()
    maps = r.bake(env, "medium")
    w = 64
    frame = r.render(Scene(material=MIRROR, view="probe", env_rotation_deg=rotation), maps, w, w)
    n, inside = shading.probe_normals(w)
    np.testing.assert_array_equal(frame.linear[..., 3] == 1.0, inside)  # alpha is the disk exactly
    v = np.array([0.0, 0.0, 1.0])
    reflected = shading.reflect(-v, n)
    expected = 1.5 + shading.rotate_world_to_map(reflected, rotation)
    # Away from grazing, where the LUT's A + B is 1 to within 1e-3 for r -> 0.
    ok = inside & (n[..., 2] > 0.3)
    err = np.abs(frame.linear[..., :3][ok] - expected[ok])
    assert err.max() < 0.01, err.max()   # cube sampling of a smooth function at 256^2 faces


def test_camera_view_centre_looks_at_minus_z():
    r = renderer()
    maps = r.bake(direction_coded_environment(), "low")
    frame = r.render(Scene(mesh=None, display=Display(background="env")), maps, 33, 33, aa="none")
    np.testing.assert_allclose(frame.linear[16, 16, :3], [1.5, 1.5, 0.5], atol=0.01)
    assert frame.linear[16, 16, 3] == 0.0                 # background: alpha 0
    top = frame.linear[0, 16, :3]
    assert top[1] > 1.5                                   # rows go up: the top edge looks above the horizon
