"""The anisotropic filtering level chosen per view (alight.core.texture_footprint): 1 where a
texture is seen face-on or magnified, 8 for a floor at a grazing angle, and the footprint
axes against a closed form."""

import math

import numpy as np

from alight.core.mesh import plane
from alight.core.scene import Camera
from alight.core.texture_footprint import anisotropy_for_view, footprints


def _floor(tiles: int = 64):
    """The built-in plane (XZ, 2 x 2) subdivided into tiles x tiles quads, uvs 0..1."""
    n = tiles + 1
    x, z = np.meshgrid(np.linspace(-1, 1, n), np.linspace(1, -1, n))
    positions = np.stack([x, np.zeros_like(x), z], -1).reshape(-1, 3)
    uvs = np.stack([(x + 1) / 2, (1 - z) / 2], -1).reshape(-1, 2)
    i = np.arange(tiles)
    a = (i[:, None] * n + i[None, :]).ravel()
    faces = np.concatenate([np.stack([a, a + 1, a + n + 1], 1), np.stack([a, a + n + 1, a + n], 1)])
    return positions, uvs, faces


def _level(camera: Camera, size: int, texture: int) -> float:
    positions, uvs, faces = _floor()
    vp = camera.view_projection(1.0)
    return anisotropy_for_view(*footprints(positions, uvs, faces, vp, (size, size), (texture, texture)))


def test_face_on_is_isotropic():
    assert _level(Camera(position=(0.0, 4.0, 0.0001), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0)), 256, 4096) == 1.0


def test_grazing_floor_gets_the_most():
    assert _level(Camera(position=(0.0, 0.15, 3.0), target=(0.0, 0.0, 0.0)), 256, 4096) == 8.0


def test_magnified_texture_needs_none():
    """Seen 20 degrees above the horizon a 4096-texel texture is minified and slanted about 3:1,
    a 16-texel one magnified everywhere: the slant alone asks for nothing."""
    camera = Camera(position=(0.0, 3.0 * math.sin(math.radians(20)), 3.0 * math.cos(math.radians(20))))
    assert _level(camera, 256, 4096) == 2.0
    assert _level(camera, 256, 16) == 1.0


def test_footprint_of_a_slanted_plane_in_closed_form():
    """An orthographic view of the plane tilted by t about X: a pixel covers 1/cos(t) more of
    the texture along v than along u, so p_max / p_min = 1 / cos(t)."""
    part = plane().parts[0]
    t = math.radians(70.0)
    camera = Camera(position=(0.0, 5.0 * math.cos(t), 5.0 * math.sin(t)), target=(0.0, 0.0, 0.0),
                    ortho_half_height=1.0)
    area, p_max, p_min = footprints(part.positions, part.uvs, part.indices, camera.view_projection(1.0),
                                    (128, 128), (1024, 1024))
    assert len(area) == 2
    np.testing.assert_allclose(p_max / p_min, 1.0 / math.cos(t), rtol=1e-4)
    np.testing.assert_allclose(p_min, 1024 / 2 / 64, rtol=1e-4)   # 2 world units = 1024 texels over 128 px
