"""KHR_materials_clearcoat (docs/layer_clearcoat.md): the GLSL terms against their numpy twins,
the white furnace, a zero-strength coat, the forward pass against its converged twin, and the
reference against the numpy ground truth."""

from __future__ import annotations

import numpy as np
import pytest

from alight.accuracy.converged import downsample_equirect, ibl_converged
from alight.accuracy.ground_truth import layered_ground_truth, probe_points, reflectance_ground_truth
from alight.core.ibl_models import DEFAULT_IBL_MODEL
from alight.core.layers import clearcoat as cc
from alight.core.material import Material
from alight.core.scene import Light, Scene
from alight.core.shading import probe_normals
from alight.ibl.environment import constant_environment, load_environment
from tests.gpu import evaluate, renderer

rng = np.random.default_rng(23)
LAYERS_SHADER = "accuracy/evaluate_layers.comp"
LAYER_DEFINES = {"HAS_CLEARCOAT": None, "HAS_SHEEN": None}


def _rows(n: int):
    nv = rng.uniform(0.02, 1.0, n)
    l = rng.normal(size=(n, 3))
    l /= np.linalg.norm(l, axis=1, keepdims=True)
    l[:, 2] = np.abs(l[:, 2]) * np.where(rng.random(n) < 0.9, 1.0, -1.0)   # a tenth from below
    return nv, l


@pytest.mark.parametrize("punctual, spread", [(True, 0.0), (False, 0.0), (False, 0.05)])
@pytest.mark.parametrize("coat, coat_roughness", [(1.0, 0.1), (0.5, 0.4), (0.8, 1.0), (1.0, 0.0)])
def test_clearcoat_terms_match_their_twins(punctual, spread, coat, coat_roughness):
    nv, l = _rows(400)
    uniforms = {"u_clearcoat": coat, "u_clearcoat_roughness": coat_roughness, "u_punctual": punctual, "u_spread": spread}
    gpu = evaluate(0, np.column_stack([nv, l]), uniforms, LAYERS_SHADER, LAYER_DEFINES)[:, 0]
    v = np.column_stack([np.sqrt(1 - nv * nv), np.zeros_like(nv), nv])
    h = (l + v) / np.linalg.norm(l + v, axis=1, keepdims=True)
    cpu = coat * cc.clearcoat_fresnel(nv) * cc.clearcoat_lobe(l[:, 2], nv, h[:, 2], coat_roughness, punctual, spread)
    np.testing.assert_allclose(gpu, cpu, rtol=5e-4, atol=1e-6)
    weight = evaluate(1, nv[:, None], uniforms, LAYERS_SHADER, LAYER_DEFINES)[:, 0]
    np.testing.assert_allclose(weight, 1.0 - coat * cc.clearcoat_fresnel(nv), rtol=1e-5, atol=1e-6)


# --- the white furnace ----------------------------------------------------------------------

WHITE_METAL = dict(base_color=(1.0, 1.0, 1.0), metallic=1.0)


@pytest.mark.parametrize("roughness", [0.2, 1.0])
@pytest.mark.parametrize("coat_roughness", [0.1, 0.5, 1.0])
def test_white_furnace_ground_truth_never_exceeds_one(roughness, coat_roughness):
    """The coat only moves energy from the base into its own lobe: a white metal under a
    constant environment of radiance 1 reflects at most 1, coated or not, at every n.v."""
    # 1024 wide for the sharpest coat: at coat roughness 0.1 the lobe spans few texels of a
    # coarser map (the texel sum is an integral only where texels are small against the lobe).
    env = constant_environment(1.0, width=1024 if coat_roughness < 0.3 else 256).radiance
    n, _ = probe_points(8)
    m = Material(**WHITE_METAL, roughness=roughness, clearcoat=1.0, clearcoat_roughness=coat_roughness)
    coated = layered_ground_truth(env, n, (0, 0, 1), m)
    bare = reflectance_ground_truth(env, n, (0, 0, 1), m.base_color, m.metallic, m.roughness, m.specular_f0)
    assert coated.max() <= 1.0 + 1e-6, coated.max()
    # The coat takes F_c(n.v) of the base and gives back F_c times its own lobe's albedo, which
    # is a white metal's of the coat's roughness (a GGX lobe without Fresnel).
    coat_lobe = reflectance_ground_truth(env, n, (0, 0, 1), m.base_color, 1.0, coat_roughness, m.specular_f0)
    fc = cc.clearcoat_fresnel(n[:, 2])[:, None]
    # rtol 2e-4: reflectance_ground_truth sums in float32 blocks (the BLAS's block order), which
    # leaves up to ~1e-4 on the sharpest lobes over a 1024-wide map; the layered sum is float64.
    np.testing.assert_allclose(coated, (1.0 - fc) * bare + fc * coat_lobe, rtol=2e-4)


@pytest.mark.parametrize("model", ["alight", "lecture"])
@pytest.mark.parametrize("coat_roughness", [0.0, 0.3, 1.0])
def test_white_furnace_render_never_exceeds_one(model, coat_roughness):
    r = renderer()
    maps = r.bake(constant_environment(1.0, width=256), "medium")
    m = Material(**WHITE_METAL, roughness=0.5, clearcoat=1.0, clearcoat_roughness=coat_roughness)
    img = r.render(Scene(material=m, view="probe", ibl_model=model), maps, 48, 48).linear
    inside = img[..., 3] > 0
    assert img[..., :3][inside].max() <= 1.0 + 2e-3


# --- a zero-strength coat changes nothing ---------------------------------------------------

def test_zero_strength_coat_compiled_in_changes_nothing(monkeypatch, shared_data):
    """With HAS_CLEARCOAT forced on and clearcoat 0 the image is the base's within 0.2%
    (forward pass with point lights and the environment, and the reference)."""
    import alight.accuracy.reference as reference
    import alight.render.variants as forward
    from alight.accuracy.reference import ReferenceRenderer

    r = renderer()
    env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
    maps = r.bake(env, "low")
    m = Material(base_color=(0.7, 0.2, 0.1), roughness=0.4, clearcoat=0.0, clearcoat_roughness=0.2)
    scene = Scene(material=m, view="probe", lights=[Light("point", (2.0, 3.0, 4.0), (1.0, 1.0, 1.0), 30.0)])
    plain = r.render(scene, maps, 32, 32).linear
    small = downsample_equirect(env.radiance, 8)
    ref_plain = ReferenceRenderer(r).render(scene, small, 16, 16).linear
    monkeypatch.setattr(forward, "layer_defines", lambda materials: {"HAS_CLEARCOAT": None})
    monkeypatch.setattr(reference, "layer_defines", lambda materials: {"HAS_CLEARCOAT": None})
    forced = r.render(scene, maps, 32, 32).linear
    ref_forced = ReferenceRenderer(r).render(scene, small, 16, 16).linear
    for a, b in ((forced, plain), (ref_forced, ref_plain)):
        inside = b[..., 3] > 0
        rel = np.abs(a[..., :3] - b[..., :3])[inside].sum() / np.abs(b[..., :3])[inside].sum()
        assert rel <= 0.002, rel


# --- the forward pass against its converged twin, the reference against numpy ---------------

COATED = {
    "coated_red": Material(base_color=(0.5, 0.05, 0.04), roughness=0.5, clearcoat=1.0, clearcoat_roughness=0.25),
    "coated_gold": Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=0.6, clearcoat=0.7,
                            clearcoat_roughness=0.5),
}


@pytest.mark.parametrize("name", COATED)
def test_forward_pass_matches_its_converged_twin(name, shared_data):
    """What the implementation adds to the model's own error (the bake, the LUT, the grid):
    the probe at `medium` against ibl_converged with the coat (royal_esplanade, 2% as for the
    base models)."""
    m = COATED[name]
    r = renderer()
    env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
    maps = r.bake(env, "medium")
    img = r.render(Scene(material=m, view="probe"), maps, 32, 32).linear
    normals, inside = probe_normals(32)
    twin = ibl_converged(DEFAULT_IBL_MODEL, downsample_equirect(env.radiance, 2), normals[inside], (0, 0, 1), m.base_color,
                         m.metallic, m.roughness, m.specular_f0, material=m)
    got = img[..., :3][inside]
    rel = np.abs(got - twin).sum() / np.abs(twin).sum()
    print(f"{name}: {100 * rel:.2f}% off the converged twin")
    assert rel <= 0.02


def test_reference_matches_the_numpy_ground_truth(shared_data):
    from alight.accuracy.reference import ReferenceRenderer, probe_gbuffer

    env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
    small = downsample_equirect(env.radiance, 8)
    m = COATED["coated_red"]
    scene = Scene(material=m, view="probe", env_rotation_deg=40.0, env_intensity=1.3)
    gpu = ReferenceRenderer(renderer()).render_gbuffer(probe_gbuffer(16, m), scene, small).linear
    pts, inside = probe_points(16)
    cpu = layered_ground_truth(small, pts, (0, 0, 1), m, rotation_deg=40.0, intensity=1.3)
    np.testing.assert_allclose(gpu[..., :3][inside], cpu, rtol=2e-4, atol=1e-6)


# --- the coat's textures, by equivalence ----------------------------------------------------

def _file_material(**fields):
    from alight.core.mesh import FileMaterial

    base = dict(base_color=(0.1, 0.15, 0.5), metallic=0.0, roughness=0.6, emissive=(0.0, 0.0, 0.0), alpha=1.0,
                base_color_texture=None, metallic_roughness_texture=None, normal_texture=None, normal_scale=1.0,
                emissive_texture=None, occlusion_texture=None, occlusion_strength=1.0)
    return FileMaterial(**{**base, **fields})


def _draw(material, shared_data):
    import dataclasses as dc

    from alight.core.mesh import sphere

    r = renderer()
    mesh = sphere(64, 32)
    mesh = dc.replace(mesh, parts=[dc.replace(mesh.parts[0], material=material)])
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    scene = Scene(mesh=mesh, material=Material(), use_file_materials=True,
                  lights=[Light("point", (2.0, 3.0, 4.0), (1.0, 1.0, 1.0), 20.0)])
    return r.render(scene, maps, 96, 96, aa="none").linear


def test_clearcoat_textures_equal_their_factors(shared_data):
    """clearcoatTexture R and clearcoatRoughnessTexture G multiply the factors (the extension):
    constant maps render as the product of the factors, within 1% (relMAE, linear)."""
    coat = np.full((8, 8, 4), 255, np.uint8)
    coat[..., 0] = 128   # R: the coat's weight 128/255
    coat[..., 1] = 102   # G: the roughness 102/255 (the roughness map's channel)
    with_maps = _draw(_file_material(layers={"clearcoat": 0.9, "clearcoat_roughness": 0.8}, clearcoat_texture=coat,
                                     clearcoat_roughness_texture=coat), shared_data)
    factors = _draw(_file_material(layers={"clearcoat": 0.9 * 128 / 255, "clearcoat_roughness": 0.8 * 102 / 255}),
                    shared_data)
    inside = factors[..., 3] > 0
    rel = np.abs(with_maps[..., :3] - factors[..., :3])[inside].sum() / np.abs(factors[..., :3])[inside].sum()
    assert rel <= 0.01, rel
    bare = _draw(_file_material(), shared_data)
    assert np.abs(bare[..., :3] - factors[..., :3])[inside].sum() / np.abs(factors[..., :3])[inside].sum() > 0.05


def test_a_flat_coat_normal_map_is_the_geometric_normal(shared_data):
    """A clearcoatNormalTexture of (0.5, 0.5, 1) leaves the coat's normal as it is; the base's own
    normal map does not bend the coat (KHR_materials_clearcoat)."""
    flat = np.zeros((8, 8, 4), np.uint8)
    flat[...] = (128, 128, 255, 255)
    tilted = np.zeros((8, 8, 4), np.uint8)
    tilted[...] = (200, 128, 220, 255)
    layers = {"clearcoat": 1.0, "clearcoat_roughness": 0.2}
    plain = _draw(_file_material(layers=layers), shared_data)
    flat_map = _draw(_file_material(layers=layers, clearcoat_normal_texture=flat), shared_data)
    inside = plain[..., 3] > 0
    assert np.abs(flat_map[..., :3] - plain[..., :3])[inside].sum() / np.abs(plain[..., :3])[inside].sum() <= 0.01
    base_bent = _draw(_file_material(layers=layers, normal_texture=tilted), shared_data)
    coat_bent = _draw(_file_material(layers=layers, clearcoat_normal_texture=tilted), shared_data)
    # Each map bends something the other leaves: the two images differ.
    assert np.abs(base_bent[..., :3] - coat_bent[..., :3])[inside].sum() / np.abs(plain[..., :3])[inside].sum() > 0.02
