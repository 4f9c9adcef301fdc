"""KHR_materials_sheen (docs/layer_sheen.md): the Charlie terms and the sheen LUT against their
numpy twins, the white furnace, a zero-strength sheen, the forward pass against its converged
twin, and the reference against the numpy ground truth."""

from __future__ import annotations

import numpy as np
import pytest

from alight.accuracy.converged import downsample_equirect, ibl_converged
from alight.accuracy.ground_truth import layered_ground_truth, probe_points
from alight.core.ibl_models import DEFAULT_IBL_MODEL
from alight.core.layers import sheen as sh
from alight.core.material import Material
from alight.core.scene import Light, Scene
from alight.core.shading import probe_normals
from alight.ibl.bake import read_lut
from alight.ibl.environment import constant_environment, load_environment
from tests.gpu import evaluate, renderer

rng = np.random.default_rng(29)
LAYERS_SHADER = "accuracy/evaluate_layers.comp"
LAYER_DEFINES = {"HAS_CLEARCOAT": None, "HAS_SHEEN": None}
UNIT = 13   # app/render/renderer.py: UNIT_SHEEN_LUT


def test_charlie_terms_match_their_twins():
    x = np.column_stack([rng.uniform(0, 1, 500), rng.uniform(0.01, 1, 500), rng.uniform(0.01, 1, 500),
                         rng.uniform(0.0049, 1, 500)])
    gpu = evaluate(5, x, None, LAYERS_SHADER, LAYER_DEFINES)
    np.testing.assert_allclose(gpu[:, 0], sh.D_Charlie(x[:, 0], x[:, 3]), rtol=2e-4, atol=1e-6)
    np.testing.assert_allclose(gpu[:, 1], sh.V_Charlie(x[:, 1], x[:, 2], x[:, 3]), rtol=2e-4, atol=1e-7)
    np.testing.assert_allclose(gpu[:, 2], sh.sheen_lambda(x[:, 1], x[:, 3]), rtol=2e-4, atol=1e-7)


def test_the_lut_matches_its_twin():
    """ibl/sheen_lut.comp against the numpy quadrature (sheen_lut_table): E to 1e-5; the lobe's
    direction and width where the lobe carries anything (E > 1e-4)."""
    gpu = read_lut(renderer().luts.sheen()).astype(np.float64)
    cpu = sh.sheen_lut_table()
    np.testing.assert_allclose(gpu[..., 0], cpu[..., 0], atol=1e-5)
    carries = cpu[..., 0] > 1e-4
    np.testing.assert_allclose(gpu[..., 1][carries], cpu[..., 1][carries], atol=1e-4)
    np.testing.assert_allclose(gpu[..., 2][carries], cpu[..., 2][carries], atol=1e-4)


def test_the_lut_integrates_the_lobe():
    """The table's quadrature against a finer one (its own error, part of the definition)."""
    for mu, r in ((0.05, 0.1), (0.3, 0.3), (0.7, 0.8), (0.95, 1.0)):
        assert sh.directional_albedo(mu, r) == pytest.approx(sh.directional_albedo(mu, r, 640), rel=2e-3, abs=1e-6)


@pytest.mark.parametrize("punctual", [True, False])
@pytest.mark.parametrize("color, roughness", [((1.0, 1.0, 1.0), 0.3), ((0.2, 0.5, 0.9), 0.07), ((0.6, 0.3, 0.1), 1.0)])
def test_sheen_terms_match_their_twins(punctual, color, roughness):
    from alight.core.layers.stack import Pairs

    r = renderer()
    r.luts.sheen().use(UNIT)
    n = 400
    nv = rng.uniform(0.02, 1.0, n)
    l = rng.normal(size=(n, 3))
    l /= np.linalg.norm(l, axis=1, keepdims=True)
    l[:, 2] = np.abs(l[:, 2]) * np.where(rng.random(n) < 0.9, 1.0, -1.0)
    uniforms = {"u_sheen_color": color, "u_sheen_roughness": roughness, "u_punctual": punctual, "u_spread": 0.0,
                "u_sheen_lut": UNIT}
    rows = np.column_stack([nv, l])
    m = Material(sheen_color=color, sheen_roughness=roughness)
    v = np.column_stack([np.sqrt(1 - nv * nv), np.zeros(n), nv])
    # One pair per row: the diagonal of a (n, n) Pairs.
    cpu_light = np.array([sh.sheen_light(m, Pairs(n=np.array([[0, 0, 1.0]]), v=v[i:i + 1], l=l[i:i + 1]))[0, 0]
                          for i in range(n)])
    cpu_weight = np.array([sh.sheen_base_weight(m, Pairs(n=np.array([[0, 0, 1.0]]), v=v[i:i + 1], l=l[i:i + 1]))[0, 0]
                           for i in range(n)])
    gpu_light = evaluate(2, rows, uniforms, LAYERS_SHADER, LAYER_DEFINES)[:, :3]
    gpu_weight = evaluate(3, rows, uniforms, LAYERS_SHADER, LAYER_DEFINES)[:, 0]
    gpu_weight_ibl = evaluate(4, rows, uniforms, LAYERS_SHADER, LAYER_DEFINES)[:, 0]
    np.testing.assert_allclose(gpu_light, cpu_light, rtol=1e-3, atol=2e-6)
    np.testing.assert_allclose(gpu_weight, cpu_weight, atol=2e-5)
    np.testing.assert_allclose(gpu_weight_ibl, sh.sheen_scaling(color, sh.sheen_albedo(nv, roughness)), atol=2e-5)


# --- the white furnace ----------------------------------------------------------------------

WHITE_METAL = dict(base_color=(1.0, 1.0, 1.0), metallic=1.0)


@pytest.mark.parametrize("roughness", [0.2, 1.0])
@pytest.mark.parametrize("sheen_roughness", [0.07, 0.3, 1.0])
def test_white_furnace_ground_truth_never_exceeds_one(roughness, sheen_roughness):
    """White sheen over a white metal under a constant environment of radiance 1 reflects at
    most 1 at every n.v (the albedo scaling; E capped at 1 where the fit exceeds it)."""
    env = constant_environment(1.0, width=256).radiance
    n, _ = probe_points(12)
    m = Material(**WHITE_METAL, roughness=roughness, sheen_color=(1.0, 1.0, 1.0), sheen_roughness=sheen_roughness)
    out = layered_ground_truth(env, n, (0, 0, 1), m)
    assert out.max() <= 1.0 + 1e-6, out.max()


@pytest.mark.parametrize("model", ["alight", "lecture"])
@pytest.mark.parametrize("sheen_roughness", [0.07, 0.5, 1.0])
def test_white_furnace_render_never_exceeds_one(model, sheen_roughness):
    r = renderer()
    maps = r.bake(constant_environment(1.0, width=256), "medium")
    m = Material(**WHITE_METAL, roughness=0.5, sheen_color=(1.0, 1.0, 1.0), sheen_roughness=sheen_roughness)
    img = r.render(Scene(material=m, view="probe", ibl_model=model), maps, 48, 48).linear
    inside = img[..., 3] > 0
    assert img[..., :3][inside].max() <= 1.0 + 2e-3


# --- a zero-strength sheen changes nothing --------------------------------------------------

def test_zero_strength_sheen_compiled_in_changes_nothing(monkeypatch, shared_data):
    import alight.accuracy.reference as reference
    import alight.render.variants as forward
    from alight.accuracy.reference import ReferenceRenderer

    r = renderer()
    env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
    maps = r.bake(env, "low")
    m = Material(base_color=(0.7, 0.2, 0.1), roughness=0.4, sheen_color=(0.0, 0.0, 0.0), sheen_roughness=0.5)
    scene = Scene(material=m, view="probe", lights=[Light("point", (2.0, 3.0, 4.0), (1.0, 1.0, 1.0), 30.0)])
    plain = r.render(scene, maps, 32, 32).linear
    small = downsample_equirect(env.radiance, 8)
    ref_plain = ReferenceRenderer(r).render(scene, small, 16, 16).linear
    monkeypatch.setattr(forward, "layer_defines", lambda materials: {"HAS_SHEEN": None})
    monkeypatch.setattr(reference, "layer_defines", lambda materials: {"HAS_SHEEN": None})
    forced = r.render(scene, maps, 32, 32).linear
    ref_forced = ReferenceRenderer(r).render(scene, small, 16, 16).linear
    for a, b in ((forced, plain), (ref_forced, ref_plain)):
        inside = b[..., 3] > 0
        rel = np.abs(a[..., :3] - b[..., :3])[inside].sum() / np.abs(b[..., :3])[inside].sum()
        assert rel <= 0.002, rel


# --- the forward pass against its converged twin, the reference against numpy ---------------

SHEENED = {
    "velvet_like": Material(base_color=(0.25, 0.02, 0.06), roughness=0.8, sheen_color=(0.9, 0.4, 0.55),
                            sheen_roughness=0.4),
    "sheen_gold": Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=0.5, sheen_color=(0.5, 0.5, 0.5),
                           sheen_roughness=0.8),
}


@pytest.mark.parametrize("name", SHEENED)
def test_forward_pass_matches_its_converged_twin(name, shared_data):
    m = SHEENED[name]
    r = renderer()
    env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
    maps = r.bake(env, "medium")
    img = r.render(Scene(material=m, view="probe"), maps, 32, 32).linear
    normals, inside = probe_normals(32)
    twin = ibl_converged(DEFAULT_IBL_MODEL, downsample_equirect(env.radiance, 2), normals[inside], (0, 0, 1), m.base_color,
                         m.metallic, m.roughness, m.specular_f0, material=m)
    rel = np.abs(img[..., :3][inside] - twin).sum() / np.abs(twin).sum()
    print(f"{name}: {100 * rel:.2f}% off the converged twin")
    assert rel <= 0.02


def test_reference_matches_the_numpy_ground_truth(shared_data):
    from alight.accuracy.reference import ReferenceRenderer, probe_gbuffer

    env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
    small = downsample_equirect(env.radiance, 8)
    m = SHEENED["velvet_like"]
    scene = Scene(material=m, view="probe", env_rotation_deg=-70.0, env_intensity=0.8)
    gpu = ReferenceRenderer(renderer()).render_gbuffer(probe_gbuffer(16, m), scene, small).linear
    pts, inside = probe_points(16)
    cpu = layered_ground_truth(small, pts, (0, 0, 1), m, rotation_deg=-70.0, intensity=0.8)
    np.testing.assert_allclose(gpu[..., :3][inside], cpu, rtol=5e-4, atol=1e-6)
