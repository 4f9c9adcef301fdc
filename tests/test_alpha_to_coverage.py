"""alphaMode MASK under MSAA is antialiased as a triangle's edge is (sharpened alpha to coverage,
common/mesh_material.glsl alpha_coverage_mask), by equivalence: a square whose base colour
texture's alpha is 0 on its right half (cutoff 0.5) renders like a control file holding only the
left half as geometry, through the forward pass and the visibility buffer alike; without MSAA
the plain test. Both files are written here (tests/gltf_builder.py)."""

from __future__ import annotations

import numpy as np
import pytest

from alight.core.scene import Camera, Light, Scene
from alight.exchange.meshes import load_mesh

from gltf_builder import Gltf
from gpu import renderer

SIZE = 64
# Turned a little about the view axis, so the cut crosses pixel rows at a slant (the stair steps
# an unfiltered alpha test leaves).
CAMERA = Camera(position=(0.3, 0.1, 3.0), target=(0.0, 0.0, 0.0), up=(0.2, 1.0, 0.0))


def _write(path, masked: bool):
    g = Gltf()
    x1 = 1.0 if masked else 0.0   # the control: the left half only, as geometry
    u1 = 1.0 if masked else 0.5
    # The control's bounds are the square's too (a degenerate triangle at its far corners, which
    # covers no pixel), so both files are placed alike.
    p = np.array([[-1, -1, 0], [x1, -1, 0], [x1, 1, 0], [-1, 1, 0], [1, 1, 0], [1, -1, 0]], np.float32)
    uv = np.array([[0, 1], [u1, 1], [u1, 0], [0, 0], [1, 0], [1, 1]], np.float32)   # glTF: v down
    n = np.tile(np.float32([0, 0, 1]), (6, 1))
    idx = np.array([0, 1, 2, 0, 2, 3] + ([] if masked else [4, 5, 5]), np.uint32)
    image = np.full((16, 16, 4), 255, np.uint8)
    image[:, :, :3] = (220, 120, 40)
    image[:, 8:, 3] = 0   # linear filtering: alpha 0.5 exactly at u = 0.5
    tex = g.image(image, sampler={"magFilter": 9729, "minFilter": 9729, "wrapS": 33071, "wrapT": 33071})
    fields = {"pbrMetallicRoughness": {"baseColorTexture": {"index": tex}, "metallicFactor": 0.0,
                                       "roughnessFactor": 0.5}, "doubleSided": True}
    if masked:
        fields.update(alphaMode="MASK", alphaCutoff=0.5)
    m = g.material(**fields)
    g.mesh([{"attributes": {"POSITION": g.accessor(p, bounds=True), "NORMAL": g.accessor(n),
                            "TEXCOORD_0": g.accessor(uv)},
             "indices": g.accessor(idx, component=5125), "material": m}])
    return g.save(path)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("a2c")
    return load_mesh(str(_write(d / "masked.glb", True))), load_mesh(str(_write(d / "control.glb", False)))


def _render(mesh, aa: str, shading: str = "forward") -> np.ndarray:
    r = renderer()
    r.mesh_shading = shading
    try:
        scene = Scene(mesh=mesh, camera=CAMERA, shadows="off", occlusion="off",
                      lights=[Light(kind="directional", vector=(0.0, 0.0, -1.0), intensity=3.0)])
        return r.render(scene, None, SIZE, SIZE, aa=aa, read_linear=True, read_srgb=False).linear[..., :3]
    finally:
        r.mesh_shading = "auto"


@pytest.mark.parametrize("shading", ["forward", "vbuffer"])
def test_a_masked_cut_under_msaa_renders_as_the_geometric_cut(files, shading):
    """Along the cut each pixel keeps the control's coverage to within one of its 4 samples
    (measured: at most 0.251 of the colour; the plain per-pixel test, 0 or 1 against MSAA's
    quarters, left 24 of the cut's pixels more than a third off and one 0.50 off)."""
    masked, control = files
    m, c = _render(masked, "msaa", shading), _render(control, "msaa", shading)
    full = float(c.max())
    difference = np.abs(m - c).max(axis=-1) / full
    assert m.mean() > 0.05   # lit
    assert difference.max() <= 0.26, difference.max()
    assert (difference > 1.0 / 3.0).sum() == 0


def test_without_msaa_the_plain_alpha_test(files):
    masked, control = files
    m, c = _render(masked, "none"), _render(control, "none")
    assert m.mean() > 0.05   # lit
    # The same cut, whole pixels on either side: a pixel differs only where its centre is within
    # the texel interpolation's rounding of the cut.
    assert (np.abs(m - c).max(axis=-1) > 0.05).sum() <= 3
