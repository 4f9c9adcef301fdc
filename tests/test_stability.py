"""Stability: where the methods fail, and what is expected of each failure case.

tests/test_robustness.py checks that nothing is NaN at the parameter extremes; tests/
test_white_furnace.py checks the furnace at the default quality for the lecture's metal;
tests/test_probe_accuracy.py bounds the probe against the converged split sum at r >= 0.25.
This file goes to the edges those leave out and states a bound for each: the error against
app/accuracy/converged.py's converged split sum (the implementation error), the white furnace, finite
output, or a clear refusal. The figures in the docstrings were measured on this 2-core llvmpipe
machine (run with -s to see them).
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import OpenImageIO as oiio
import pytest
from numpy.lib.stride_tricks import sliding_window_view

from alight.accuracy.converged import (
    brdf_lut_converged,
    diffuse_fresnel,
    downsample_equirect,
    ibl_converged,
    irradiance_converged,
    prefiltered_converged,
)
from alight.core import shading
from alight.core.ibl_models import IBL_MODELS
from alight.core.material import Material
from alight.core.mesh import FileMaterial, Mesh, MeshPart, plane, sphere
from alight.core.scene import Camera, Scene
from alight.core.sky_weight import cube_texel_directions
from alight.ibl.bake import QUALITY, grid_roughness, quality_named, read_cube, read_lut
from alight.ibl.environment import Environment, constant_environment, load_environment
from alight.ibl.sun import extract_suns
from tests.gpu import renderer

WIDTH = 48
WHITE_METAL = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0)
GOLD = Material(base_color=(1.0, 0.71, 0.29), metallic=1.0)
GREY = Material(base_color=(0.8, 0.8, 0.8), metallic=0.0)


def _write(path, pixels, fmt=oiio.FLOAT):
    pixels = np.ascontiguousarray(pixels, dtype=np.float32)
    h, w, c = pixels.shape
    out = oiio.ImageOutput.create(str(path))
    assert out is not None and out.open(str(path), oiio.ImageSpec(w, h, c, fmt)), oiio.geterror()
    assert out.write_image(pixels), out.geterror()
    out.close()
    return path


@pytest.fixture(scope="module")
def furnace():
    return constant_environment(1.0, width=128)


@pytest.fixture(scope="module")
def env_of(shared_data):
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = load_environment(str(shared_data / "env" / name))
        return cache[name]
    return get


def converged_probe(radiance, m: Material, width: int = WIDTH):
    """app/accuracy/converged.py's split sum on the probe: (P, 3) over the disk, and the disk mask."""
    n, inside = shading.probe_normals(width)
    normals = n[inside]
    nv = np.maximum(normals[:, 2], 0.0)
    coarse = downsample_equirect(radiance, 2) if m.roughness >= 0.25 else radiance
    f0 = shading.f0_of(m.base_color, m.metallic, m.specular_f0)
    F = shading.F_SchlickRoughness(nv, f0, m.roughness)
    kd = (1 - F) * (1 - m.metallic)
    a, b = brdf_lut_converged(nv, np.full_like(nv, m.roughness))
    reflected = shading.reflect(-np.array([0.0, 0.0, 1.0]), normals)
    pre = prefiltered_converged(radiance if m.roughness < 0.25 else coarse, reflected, m.roughness)
    irr = irradiance_converged(coarse, normals)
    return kd * np.array(m.base_color) * irr + pre * (F * a[:, None] + b[:, None]), inside, nv


def rel_error(got, want) -> float:
    return float(np.abs(got - want).sum() / np.abs(want).sum())


# --- roughness exactly 0 and 1 -------------------------------------------------------------

@pytest.mark.parametrize("roughness,bound", [(0.0, 0.03), (1.0, 0.02)])
@pytest.mark.parametrize("material", [GREY, GOLD], ids=["dielectric", "gold"])
def test_roughness_exactly_zero_and_one_against_converged(env_of, material, roughness, bound):
    """r = 0 is the mirror: the probe reads the source cube's level 0 (no prefiltering), and the
    converged value is the bilinear lookup of the map itself (the cube's 256^2 faces resample
    the 1024x512 map); r = 1 is grid A's last mip. Against the converged split sum on
    royal_esplanade at the default quality: r = 0 within 3%, r = 1 within 2% (measured: r = 0
    dielectric 0.6%, gold 2.2%; r = 1 dielectric 0.5%, gold 0.9%).
    Between 0 and the first grid step (r = 0.25) the error is larger: see
    test_below_first_grid_step_with_a_sun."""
    m = Material(base_color=material.base_color, metallic=material.metallic, roughness=roughness)
    env = env_of("royal_esplanade_1k.hdr")
    want, inside, _ = converged_probe(env.radiance, m)
    r = renderer()
    got = r.render(Scene(material=m, view="probe", ibl_model="lecture"), r.bake(env, "medium"),
                   WIDTH, WIDTH).linear[..., :3][inside]
    err = rel_error(got, want)
    print(f"r={roughness} {'metal' if m.metallic else 'dielectric'}: {err * 100:.2f}%")
    assert np.isfinite(got).all() and err <= bound


def test_below_first_grid_step_with_a_sun(env_of):
    """Between r = 0 and the first prefiltered step (r = 0.25 at medium) the shader blends the
    source cube's box mips (which keep the sun as texels) into step 0 (which has the sun in
    closed form). A box filter is not a GGX lobe: under pedestrian_overpass's low sun, gold at
    r = 0.15 is far off the converged split sum (measured 47% at medium, 9% at the finer
    'medium-fine' candidate of app/accuracy/auto_quality.py). This documents the failure (a bound, not
    a pass mark): the error stays finite and below 60% at medium, and the finer grid, whose first
    step is at r = 0.18, brings it under 15%. --quality auto knows it from its table."""
    from alight.accuracy.auto_quality import CANDIDATES

    env = env_of("pedestrian_overpass_1k.hdr")
    m = Material(base_color=GOLD.base_color, metallic=1.0, roughness=0.15)
    want, inside, _ = converged_probe(env.radiance, m)
    r = renderer()
    errors = {}
    for q in (QUALITY["medium"], CANDIDATES["medium-fine"]):
        got = r.render(Scene(material=m, view="probe", ibl_model="lecture"), r.bake(env, q),
                       WIDTH, WIDTH).linear[..., :3][inside]
        assert np.isfinite(got).all()
        errors[q.name] = rel_error(got, want)
    print({k: f"{v * 100:.1f}%" for k, v in errors.items()})
    assert errors["medium"] <= 0.60
    assert errors["auto:medium-fine"] <= 0.15


def test_default_model_below_first_grid_step_with_a_sun(env_of):
    """The default model (alight) has no such failure: it reads the source cube *without* the
    compact sources below the grid (a smooth map, which box mips filter well) and shades the sun
    through the exact BRDF at every roughness, widened by the source's own size. Against its
    numpy twin (alight.accuracy.converged.ibl_converged: the sun-free map's texel sums plus the same sun
    term), the same case as above stays under 5% (measured 1.8%) where the lecture's blend is 47% off
    its own converged value."""
    env = env_of("pedestrian_overpass_1k.hdr")
    m = Material(base_color=GOLD.base_color, metallic=1.0, roughness=0.15)
    n, inside = shading.probe_normals(WIDTH)
    want = ibl_converged("alight", env.radiance, n[inside], (0.0, 0.0, 1.0), m.base_color, m.metallic,
                         m.roughness, m.specular_f0)
    r = renderer()
    got = r.render(Scene(material=m, view="probe", ibl_model="alight"), r.bake(env, "medium"),
                   WIDTH, WIDTH).linear[..., :3][inside]
    err = rel_error(got, want)
    print(f"alight below the grid: {err * 100:.2f}%")
    assert np.isfinite(got).all() and err <= 0.05


# --- n.v -> 0 ------------------------------------------------------------------------------

def test_probe_rim_against_converged(env_of):
    """The probe's outer ring (n.v < 0.2) is where the LUT is read at its first column and F is
    largest. Against the converged split sum over that ring alone, at the default quality on
    royal_esplanade, the error stays under 3% (measured: dielectric r = 0.5 0.6%, gold 2.4%),
    and no rim pixel is NaN or negative."""
    env = env_of("royal_esplanade_1k.hdr")
    r = renderer()
    maps = r.bake(env, "medium")
    for base in (GREY, GOLD):
        m = Material(base_color=base.base_color, metallic=base.metallic, roughness=0.5)
        want, inside, nv = converged_probe(env.radiance, m)
        got = r.render(Scene(material=m, view="probe", ibl_model="lecture"), maps, WIDTH, WIDTH).linear[..., :3][inside]
        rim = nv < 0.2
        assert rim.sum() > 20
        err = rel_error(got[rim], want[rim])
        print(f"rim {'metal' if m.metallic else 'dielectric'}: {err * 100:.2f}% over {rim.sum()} pixels")
        assert np.isfinite(got).all() and got.min() >= 0.0 and err <= 0.03


@pytest.mark.parametrize("quality", ["low", "medium"])
def test_lut_at_grazing_is_bounded(quality):
    """The BRDF LUT's first column (n.v -> 0): A and B finite, >= 0, and A + B <= 1 (A + B is the
    directional albedo of a metal with F0 = 1, which cannot exceed 1), within the Hammersley
    estimate's noise (1e-3). Measured max A + B over the table: 0.9999 (medium)."""
    r = renderer()
    q = QUALITY[quality]
    lut = read_lut(r.luts.get(q.lut_size, q.lut_samples))
    assert np.isfinite(lut).all() and lut.min() >= 0.0
    assert lut[..., 2:].max() <= 1.0          # the lobe directions: lerp factors between n and R
    total = lut[..., :2].sum(axis=2)
    print(f"max A+B {total.max():.5f}, first column {total[:, 0].min():.4f}..{total[:, 0].max():.4f}")
    assert total.max() <= 1.0 + 1e-3


def test_grazing_camera_white_furnace(furnace):
    """A camera skimming a plane (n.v from 0.02 to 0.08 over it), a white metal (F0 = 1)
    under radiance 1, roughness 0, 0.5 and 1: every pixel finite, >= 0 and <= 1 + 1e-3 (the
    furnace bound; a metal has no diffuse term to add to it)."""
    r = renderer()
    maps = r.bake(furnace, "medium")
    cam = Camera(position=(0.0, 0.05, 1.6), target=(0.0, 0.0, -0.5))
    for rough in (0.0, 0.5, 1.0):
        m = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=rough)
        frame = r.render(Scene(mesh=plane(), material=m, camera=cam, display=_no_background()), maps, 128, 128).linear
        hit = frame[..., 3] > 0
        assert hit.sum() > 100
        px = frame[..., :3][hit]
        assert np.isfinite(px).all() and px.min() >= 0.0 and px.max() <= 1.0 + 1e-3, (rough, px.max())


def _no_background():
    from alight.core.scene import Display

    return Display(background="transparent")


# --- very bright small sources: fireflies in the prefiltered map -----------------------------

def neighbour_ratio(faces: np.ndarray) -> float:
    """Max over texels of luminance / the median of its 8 neighbours on the same face: a firefly
    is one texel far brighter than all around it. A smooth prefiltered map stays near 1."""
    lum = faces[..., :3].mean(axis=-1)
    s = lum.shape[1]
    if s < 3:
        return 1.0
    win = sliding_window_view(lum, (3, 3), axis=(1, 2)).reshape(6, s - 2, s - 2, 9)
    median = np.median(np.delete(win, 4, axis=-1), axis=-1)
    return float((win[..., 4] / np.maximum(median, 1e-30)).max())


# (map, quality): (neighbour-ratio bound, bound on the step's error against converged)
FIREFLY_BOUNDS = {
    ("quarry_01_1k.hdr", "low"): (1.25, 0.03), ("quarry_01_1k.hdr", "medium"): (1.25, 0.025),
    ("spot1Lux.hdr", "low"): (1.25, 0.04), ("spot1Lux.hdr", "medium"): (1.25, 0.05),
}


@pytest.mark.parametrize("env_name,quality", list(FIREFLY_BOUNDS))
def test_no_fireflies_in_prefiltered_map(env_of, env_name, quality):
    """quarry_01's sun (peak 86,528, 48% of the power in a few texels) and spot1Lux's spot (all
    of it) would make fireflies in every prefiltered step: a sample that lands on the source
    carries a huge weight. app/ibl/sun.py takes them out (the forward pass adds them per pixel in
    closed form), so the prefiltered map is that of the environment without them, and:
    - every step's neighbour ratio (texel / median of its 8 neighbours) stays <= 1.25
      (measured <= 1.07 on quarry; spot1Lux is black without its spot, and so is every step;
      with the sources left in the map the same
      measure reads 1.4-2.3 on quarry and ~1e24 on spot1Lux: test_fireflies_without_sun_handling);
    - each step's error against prefiltered_converged of the map without its sources over 1000
      random texels,
      sum |bake - converged| / sum converged, stays within the table's bound (measured: quarry
      low 0.2-2.5%, medium 0.1-0.6%; largest at the first step, r = 0.25)."""
    env = env_of(env_name)
    r = renderer()
    maps = r.bake(env, quality)
    assert maps.suns                          # the source was found and taken out
    small = downsample_equirect(extract_suns(env.radiance)[0], 2)
    levels = QUALITY[quality].prefiltered_levels
    ratio_bound, error_bound = FIREFLY_BOUNDS[(env_name, quality)]
    rng = np.random.default_rng(7)
    report = []
    if float(small.max()) <= 1e-6 * float(env.radiance.max()):
        # spot1Lux is its spot on black: without it nothing is left, and every step must be
        # black too (no firefly can come from nothing).
        for step in range(2 * levels - 1):
            cube = maps.prefiltered_radiance if step % 2 == 0 else maps.prefiltered_radiance_mid
            faces = read_cube(r.shaders, cube, step // 2)[..., :3]
            assert np.isfinite(faces).all() and faces.max() <= 1e-6 * float(env.radiance.max())
        print(env_name, quality, "all steps black without the spot")
        return
    for step in range(2 * levels - 1):
        cube = maps.prefiltered_radiance if step % 2 == 0 else maps.prefiltered_radiance_mid
        faces = read_cube(r.shaders, cube, step // 2)[..., :3]
        assert np.isfinite(faces).all() and faces.min() >= 0.0
        ratio = neighbour_ratio(faces)
        dirs = cube_texel_directions(faces.shape[1]).reshape(-1, 3)
        pick = rng.choice(len(dirs), min(len(dirs), 1000), replace=False)
        want = prefiltered_converged(small, dirs[pick], grid_roughness(step, levels))
        err = rel_error(faces.reshape(-1, 3)[pick], want)
        report.append(f"step {step}: ratio {ratio:.3f} err {err * 100:.2f}%")
        assert ratio <= ratio_bound, report[-1]
        assert err <= error_bound, report[-1]
    print(env_name, quality, "; ".join(report))


def test_fireflies_without_sun_handling(env_of, monkeypatch):
    """The control for the test above: with app/ibl/sun.py's extraction switched off, quarry's
    prefiltered steps do have fireflies by the same measure (> 1.25 at some step; measured
    1.37-1.55 at low), so the measure can fail."""
    import alight.ibl.bake as bake

    monkeypatch.setattr(bake, "extract_suns", lambda radiance: (radiance, []))
    env = env_of("quarry_01_1k.hdr")
    r = renderer()
    maps = bake.bake_environment(r.ctx, r.shaders, env, QUALITY["low"], r.luts)
    try:
        levels = QUALITY["low"].prefiltered_levels
        ratios = [neighbour_ratio(read_cube(r.shaders, maps.prefiltered_radiance if s % 2 == 0 else
                                            maps.prefiltered_radiance_mid, s // 2)) for s in range(2 * levels - 1)]
    finally:
        maps.release()
    print("without sun handling:", [f"{x:.2f}" for x in ratios])
    assert max(ratios) > 1.25


# --- all-black, NaN/Inf/negative, 2x1 and 16384x8192 environments --------------------------

@pytest.mark.parametrize("quality,irradiance", [("low", "sh9"), ("medium", "convolution")])
def test_black_environment_bakes_exact_zeros(quality, irradiance):
    """An all-black map has no power: no compact source is found, and every baked map (source
    cube, irradiance, every prefiltered step of both grids) is exactly 0, not NaN (the
    prefilter divides by its weight sum, the sun search by the map's power). A mesh view renders
    exactly 0 too."""
    from alight.ibl.sun import extract_suns

    black = Environment(np.zeros((64, 128, 3), np.float32), "black")
    assert extract_suns(black.radiance)[1] == []
    r = renderer()
    maps = r.bake(black, quality_named(quality, irradiance))
    levels = maps.quality.prefiltered_levels
    cubes = [read_cube(r.shaders, maps.environment, 0), read_cube(r.shaders, maps.irradiance, 0)]
    cubes += [read_cube(r.shaders, maps.prefiltered_radiance, m) for m in range(levels)]
    cubes += [read_cube(r.shaders, maps.prefiltered_radiance_mid, m) for m in range(levels - 1)]
    for faces in cubes:
        assert np.all(faces[..., :3] == 0.0)
    frame = r.render(Scene(mesh=sphere(), material=GOLD), maps, 32, 32).linear
    assert np.all(frame[..., :3] == 0.0)


def test_bad_texels_from_a_file_give_finite_renders(tmp_path):
    """NaN, +Inf, -Inf and negative texels in a file are set to 0 with one warning line (the
    loader's own test checks the count); what matters here is the rest of the way: the bake and
    the render of the repaired map are finite and >= 0, next to a very bright texel."""
    px = np.full((32, 64, 3), 0.5, np.float32)
    px[3, 7] = np.nan
    px[10, 20, 1] = np.inf
    px[11, 21] = -np.inf
    px[20, 40] = -3.0
    px[16, 16] = 1e6
    env = load_environment(str(_write(tmp_path / "bad.exr", px)))
    assert len(env.warnings) == 1 and "4 NaN/Inf/negative texels set to 0" in env.warnings[0]
    r = renderer()
    for quality in ("low", "medium"):
        maps = r.bake(env, quality)
        for m in (GREY, GOLD):
            frame = r.render(Scene(material=m, view="probe"), maps, 32, 32).linear
            assert np.isfinite(frame).all() and frame.min() >= 0.0


def test_bad_texels_in_an_environment_made_in_memory_are_repaired():
    """An Environment made from an array (the Python API takes one) must keep the same promise
    as a file: NaN/Inf/negative texels set to 0 with a warning, and a finite bake. (Before the
    fix, Environment() took the array as it was and NaN spread through the cube's mips to every
    pixel.)"""
    px = np.full((32, 64, 3), 0.5, np.float32)
    px[3, 7] = np.nan
    px[5, 9, 2] = -np.inf
    px[8, 8] = -1.0
    env = Environment(px, "memory")
    assert np.isfinite(env.radiance).all() and env.radiance.min() >= 0.0
    assert len(env.warnings) == 1 and "3 NaN/Inf/negative texels set to 0" in env.warnings[0]
    assert np.isnan(px[3, 7]).all()       # the caller's array is not modified
    r = renderer()
    frame = r.render(Scene(material=GREY, view="probe"), r.bake(env, "low"), 32, 32).linear
    assert np.isfinite(frame).all()


def test_two_by_one_environment(tmp_path):
    """The smallest 2:1 map, 2x1 texels (each half of the sphere one colour), loads, bakes at
    every quality and renders finite. Made constant (radiance 1), it is a white furnace: the
    irradiance is 1 within 1e-3 and a white metal never exceeds 1 + 1e-3."""
    px = np.array([[[1.0, 2.0, 3.0], [0.0, 0.5, 4.0]]], np.float32)
    env = load_environment(str(_write(tmp_path / "tiny.exr", px)))
    assert env.radiance.shape == (1, 2, 3) and env.warnings == []
    r = renderer()
    for quality in ("low", "medium"):
        maps = r.bake(env, quality)
        for m in (GREY, GOLD, Material(roughness=0.0)):
            frame = r.render(Scene(material=m, view="probe"), maps, 32, 32).linear
            assert np.isfinite(frame).all() and frame.min() >= 0.0
    one = load_environment(str(_write(tmp_path / "one.exr", np.ones((1, 2, 3), np.float32))))
    maps = r.bake(one, "medium")
    np.testing.assert_allclose(read_cube(r.shaders, maps.irradiance)[..., :3], 1.0, atol=1e-3)
    for rough in (0.0, 0.5, 1.0):
        m = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=rough)
        probe = r.render(Scene(material=m, view="probe"), maps, 32, 32).linear
        assert probe[..., :3].max() <= 1.0 + 1e-3


HUGE_BOUND_MIB = 320


def test_huge_environment_memory_stays_bounded(tmp_path):
    """A 16384x8192 map (1.5 GiB as float RGB) is written here in strips (OpenImageIO, RLE
    .hdr, ~9 MB on disk) and loaded in a fresh process: the loader reads strips and box-reduces
    them to 4096x2048 (a warning says so), so the peak RSS grows by the reduced map (96 MiB)
    and a few strips and OIIO's buffers, not by the full map: the bound is 320 MiB, a fifth of
    the full map (measured growth: 125-181 MiB).
    The reduced map keeps the content: a row gradient and an 8x8-texel spot of 1000 aligned
    on the box grid become a 2x2 spot of 1000."""
    w, h = 16384, 8192
    path = tmp_path / "huge.hdr"
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), oiio.ImageSpec(w, h, 3, oiio.FLOAT)), out.geterror()
    rows = 256
    for y0 in range(0, h, rows):
        strip = np.empty((rows, w, 3), np.float32)
        strip[...] = (0.2 + 0.8 * np.arange(y0, y0 + rows, dtype=np.float32) / h)[:, None, None]
        if y0 == 4096:
            strip[0:8, 100:108] = 1000.0
        assert out.write_scanlines(y0, y0 + rows, 0, strip), out.geterror()
    out.close()
    del strip
    script = textwrap.dedent(f"""
        import numpy as np
        def hwm():
            for line in open('/proc/self/status'):
                if line.startswith('VmHWM'):
                    return int(line.split()[1]) * 1024
        from alight.ibl.environment import load_environment
        before = hwm()
        env = load_environment({str(path)!r})
        growth = hwm() - before
        np.save({str(tmp_path / 'reduced.npy')!r}, env.radiance[1020:1030, 20:30])
        print(growth, env.radiance.shape[0], env.radiance.shape[1], '|'.join(env.warnings))
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    growth, rh, rw, warnings = done.stdout.split(maxsplit=3)
    growth_mib = int(growth) / 2 ** 20
    print(f"peak RSS growth {growth_mib:.0f} MiB")
    assert (int(rh), int(rw)) == (2048, 4096)
    assert "16384x8192 is wider than 4096; box-reduced by 4 to 4096x2048" in warnings
    assert growth_mib < HUGE_BOUND_MIB
    patch = np.load(tmp_path / "reduced.npy")
    np.testing.assert_allclose(patch[4:6, 5:7], 1000.0, rtol=1e-2)   # rows 1024-1025, columns 25-26
    # RGBE keeps ~1% precision: the gradient row 1020 averages rows 4080..4083 of the file.
    np.testing.assert_allclose(patch[0, 0], 0.2 + 0.8 * 4081.5 / h, rtol=1e-2)


# --- non-unit and zero normals ---------------------------------------------------------------

def _sphere_with(normals_scale=None, zero_every=0, material=None):
    part = sphere().parts[0]
    normals = part.normals.copy()
    if normals_scale is not None:
        normals = normals * normals_scale
    if zero_every:
        normals[::zero_every] = 0.0
    return Mesh([MeshPart(part.name, part.positions, normals.astype(np.float32), part.uvs, part.tangents,
                          part.indices, material)], "sphere")


def test_non_unit_mesh_normals_change_nothing(furnace, env_of):
    """Vertex normals scaled by 3 or by 1e-3 (non-unit normals in a file) are normalised per
    fragment: the image equals the one with unit normals (within 1e-4 relative, the
    interpolation's rounding)."""
    r = renderer()
    maps = r.bake(env_of("royal_esplanade_1k.hdr"), "low")
    m = Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=0.3)
    ref = r.render(Scene(mesh=_sphere_with(), material=m), maps, 64, 64, aa="none").linear
    for scale in (3.0, 1e-3):
        got = r.render(Scene(mesh=_sphere_with(scale), material=m), maps, 64, 64, aa="none").linear
        np.testing.assert_allclose(got, ref, rtol=1e-4, atol=1e-5)


def test_zero_mesh_normals_fall_back_to_the_face(furnace):
    """Vertex normals of zero length (every third vertex) interpolate to short or zero normals;
    the shader falls back to the face normal where the length is 0. Under the furnace a white
    metal stays finite, >= 0 and <= 1 + 1e-3 on every pixel, at r = 0, 0.5 and 1."""
    r = renderer()
    maps = r.bake(furnace, "medium")
    for rough in (0.0, 0.5, 1.0):
        m = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=rough)
        frame = r.render(Scene(mesh=_sphere_with(zero_every=3), material=m, display=_no_background()),
                         maps, 64, 64).linear
        px = frame[..., :3][frame[..., 3] > 0]
        assert len(px) > 500 and np.isfinite(px).all() and px.min() >= 0.0 and px.max() <= 1.0 + 1e-3


@pytest.mark.parametrize("texel,what", [((128, 128, 128), "decodes to ~0 (0.004, 0.004, 0.004)"),
                                        ((127, 127, 127), "decodes to ~0, pointing inward"),
                                        ((255, 255, 255), "decodes to (1, 1, 1), length 1.73"),
                                        ((128, 128, 0), "decodes to -z: into the surface"),
                                        ((0, 0, 0), "decodes to (-1, -1, -1)")])
def test_degenerate_normal_map_texels(furnace, texel, what):
    """A normal map whose texels decode to zero, non-unit or inward vectors (every texel the
    same): the shading normal is normalised (or falls back to the vertex normal at zero length),
    n.v is clamped at 0, so a white metal under the furnace stays finite, >= 0 and
    <= 1 + 1e-3 at r = 0, 0.5 and 1."""
    image = np.empty((4, 4, 4), np.uint8)
    image[...] = (*texel, 255)
    r = renderer()
    maps = r.bake(furnace, "medium")
    for rough in (0.0, 0.5, 1.0):
        fm = FileMaterial(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=rough, emissive=(0.0, 0.0, 0.0),
                          alpha=1.0, base_color_texture=None, metallic_roughness_texture=None,
                          normal_texture=image, normal_scale=1.0, emissive_texture=None,
                          occlusion_texture=None, occlusion_strength=1.0)
        frame = r.render(Scene(mesh=_sphere_with(material=fm), display=_no_background()), maps, 48, 48).linear
        px = frame[..., :3][frame[..., 3] > 0]
        assert len(px) > 300, what
        assert np.isfinite(px).all() and px.min() >= 0.0 and px.max() <= 1.0 + 1e-3, (what, rough, px.max())


# --- white furnace: never above 1 --------------------------------------------------------------

FURNACE_ROUGHNESS = [round(x, 1) for x in np.linspace(0.0, 1.0, 11)]


@pytest.mark.parametrize("multiple_scattering", [False, True], ids=["single", "multiple-scattering"])
@pytest.mark.parametrize("model", list(IBL_MODELS))
def test_white_furnace_metal_never_above_one(furnace, model, multiple_scattering):
    """A metal with F0 = 1 under radiance 1 reflects at most what arrives: <= 1 + 1e-3 (the LUT's
    Hammersley noise and bilinear blend) at every pixel of the probe, for every IBL model, with
    and without multiple-scattering compensation (which aims at exactly 1 for F0 = 1), at every
    roughness 0, 0.1, ..., 1, with the low and the default quality's LUTs."""
    r = renderer()
    for quality in ("low", "medium"):
        maps = r.bake(furnace, quality)
        worst = 0.0
        for rough in FURNACE_ROUGHNESS:
            m = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=rough)
            scene = Scene(material=m, view="probe", ibl_model=model, multiple_scattering=multiple_scattering)
            probe = r.render(scene, maps, 48, 48).linear[..., :3]
            assert np.isfinite(probe).all()
            worst = max(worst, float(probe.max()))
        print(f"{model} ms={multiple_scattering} {quality}: max {worst:.5f}")
        assert worst <= 1.0 + 1e-3


@pytest.mark.parametrize("model", list(IBL_MODELS))
@pytest.mark.parametrize("f0", [0.04, 0.0], ids=["F0=0.04", "F0=0"])
def test_white_furnace_dielectric(furnace, model, f0):
    """A white dielectric (base colour 1) under radiance 1. docs/conventions.md's BRDF itself is not
    energy-conserving here: kd = 1 - F(v.h) per direction lets the diffuse keep what the specular
    also reflects at grazing. At r = 0 its albedo is exactly
        F0 + (1 - F0) Fc(n.v) + (1 - F0)(1 - C(n.v))
    (the mirror's Fresnel plus the Lambert lobe's (1 - F0)(1 - Fc(v.h)); C <= 0.028, see
    ibl.glsl's diffuse_fresnel): 1.72 at n.v = 0.05, and it only falls as roughness grows.
    - The lecture's split sum reaches 1 + Fc (1 - F) at r = 0 (kd = 1 - F plus F A + B), at most
      1.24 for F0 = 0.04 and exactly 1.25 for F0 = 0 (measured 1.2396 and 1.2496): bound 1.25 + 2e-3.
    - Karis' split (karis, dominant, alight) has the ground truth's own weights, (1 - F0)(1 - C)
      and F0 A + B, so it follows that r = 0 albedo: every pixel stays <= it + 3e-3 (measured
      max 1.77 and 1.80 at the rim pixel, n.v ~ 0.03, where the truth is as high).
    - Where n.v >= 0.8 (away from grazing, where the truth is <= 1 too) every model stays
      <= 1 + 3e-3 (measured 1.0003-1.0013)."""
    r = renderer()
    maps = r.bake(furnace, "medium")
    n, inside = shading.probe_normals(64)
    front = inside & (n[..., 2] >= 0.8)
    worst = worst_front = 0.0
    for rough in FURNACE_ROUGHNESS:
        m = Material(base_color=(1.0, 1.0, 1.0), metallic=0.0, roughness=rough, specular_f0=(f0, f0, f0))
        probe = r.render(Scene(material=m, view="probe", ibl_model=model), maps, 64, 64).linear[..., :3]
        assert np.isfinite(probe).all() and probe.min() >= 0.0
        worst = max(worst, float(probe[inside].max()))
        worst_front = max(worst_front, float(probe[front].max()))
        if model not in ("lecture", "lecture-schlick"):
            nv = n[..., 2][inside]
            fc = (1.0 - nv) ** 5
            albedo_r0 = f0 + (1.0 - f0) * fc + (1.0 - f0) * (1.0 - diffuse_fresnel(nv))
            assert (probe[inside].max(axis=1) <= albedo_r0 + 3e-3).all()
    print(f"{model} F0={f0}: max {worst:.4f}, max at n.v >= 0.8 {worst_front:.5f}")
    if model in ("lecture", "lecture-schlick"):
        assert worst <= 1.25 + 2e-3
    assert worst_front <= 1.0 + 3e-3
