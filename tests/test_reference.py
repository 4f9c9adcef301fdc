"""alight reference (app/accuracy/reference.py): docs/conventions.md's ground truth on the GPU, against analytic
values, the numpy ground truth (app/accuracy/ground_truth.py) and the real-time punctual path."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from alight.accuracy.ground_truth import (
    ground_truth_terms,
    probe_points,
    relative_error,
)
from alight.core.equirect import box_reduce
from alight.core.material import Material
from alight.core.scene import Scene, parse_light
from alight.exchange.meshes import load_mesh
from alight.ibl.environment import constant_environment, load_environment
from tests.gpu import renderer

REPO = Path(__file__).resolve().parents[1]
WHITE = dict(base_color=(1.0, 1.0, 1.0), metallic=0.0, specular_f0=(0.0, 0.0, 0.0))


@pytest.fixture(scope="module")
def ref():
    from alight.accuracy.reference import ReferenceRenderer

    return ReferenceRenderer(renderer())


@pytest.fixture(scope="module")
def royal(shared_data):
    return load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")).radiance


def _points(ref, radiance, normals, views, material, env_level=0):
    """The reference at arbitrary (n, v) pairs: a 1-row G-buffer through the same compute pass."""
    from alight.accuracy.reference import GBUFFER

    n = len(normals)
    g = {name: np.zeros((1, n, 4), np.float32) for name in GBUFFER}
    g["position"][0, :, 3] = 1.0
    g["normal"][0, :, :3] = normals
    g["normal"][0, :, 3] = material.roughness
    g["view"][0, :, :3] = views
    g["view"][0, :, 3] = material.metallic
    g["base_color"][0, :, :3] = material.base_color
    g["specular_f0"][0, :, :3] = material.specular_f0
    g["emissive"][0, :, :3] = material.emissive
    return ref.render_gbuffer(g, Scene(material=material), radiance, env_level=env_level).linear[0]


def test_white_furnace_at_normal_incidence(ref):
    # docs/conventions.md: base 1, metallic 0, specular_f0 0 under radiance 1 has albedo 0.99995 at
    # n.v = 1, r = 1. Tolerance 1e-3: the texel sum is a midpoint rule in theta, off by about
    # (pi/H)^2/24 = 1.6e-6 at H = 512, plus float32 rounding; measured 0.999953 (3e-6 off).
    # A full 1024x512 map needs 16 dispatches: llvmpipe cut a single one short at 65535 loop
    # iterations (0.012 instead of 1; app/accuracy/reference.py's MAX_TEXELS_PER_DISPATCH).
    m = Material(roughness=1.0, **WHITE)
    env = constant_environment(1.0, 1024)
    result = ref.render(Scene(material=m, view="probe"), env.radiance, 9, 9, env_level=0)
    assert result.env_size == (1024, 512) and result.dispatches > 1
    out = result.linear
    assert out[4, 4, 3] == 1.0
    np.testing.assert_allclose(out[4, 4, :3], 0.99995, atol=1e-3)
    assert out[0, 0].tolist() == [0.0, 0.0, 0.0, 0.0]   # background: radiance 0, alpha 0


def test_half_lit_environment(ref):
    # Upper hemisphere radiance 1, lower 0 (the boundary falls on a row boundary: H even). With
    # v = n the BRDF depends on l only through n.l, so the answer is the furnace albedo times the
    # lit fraction of the hemisphere: 1 (n = +Y), 1/2 (horizontal), 0 (n = -Y), times 0.99995.
    # Tolerance 1e-3 for the same midpoint-rule reason as above.
    rad = np.zeros((128, 256, 3), np.float32)
    rad[:64] = 1.0
    m = Material(roughness=1.0, **WHITE)
    normals = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]], np.float32)
    out = _points(ref, rad, normals, normals, m)
    expected = np.repeat(np.array([[1.0], [0.5], [0.5], [0.0]]) * 0.99995, 3, axis=1)
    np.testing.assert_allclose(out[:, :3], expected, atol=1e-3)  # measured: 1.00005, 0.49999, 0.49999, 0
    assert np.all(out[:, 3] == 1.0)


@pytest.mark.parametrize("kind", ["dielectric", "metal"])
def test_probe_matches_numpy_ground_truth(ref, royal, kind):
    # The numpy ground truth (float32 per chunk, float64 across chunks) and the GPU sum (float32,
    # per-row partial sums) over the same map, box-reduced by 4 (env level 2) for speed.
    # Measured relative difference over the disk: dielectric 6e-7 (r = 0.3), 2e-7 (r = 1); metal
    # 5e-6 (r = 0.3), 2e-7 (r = 1); worst pixel 4e-5. The 1e-4 bound leaves room for another GPU.
    size = 32
    reduced = box_reduce(royal, 4)
    pts, inside = probe_points(size)
    terms = ground_truth_terms(reduced, pts, (0.0, 0.0, 1.0), (0.3, 1.0))
    base = (0.8, 0.3, 0.2) if kind == "dielectric" else (1.0, 0.78, 0.34)
    for r in (0.3, 1.0):
        m = Material(base_color=base, metallic=0.0 if kind == "dielectric" else 1.0, roughness=r,
                     specular_f0=(0.04, 0.04, 0.04))
        gpu = ref.render(Scene(material=m, view="probe"), royal, size, size, env_level=2)
        assert gpu.env_size == (256, 128)
        expected = np.zeros((size, size, 3))
        expected[inside] = terms.combine(m.base_color, m.metallic, m.specular_f0, roughness=r)
        err = relative_error(gpu.linear, expected, inside)
        assert err < 1e-4, f"{kind} r={r}: relative error {err:.2e}"
        assert np.all(gpu.linear[inside, 3] == 1.0) and np.all(gpu.linear[~inside] == 0.0)


def test_mesh_view_centre_matches_probe(ref, royal):
    # The sphere's vertex at (0, 0, 1) lies on the camera's axis: the centre pixel of an odd-sized
    # image has n = v = +Z there, as the probe's centre pixel has.
    m = Material(base_color=(0.7, 0.2, 0.1), metallic=0.0, roughness=0.5)
    size = 33
    mesh = ref.render(Scene(mesh=load_mesh("sphere"), material=m), royal, size, size, env_level=2).linear
    probe = ref.render(Scene(material=m, view="probe"), royal, size, size, env_level=2).linear
    c = size // 2
    np.testing.assert_allclose(mesh[c, c, :3], probe[c, c, :3], rtol=1e-3)
    assert mesh[c, c, 3] == 1.0
    assert mesh[0, 0].tolist() == [0.0, 0.0, 0.0, 0.0] and mesh[-1, -1, 3] == 0.0
    assert 0.2 < float(np.mean(mesh[..., 3])) < 0.8


def test_punctual_lights_match_the_real_time_path(ref):
    # No environment: both paths evaluate punctual.glsl's punctual_light at the same n, v, l
    # (measured: 6e-7 relative, 4.5e-5 largest absolute difference).
    m = Material(base_color=(0.9, 0.5, 0.2), metallic=0.3, roughness=0.4, emissive=(0.01, 0.02, 0.03))
    lights = [parse_light("point:pos=2,3,4:intensity=30"), parse_light("directional:dir=-1,-1,-1:color=1,0.9,0.8")]
    scene = Scene(material=m, view="probe", lights=lights, ibl_enabled=False)
    size = 48
    realtime = renderer().render(scene, None, size, size, read_srgb=False).linear
    reference = ref.render(scene, None, size, size).linear
    _, inside = probe_points(size)
    assert np.array_equal(reference[..., 3] == 1.0, inside)
    assert relative_error(reference, realtime, inside) < 1e-4
    np.testing.assert_allclose(reference[inside, :3], realtime[inside, :3], rtol=1e-4, atol=1e-6)


def run(*args):
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "alight", "reference", *map(str, args)], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=300)


def test_cli_writes_float_rgba_exr(tmp_path):
    import OpenImageIO as oiio

    out = tmp_path / "x.exr"
    proc = run("--view", "probe", "--size", 32, "--roughness", 0.5, "--out", out)
    assert proc.returncode == 0, proc.stderr
    image = oiio.ImageInput.open(str(out))
    spec = image.spec()
    pixels = image.read_image(oiio.FLOAT)
    image.close()
    assert (spec.width, spec.height, spec.nchannels) == (32, 32, 4)
    assert spec.format == oiio.FLOAT
    _, inside = probe_points(32)
    assert np.all(pixels[inside, 3] == 1.0) and np.all(pixels[~inside] == 0.0)
    assert np.all(pixels[inside, :3] > 0.0)


@pytest.mark.parametrize("args, name", [
    (("--roughness", "0.05"), "x.exr"),
    (("--roughness", "0.5"), "x.png"),
    (("--roughness", "0.5", "--env", "no_such_map.hdr"), "x.exr"),
    (("--roughness", "0.5", "--env-level", "two"), "x.exr"),
])
def test_cli_refuses_bad_input(tmp_path, args, name):
    out = tmp_path / name
    proc = run("--view", "probe", "--size", 16, *args, "--out", out)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("alight: error:"), proc.stderr
    assert list(tmp_path.iterdir()) == []


def test_automatic_env_level(royal, shared_data):
    from alight.accuracy.reference import choose_env_level

    quarry = load_environment(str(shared_data / "env" / "quarry_01_1k.hdr")).radiance
    assert choose_env_level(royal, [0.5, 0.25]) == 1      # royal's sun holds 6% of the power
    assert choose_env_level(royal, [0.5, 0.2]) == 0       # a narrow lobe: the full map
    assert choose_env_level(quarry, [1.0]) == 0           # a sun with 48% of the power
    assert choose_env_level(box_reduce(royal, 2), [1.0]) == 0   # already only 512 wide


def test_mesh_view_orientation(ref):
    # Light from one side only: the sphere seen from +Z is bright on that side of the image
    # (+Y up: top rows; +X: right columns; u = 0.75 is +X in docs/conventions.md's mapping). Near
    # Lambert, E/pi = (1 + n.y)/2 under the upper-half sky: the outer thirds of the disk differ by
    # about 4x (measured 73.2 vs 18.5); a flipped image would give the inverse ratio.
    m = Material(roughness=1.0, **WHITE)
    mesh = load_mesh("sphere")
    up = np.zeros((64, 128, 3), np.float32)
    up[:32] = 1.0
    right = np.zeros((64, 128, 3), np.float32)
    right[:, 64:] = 1.0
    size = 31
    top = ref.render(Scene(mesh=mesh, material=m), up, size, size, env_level=0).linear
    side = ref.render(Scene(mesh=mesh, material=m), right, size, size, env_level=0).linear
    third = size // 3
    assert top[:third, :, 0].sum() > 2.5 * top[-third:, :, 0].sum()
    assert side[:, -third:, 0].sum() > 2.5 * side[:, :third, 0].sum()
