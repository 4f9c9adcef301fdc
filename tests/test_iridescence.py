"""KHR_materials_iridescence (docs/layer_iridescence.md): the white furnace, a weight of 0 and a
film of no thickness, the reference against the numpy ground truth, the forward pass against
its converged twin, and the glTF reader and its textures by equivalence. The GLSL terms against
their numpy twins: tests/test_glsl_twins.py."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from alight.accuracy.converged import downsample_equirect, ibl_converged
from alight.accuracy.ground_truth import layered_ground_truth, probe_points
from alight.core.ibl_models import DEFAULT_IBL_MODEL
from alight.core.layers import iridescence as ir
from alight.core.material import Material
from alight.core.scene import Light, Scene
from alight.core.shading import probe_normals
from alight.ibl.environment import constant_environment, load_environment
from tests.gltf_builder import USHORT, Gltf, grid_plane
from tests.gpu import renderer

FILM = dict(iridescence=1.0, iridescence_ior=1.8, iridescence_thickness_maximum=350.0)
LIGHTS = [Light("point", (2.0, 3.0, 4.0), (1.0, 1.0, 1.0), 30.0)]


def _royal(shared_data):
    return load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))


def _rel(a, b, inside):
    return np.abs(a[..., :3] - b[..., :3])[inside].sum() / np.abs(b[..., :3])[inside].sum()


# --- the film's Fresnel ----------------------------------------------------------------------

def test_film_fresnel_stays_in_zero_one():
    """F_film in [0, 1] over the range of thickness, index, angle and substrate a file can give
    (the Airy sum's clamp below, total internal reflection's 1 above)."""
    rng = np.random.default_rng(3)
    n = 20000
    f = ir.iridescence_fresnel(1.0, rng.uniform(1.0, 3.0, n), rng.uniform(0, 1, n), rng.uniform(0, 2000, n),
                               rng.uniform(0, 1, (n, 3)))
    assert f.min() >= 0.0 and f.max() <= 1.0, (f.min(), f.max())


def test_film_of_the_substrates_index_is_only_its_first_interface():
    """A film of the base's own index (1.5 over F0 0.04) has no second interface: at normal
    incidence the plain Fresnel of 1.5, 0.04, up to the interference terms the Sample Viewer's
    floor of 1e-5 on R12 R23 leaves (sqrt(1e-5) T121 S: measured 0.030, 0.040, 0.043)."""
    f = ir.iridescence_fresnel(1.0, 1.5, np.array([1.0]), np.array([400.0]), np.array([[0.04, 0.04, 0.04]]))
    np.testing.assert_allclose(f[0], 0.04, atol=0.012)


# --- the white furnace -----------------------------------------------------------------------

@pytest.mark.parametrize("roughness", [0.3, 1.0])
@pytest.mark.parametrize("thickness", [150.0, 400.0, 900.0])
def test_white_furnace_ground_truth(roughness, thickness):
    """A white metal under a constant environment of radiance 1: the film's Fresnel is constant
    over the lobe, so the exact answer is mix(E_base, F_film (A + B), i), never above 1."""
    env = constant_environment(1.0, width=256).radiance
    n, _ = probe_points(8)
    film = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=roughness, iridescence=0.7,
                    iridescence_ior=1.6, iridescence_thickness_maximum=thickness)
    bare = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=roughness)
    with_film = layered_ground_truth(env, n, (0, 0, 1), film)
    without = layered_ground_truth(env, n, (0, 0, 1), bare)   # = A + B: F0 = 1
    assert with_film.max() <= 1.0 + 1e-6, with_film.max()
    f = ir.iridescence_fresnel_at_view(film, n[:, 2])
    np.testing.assert_allclose(with_film, without + (f * without - without) * 0.7, rtol=1e-9)


@pytest.mark.parametrize("model", ["alight", "lecture"])
def test_white_furnace_render_never_exceeds_one(model):
    r = renderer()
    maps = r.bake(constant_environment(1.0, width=256), "medium")
    m = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.5, **FILM)
    img = r.render(Scene(material=m, view="probe", ibl_model=model), maps, 48, 48).linear
    inside = img[..., 3] > 0
    assert img[..., :3][inside].max() <= 1.0 + 2e-3


# --- a weight of 0, a film of no thickness ---------------------------------------------------

def test_zero_weight_renders_exactly_as_without(shared_data):
    """iridescence 0 (with the film's other fields set) is the material without the extension,
    bit for bit: the layer is not compiled in (forward pass, both views, lights and environment)."""
    r = renderer()
    maps = r.bake(_royal(shared_data), "low")
    base = dict(base_color=(0.2, 0.3, 0.6), roughness=0.35)
    off = Material(**base, iridescence=0.0, iridescence_ior=2.0, iridescence_thickness_minimum=50.0,
                   iridescence_thickness_maximum=700.0)
    assert "iridescence" not in off.layers()
    for view in ("probe", "camera"):
        a = r.render(Scene(material=off, view=view, lights=LIGHTS), maps, 32, 32).linear
        b = r.render(Scene(material=Material(**base), view=view, lights=LIGHTS), maps, 32, 32).linear
        assert np.array_equal(a, b), view


def test_zero_weight_compiled_in_changes_nothing(monkeypatch, shared_data):
    """With HAS_IRIDESCENCE forced on, weight 0 is the base (forward pass and reference) to
    float rounding, and a film of thickness 0 is no film either."""
    import alight.accuracy.reference as reference
    import alight.render.variants as forward   # the layer defines a draw compiles (material_defines)
    from alight.accuracy.reference import ReferenceRenderer

    r = renderer()
    env = _royal(shared_data)
    maps = r.bake(env, "low")
    small = downsample_equirect(env.radiance, 8)
    plain = Material(base_color=(0.7, 0.2, 0.1), roughness=0.4)
    scene = Scene(material=plain, view="probe", lights=LIGHTS)
    img = r.render(scene, maps, 32, 32).linear
    ref = ReferenceRenderer(r).render(scene, small, 16, 16).linear
    monkeypatch.setattr(forward, "layer_defines", lambda materials: {"HAS_IRIDESCENCE": None})
    monkeypatch.setattr(reference, "layer_defines", lambda materials: {"HAS_IRIDESCENCE": None})
    for m in (Material(base_color=(0.7, 0.2, 0.1), roughness=0.4, iridescence=0.0, iridescence_ior=1.8),
              Material(base_color=(0.7, 0.2, 0.1), roughness=0.4, iridescence=1.0, iridescence_ior=1.8,
                       iridescence_thickness_maximum=0.0)):
        s = Scene(material=m, view="probe", lights=LIGHTS)
        forced, ref_forced = r.render(s, maps, 32, 32).linear, ReferenceRenderer(r).render(s, small, 16, 16).linear
        for a, b in ((forced, img), (ref_forced, ref)):
            inside = b[..., 3] > 0
            assert _rel(a, b, inside) <= 1e-6


# --- the reference against numpy, the forward pass against its converged twin ---------------

def test_reference_matches_the_numpy_ground_truth(shared_data):
    from alight.accuracy.reference import ReferenceRenderer, probe_gbuffer

    small = downsample_equirect(_royal(shared_data).radiance, 8)
    m = Material(base_color=(0.3, 0.2, 0.1), roughness=0.4, **FILM)
    scene = Scene(material=m, view="probe", env_rotation_deg=40.0, env_intensity=1.3)
    gpu = ReferenceRenderer(renderer()).render_gbuffer(probe_gbuffer(16, m), scene, small).linear
    pts, inside = probe_points(16)
    cpu = layered_ground_truth(small, pts, (0, 0, 1), m, rotation_deg=40.0, intensity=1.3)
    np.testing.assert_allclose(gpu[..., :3][inside], cpu, rtol=2e-3, atol=1e-5)


FILMS = {
    "film_dark": Material(base_color=(0.05, 0.05, 0.05), roughness=0.3, **FILM),
    "film_gold": Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=0.5, iridescence=0.8,
                          iridescence_ior=1.3, iridescence_thickness_maximum=500.0),
}


@pytest.mark.parametrize("name", FILMS)
def test_forward_pass_matches_its_converged_twin(name, shared_data):
    """What the implementation adds to the model's own error: the probe at `medium` against
    ibl_converged with the film (royal_esplanade, 2% as for the base models)."""
    m = FILMS[name]
    r = renderer()
    env = _royal(shared_data)
    img = r.render(Scene(material=m, view="probe"), r.bake(env, "medium"), 32, 32).linear
    normals, inside = probe_normals(32)
    twin = ibl_converged(DEFAULT_IBL_MODEL, downsample_equirect(env.radiance, 2), normals[inside], (0, 0, 1), m.base_color,
                         m.metallic, m.roughness, m.specular_f0, material=m)
    rel = np.abs(img[..., :3][inside] - twin).sum() / np.abs(twin).sum()
    print(f"{name}: {100 * rel:.2f}% off the converged twin")
    assert rel <= 0.02


# --- glTF files -------------------------------------------------------------------------------

def _plane_file(path, extension: dict | None, textures: dict | None = None):
    """A plane with a dark dielectric material, with KHR_materials_iridescence as given (None:
    without the extension); ``textures``: {textureInfo key: (8, 8, 4) uint8 image}."""
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(2)
    ext = {}
    if extension is not None:
        ext = dict(extension)
        for key, image in (textures or {}).items():
            ext[key] = {"index": g.image(image)}
        g.use("KHR_materials_iridescence")
    mat = g.material(pbrMetallicRoughness={"baseColorFactor": [0.05, 0.05, 0.05, 1.0], "metallicFactor": 0.0,
                                           "roughnessFactor": 0.3},
                     **({"extensions": {"KHR_materials_iridescence": ext}} if extension is not None else {}))
    g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals),
                            "TEXCOORD_0": g.accessor(uvs)}, "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
    return g.save(path)


def _cli_render(path, out):
    run = subprocess.run([sys.executable, "-m", "alight", "render", "--mesh", str(path), "--size", "48",
                          "--quality", "low", "--aa", "none", "--orbit", "20", "--elevation", "30", "--out", str(out)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    import OpenImageIO as oiio

    image = oiio.ImageInput.open(str(out))
    pixels = image.read_image(oiio.FLOAT)
    image.close()
    return run.stderr, np.asarray(pixels, np.float64)


def test_gltf_factors_are_read_and_rendered_without_a_warning(tmp_path):
    from alight.exchange.meshes import load_mesh

    path = _plane_file(tmp_path / "f.glb", {"iridescenceFactor": 0.8, "iridescenceIor": 1.7,
                                            "iridescenceThicknessMinimum": 50, "iridescenceThicknessMaximum": 300})
    fm = load_mesh(str(path)).parts[0].material
    assert fm.layers == {"iridescence": 0.8, "iridescence_ior": 1.7, "iridescence_thickness_minimum": 50.0,
                         "iridescence_thickness_maximum": 300.0}
    stderr, with_film = _cli_render(path, tmp_path / "f.exr")
    assert "warning" not in stderr, stderr
    _, without = _cli_render(_plane_file(tmp_path / "n.glb", None), tmp_path / "n.exr")
    inside = without[..., 3] > 0
    assert _rel(with_film, without, inside) > 0.05


def test_gltf_factor_zero_is_the_file_without_the_extension(tmp_path):
    _, zero = _cli_render(_plane_file(tmp_path / "z.glb", {"iridescenceFactor": 0.0, "iridescenceIor": 2.0}),
                          tmp_path / "z.exr")
    _, without = _cli_render(_plane_file(tmp_path / "n.glb", None), tmp_path / "n.exr")
    assert np.array_equal(zero, without)


def test_gltf_textures_equal_their_factors(tmp_path):
    """iridescenceTexture R multiplies the factor; iridescenceThicknessTexture G mixes the
    thickness from the minimum to the maximum (constant maps against the factors they stand for)."""
    image = np.full((8, 8, 4), 255, np.uint8)
    image[..., 0] = 128   # R: the weight 128/255
    image[..., 1] = 51    # G: thickness 100 + (500 - 100) 51/255 = 180 nm
    ext = {"iridescenceFactor": 0.9, "iridescenceIor": 1.8, "iridescenceThicknessMinimum": 100,
           "iridescenceThicknessMaximum": 500}
    _, maps = _cli_render(_plane_file(tmp_path / "m.glb", ext, {"iridescenceTexture": image,
                                                                "iridescenceThicknessTexture": image}), tmp_path / "m.exr")
    _, factors = _cli_render(_plane_file(tmp_path / "f.glb", {"iridescenceFactor": 0.9 * 128 / 255, "iridescenceIor": 1.8,
                                                              "iridescenceThicknessMaximum": 100 + 400 * 51 / 255}),
                             tmp_path / "f.exr")
    _, no_maps = _cli_render(_plane_file(tmp_path / "x.glb", ext), tmp_path / "x.exr")
    inside = factors[..., 3] > 0
    assert _rel(maps, factors, inside) <= 0.01
    assert _rel(no_maps, factors, inside) > 0.05
