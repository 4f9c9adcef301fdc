"""Each shared GLSL function against its numpy twin in app/core/shading.py, on the same inputs.

Tolerances: GLSL runs in float32, the twins in float64, so agreement is to float32 rounding
(relative ~1e-5) except where a function amplifies it (D_GGX near its peak at low roughness).
"""

import numpy as np
import pytest

from alight.core import btdf, shading
from alight.ibl.bake import roughness_to_grid_step
from tests.gpu import evaluate, term_indices

rng = np.random.default_rng(7)


def close(gpu, cpu, rtol=2e-5, atol=2e-6):
    np.testing.assert_allclose(gpu, cpu, rtol=rtol, atol=atol)


def test_d_ggx():
    x = np.column_stack([rng.uniform(0, 1, 500), rng.uniform(0.05, 1, 500)])
    close(evaluate("D_GGX", x)[:, 0], shading.D_GGX(x[:, 0], x[:, 1]), rtol=2e-4)


def test_geometry_terms():
    x = np.column_stack([rng.uniform(1e-4, 1, 500), rng.uniform(1e-3, 1, 500), rng.uniform(0.01, 0.6, 500)])
    close(evaluate("G1", x[:, [0, 2]])[:, 0], shading.G1_SchlickGGX(x[:, 0], x[:, 2]))
    close(evaluate("G_SMITH", x)[:, 0], shading.G_Smith(x[:, 0], x[:, 1], x[:, 2]))
    r = np.linspace(0, 1, 11)
    k = evaluate("K", r[:, None])
    close(k[:, 0], shading.k_direct(r))
    close(k[:, 1], shading.k_ibl(r))
    # The lecture's two k's: (r+1)^2/8 for punctual lights, r^2/2 for IBL.
    assert shading.k_direct(1.0) == 0.5 and shading.k_ibl(1.0) == 0.5 and shading.k_ibl(0.0) == 0.0


def test_fresnel_terms():
    x = np.column_stack([rng.uniform(0, 1, 400), rng.uniform(0, 1, (400, 3))])
    close(evaluate("F_SCHLICK", x)[:, :3], shading.F_Schlick(x[:, 0], x[:, 1:4]))
    z = np.column_stack([rng.uniform(0, 1, 400), rng.uniform(0, 1, 400), rng.uniform(0, 1, 400)])
    close(evaluate("F_SCHLICK_F90", z)[:, :3], shading.F_Schlick(z[:, 0], np.repeat(z[:, 1:2], 3, axis=1), z[:, 2]))
    assert shading.F_Schlick(0.0, (0.0, 0.0, 0.0), 0.0).max() == 0.0   # specularFactor 0: no grazing rim
    y = np.column_stack([rng.uniform(0, 1, 400), rng.uniform(0, 1, 400), rng.uniform(0, 1, 400)])
    close(evaluate("F_SCHLICK_ROUGHNESS", y)[:, :3],
          shading.F_SchlickRoughness(y[:, 0], np.repeat(y[:, 1:2], 3, axis=1), y[:, 2]))


def test_normal_map_roughness():
    # surface.glsl's Toksvig widening: alpha^2 + A^4 (alight.render.normal_spread's A)
    x = np.column_stack([rng.uniform(0, 1, 400), rng.uniform(0, 1, 400)])
    x[:40, 1] = 0.0
    got = evaluate("NORMAL_MAP_ROUGHNESS", x)[:, 0]
    close(got, shading.normal_map_roughness(x[:, 0], x[:, 1]))
    assert np.array_equal(got[:40], x[:40, 0].astype(np.float32))   # A = 0 leaves the roughness exactly
    assert shading.normal_map_roughness(0.0, 0.5) == 0.5


def test_equirect_mapping_both_ways():
    d = shading._normalize(rng.normal(size=(500, 3)))
    uv = evaluate("DIRECTION_TO_EQUIRECT", d)[:, :2]
    close(uv, shading.direction_to_equirect_uv(d), atol=2e-6)
    back = evaluate("EQUIRECT_TO_DIRECTION", uv)[:, :3]
    close(back, d, atol=1e-5)


@pytest.mark.parametrize("deg", [0.0, 37.0, 90.0, -120.0])
def test_rotation(deg):
    d = shading._normalize(rng.normal(size=(100, 3)))
    x = np.column_stack([d, np.full(len(d), deg)])
    close(evaluate("ROTATE_WORLD_TO_MAP", x)[:, :3], shading.rotate_world_to_map(d, deg), atol=1e-6)


def test_hammersley_and_ggx_sampling():
    n = 1024
    i = np.arange(n)
    gpu = evaluate("HAMMERSLEY", np.column_stack([i, np.full(n, n)]))[:, :2]
    close(gpu, shading.hammersley(i, n), atol=1e-7)
    xi = shading.hammersley(i, n)
    for r in (0.1, 0.5, 1.0):
        h = evaluate("IMPORTANCE_SAMPLE_GGX", np.column_stack([xi, np.full(n, r)]))[:, :3]
        close(h, shading.importance_sample_ggx_tangent(xi, r), atol=2e-6)


def test_tonemappers_and_srgb():
    c = np.concatenate([rng.uniform(0, 1, (300, 3)), rng.uniform(0, 50, (300, 3)), np.zeros((1, 3))])
    close(evaluate("ACES", c)[:, :3], shading.tonemap_aces_fitted(c), atol=5e-6)
    close(evaluate("NEUTRAL", c)[:, :3], shading.tonemap_pbr_neutral(c), atol=5e-6)
    s = rng.uniform(0, 1, (300, 3))
    close(evaluate("SRGB", s)[:, :3], shading.linear_to_srgb(s), atol=5e-6)


def test_grid_step_mapping():
    r = np.linspace(0.05, 1.0, 40)
    for levels in (4, 5, 6):
        gpu = evaluate("GRID_STEP", r[:, None], {"u_prefiltered_max_mip": float(levels - 1)})[:, 0]
        close(gpu, roughness_to_grid_step(r, levels), atol=2e-5)


def test_cube_texel_directions_match_opengl_face_order():
    # Texel centres of a 4x4 cube: the direction's major axis names the face (+X -X +Y -Y +Z -Z).
    size = 4
    texels = np.array([(x, y, f, size) for f in range(6) for y in range(size) for x in range(size)], float)
    d = evaluate("CUBE_TEXEL_DIRECTION", texels)[:, :3]
    axis = np.argmax(np.abs(d), axis=1)
    sign = np.sign(d[np.arange(len(d)), axis])
    face = axis * 2 + (sign < 0)
    np.testing.assert_array_equal(face, texels[:, 2].astype(int))
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-6)


def test_punctual_light():
    x = np.column_stack([rng.uniform(0.01, 1, 300), rng.uniform(0, 1, 300), rng.integers(0, 2, 300), rng.uniform(0, 1, 300)])
    gpu = evaluate("PUNCTUAL", x)[:, :3]
    n = np.array([0.0, 0.0, 1.0])
    l = np.column_stack([np.sqrt(1 - x[:, 0] ** 2), np.zeros(len(x)), x[:, 0]])
    cpu = shading.punctual_light(n, n, l, np.repeat(x[:, 3:4], 3, axis=1), x[:, 2], x[:, 1], np.full((len(x), 3), 0.04), 1.0)
    close(gpu, cpu, rtol=3e-4, atol=1e-5)
    assert np.isfinite(gpu).all()


def test_spot_and_range_attenuation():
    x = np.column_stack([rng.uniform(0.5, 1, 300), rng.uniform(1, 20, 300), rng.uniform(-19, 0, 300), rng.uniform(0, 1.5, 300)])
    gpu = evaluate("SPOT_RANGE", x)
    close(gpu[:, 0], shading.spot_attenuation(x[:, 0], x[:, 1], x[:, 2]), rtol=1e-4, atol=1e-6)
    close(gpu[:, 1], shading.range_attenuation(x[:, 3], 1.0), rtol=1e-4, atol=1e-6)


# --- the transmission BTDF and layer (common/btdf.glsl and transmission.glsl against
# app/core/btdf.py and app/core/layers/transmission.py) -------------------------------------

TRANSMISSION_TERMS = term_indices("accuracy/evaluate_transmission.comp")


def evaluate_transmission(term, inputs, uniforms=None, dispersion=False, diffuse=False):
    defines = {"HAS_TRANSMISSION": None, "HAS_VOLUME": None}
    if dispersion:
        defines["HAS_DISPERSION"] = None
    if diffuse:
        defines["HAS_DIFFUSE_TRANSMISSION"] = None
    return evaluate(TRANSMISSION_TERMS[term], inputs, uniforms, shader="accuracy/evaluate_transmission.comp",
                    defines=defines)


def _view_at(n_dot_v):
    return np.column_stack([np.sqrt(1 - n_dot_v ** 2), np.zeros_like(n_dot_v), n_dot_v])


def _light_at(n_dot_l, phi):
    s = np.sqrt(1 - n_dot_l ** 2)
    return np.column_stack([s * np.cos(phi), s * np.sin(phi), n_dot_l])


def test_btdf_thin():
    x = np.column_stack([rng.uniform(0.01, 1, 400), -rng.uniform(0.01, 1, 400), rng.uniform(0, 1, 400),
                         rng.uniform(0.1, 1, 400)])
    gpu = evaluate_transmission("BTDF_THIN", x)
    for column, k in ((0, shading.k_ibl), (1, shading.k_direct)):
        close(gpu[:, column], btdf.btdf_thin(x[:, 0], x[:, 1], x[:, 2], x[:, 3], k(x[:, 3])), rtol=3e-4, atol=1e-6)


def test_btdf_refraction_and_its_half_vector():
    x = np.column_stack([rng.uniform(0.05, 1, 500), -rng.uniform(0.05, 1, 500), rng.uniform(0.2, 1, 500),
                         rng.uniform(1.05, 2.6, 500)])
    gpu = evaluate_transmission("BTDF_REFRACTION", x)
    n = np.array([0.0, 0.0, 1.0])
    value, v_dot_h = btdf.transmission_btdf(n, _view_at(x[:, 0]), _light_at(x[:, 1], np.pi), x[:, 2],
                                            shading.k_ibl(x[:, 2]), x[:, 3], False)
    close(gpu[:, 0], value, rtol=2e-3, atol=1e-5)
    close(np.clip(gpu[:, 1], 0, 1), v_dot_h, atol=1e-5)
    assert (value > 0).sum() > 300   # most of the cases are real refractions, not the zero branch


def test_beer_lambert():
    x = np.column_stack([rng.uniform(0, 1, (200, 3)), rng.uniform(0, 3, 200)])
    x[:10, 3] = 0.0
    for distance in (0.5, 2.0, 3.0e38):
        gpu = evaluate_transmission("BEER_LAMBERT", x, {"u_params": (distance, 0.0, 0.0, 0.0)})[:, :3]
        close(gpu, btdf.beer_lambert(x[:, :3], distance, x[:, 3:4]), rtol=1e-4, atol=1e-6)
    assert np.all(btdf.beer_lambert(x[:, :3], np.inf, x[:, 3:4]) == 1.0)
    np.testing.assert_allclose(btdf.beer_lambert([0.25, 0.5, 1.0], 2.0, 4.0), [0.0625, 0.25, 1.0])


@pytest.mark.parametrize("ior,thickness", [(1.5, 0.0), (1.5, 1.0), (2.4, 0.3), (1.33, 2.0)])
@pytest.mark.parametrize("punctual", [False, True])
def test_transmission_light(ior, thickness, punctual):
    from alight.core.layers.stack import Pairs
    from alight.core.layers.transmission import transmission_light
    from alight.core.material import Material

    x = np.column_stack([-rng.uniform(0.02, 1, 300), rng.uniform(0.02, 1, 300), rng.uniform(0.05, 1, 300),
                         rng.uniform(0, 2 * np.pi, 300)])
    x[:20, 0] *= -1   # some lights in front: no transmitted light there
    params = (ior, thickness, 0.25, float(punctual))
    gpu = evaluate_transmission("TRANSMISSION_LIGHT", x, {"u_params": params})[:, :3]
    cpu = np.empty_like(gpu, dtype=np.float64)
    for i, (nl, nv, r, phi) in enumerate(x):
        m = Material(base_color=(0.9, 0.6, 0.3), metallic=0.25, roughness=r, specular_f0=(0.05, 0.04, 0.03), ior=ior,
                     transmission=0.8, thickness=thickness, attenuation_color=(1.0, 0.8, 0.5), attenuation_distance=0.7)
        p = Pairs(n=np.array([[0.0, 0.0, 1.0]]), v=_view_at(np.array([nv])), l=_light_at(np.array([nl]), np.array([phi])))
        cpu[i] = transmission_light(m, p, punctual)[0, 0]
    close(gpu, cpu, rtol=2e-3, atol=2e-5)
    assert np.isfinite(gpu).all() and (gpu >= 0).all() and np.all(gpu[:20] == 0)


# --- KHR_materials_iridescence (common/iridescence_terms.glsl and iridescence.glsl against
# app/core/layers/iridescence.py; the base BRDF with the film against app/core/layers/stack.py) ---

IRIDESCENCE_TERMS = term_indices("accuracy/evaluate_iridescence.comp")


def evaluate_iridescence(term, inputs, material=None, outside_ior=1.0):
    from alight.core.layers.iridescence import iridescence_uniforms
    from alight.core.material import Material

    m = material or Material()
    uniforms = {"u_params": (outside_ior, m.metallic, m.roughness, 0.0), **iridescence_uniforms(m)}
    return evaluate(IRIDESCENCE_TERMS[term], inputs, uniforms, shader="accuracy/evaluate_iridescence.comp",
                    defines={"HAS_IRIDESCENCE": None})


def test_iridescence_sensitivity():
    from alight.core.layers import iridescence

    x = np.column_stack([rng.uniform(0, 3000, 300), rng.choice([0.0, np.pi, 2 * np.pi], (300, 3))])
    gpu = evaluate_iridescence("SENSITIVITY", x)[:, :3]
    close(gpu, iridescence.iridescence_sensitivity(x[:, 0], x[:, 1:]), rtol=2e-4, atol=2e-5)


@pytest.mark.parametrize("outside_ior", [1.0, 1.5])
def test_iridescence_fresnel(outside_ior):
    from alight.core.layers import iridescence

    x = np.column_stack([rng.uniform(0, 1, 400), rng.uniform(0, 1200, 400), rng.uniform(1.0, 2.4, 400),
                         rng.uniform(0, 1, 400)])
    gpu = evaluate_iridescence("FRESNEL", x, outside_ior=outside_ior)[:, :3]
    cpu = iridescence.iridescence_fresnel(outside_ior, x[:, 2], x[:, 0], x[:, 1], np.repeat(x[:, 3:4], 3, axis=1))
    close(gpu, cpu, rtol=2e-3, atol=2e-4)   # cos of phases up to 2e-9 * 2 pi * 2e6 * 2 * 2.4 * 1200 nm
    assert (gpu >= 0).all() and np.isfinite(gpu).all()


@pytest.mark.parametrize("metallic,thickness", [(0.0, 400.0), (1.0, 250.0), (0.0, 0.0)])
def test_iridescence_base_brdf(metallic, thickness):
    """brdf_ground_truth with the film (accuracy/ground_truth.glsl through common/base_lobes.glsl)
    against stack.layered_brdf_cos, the numpy ground truth's BRDF."""
    from alight.core.layers.stack import Pairs, layered_brdf_cos
    from alight.core.material import Material

    m = Material(base_color=(0.8, 0.5, 0.3), metallic=metallic, roughness=0.4, iridescence=0.8,
                 iridescence_ior=1.4, iridescence_thickness_maximum=thickness)
    nv = rng.uniform(0.05, 1, 200)
    l = _light_at(rng.uniform(0.05, 1, 200), rng.uniform(0, 2 * np.pi, 200))
    gpu = evaluate_iridescence("BASE_BRDF", np.column_stack([nv, l]), m)[:, :3]
    cpu = np.stack([layered_brdf_cos(m, Pairs(n=np.array([[0.0, 0.0, 1.0]]), v=_view_at(nv[i:i + 1]), l=l[i:i + 1]))[0, 0]
                    for i in range(len(nv))])
    close(gpu, cpu, rtol=2e-3, atol=2e-5)


def test_iridescence_ibl_weights():
    from alight.core.layers import iridescence
    from alight.core.material import Material
    m = Material(roughness=0.3, iridescence=0.6, iridescence_ior=1.8, iridescence_thickness_maximum=500.0)
    x = np.column_stack([rng.uniform(0.01, 1, 200), rng.uniform(0, 1, 200), rng.uniform(0, 0.2, 200)])
    gpu = evaluate_iridescence("IBL_WEIGHTS", x, m)
    film = iridescence.iridescence_fresnel_at_view(m, x[:, 0])
    f0 = np.full((len(x), 3), 0.04)
    dfres = 8.233601e-05 + (1 - x[:, 0]) * (0.002021979 + (1 - x[:, 0]) * (0.009310647 + (1 - x[:, 0]) * (0.007795988 + (1 - x[:, 0]) * 0.0089526)))
    dw, spec = iridescence.iridescence_ibl_weights(film, m.iridescence, x[:, 1], x[:, 2],
                                                   1 - f0 - (1 - f0) * dfres[:, None], f0 * x[:, 1:2] + x[:, 2:3])
    close(gpu[:, :3], spec, rtol=2e-3, atol=2e-5)
    close(gpu[:, 3], dw[:, 0], rtol=2e-3, atol=2e-5)


# --- KHR_materials_dispersion (common/dispersion_terms.glsl and transmission.glsl against
# app/core/layers/dispersion.py and transmission.py) ------------------------------------------

def test_dispersion_iors():
    from alight.core.layers.dispersion import dispersion_iors

    x = np.column_stack([rng.uniform(1.0, 3.0, 200), rng.uniform(0.0, 2.0, 200)])
    gpu = evaluate_transmission("DISPERSION_IORS", x, dispersion=True)[:, :3]
    close(gpu, np.array([dispersion_iors(ior, d) for ior, d in x]), rtol=1e-6)
    # Abbe number 40 (dispersion 0.5) at ior 1.5: n_F - n_C = 0.5 / 40 = 0.0125, centred on n_d.
    np.testing.assert_allclose(dispersion_iors(1.5, 0.5), [1.49375, 1.5, 1.50625])


@pytest.mark.parametrize("ior,thickness,dispersion", [(1.5, 1.0, 1.0), (2.4, 0.3, 3.0), (1.5, 0.0, 2.0)])
@pytest.mark.parametrize("punctual", [False, True])
def test_dispersed_transmission_light(ior, thickness, dispersion, punctual):
    """transmission_light with HAS_DISPERSION: each channel at its own index (a thin wall: none)."""
    from alight.core.layers.stack import Pairs
    from alight.core.layers.transmission import transmission_light
    from alight.core.material import Material

    x = np.column_stack([-rng.uniform(0.02, 1, 300), rng.uniform(0.02, 1, 300), rng.uniform(0.05, 1, 300),
                         rng.uniform(0, 2 * np.pi, 300)])
    params = (ior, thickness, 0.25, float(punctual))
    gpu = evaluate_transmission("TRANSMISSION_LIGHT", x, {"u_params": params, "u_dispersion_factor": dispersion},
                                dispersion=True)[:, :3]
    cpu = np.empty_like(gpu, dtype=np.float64)
    plain = np.empty_like(cpu)
    for i, (nl, nv, r, phi) in enumerate(x):
        m = Material(base_color=(0.9, 0.6, 0.3), metallic=0.25, roughness=r, specular_f0=(0.05, 0.04, 0.03), ior=ior,
                     transmission=0.8, thickness=thickness, attenuation_color=(1.0, 0.8, 0.5), attenuation_distance=0.7,
                     dispersion=dispersion)
        p = Pairs(n=np.array([[0.0, 0.0, 1.0]]), v=_view_at(np.array([nv])), l=_light_at(np.array([nl]), np.array([phi])))
        cpu[i] = transmission_light(m, p, punctual)[0, 0]
        plain[i] = transmission_light(Material(**{**m.__dict__, "dispersion": 0.0}), p, punctual)[0, 0]
    close(gpu, cpu, rtol=2e-3, atol=2e-5)
    if thickness > 0.0:   # the channels really refract apart (red and blue differ from undispersed)
        assert np.abs(cpu[:, 0] - plain[:, 0]).max() > 1e-3 and np.abs(cpu[:, 2] - plain[:, 2]).max() > 1e-3
        np.testing.assert_allclose(cpu[:, 1], plain[:, 1], rtol=1e-12)
    else:
        np.testing.assert_allclose(cpu, plain, rtol=1e-12)


# --- KHR_materials_diffuse_transmission (common/diffuse_transmission_terms.glsl and
# diffuse_transmission.glsl against app/core/layers/diffuse_transmission.py) ---------------------

def test_diffuse_btdf_cos():
    from alight.core.layers.diffuse_transmission import diffuse_btdf_cos

    x = np.column_stack([rng.uniform(0, 1, (300, 3)), rng.uniform(-1, 1, 300)])
    gpu = evaluate_transmission("DIFFUSE_BTDF_COS", x)[:, :3]
    close(gpu, np.array([diffuse_btdf_cos(c, nl) for c, nl in zip(x[:, :3], x[:, 3])]))
    assert np.all(gpu[x[:, 3] >= 0] == 0)


@pytest.mark.parametrize("thickness", [0.0, 0.8])
def test_diffuse_transmission_light(thickness):
    from alight.core.layers.diffuse_transmission import diffuse_transmission_light, front_weight
    from alight.core.layers.stack import Pairs
    from alight.core.material import Material

    x = np.column_stack([-rng.uniform(0.02, 1, 300), rng.uniform(0.02, 1, 300), rng.uniform(0.05, 1, 300),
                         rng.uniform(0, 2 * np.pi, 300)])
    x[:20, 0] *= -1   # some lights in front: no transmitted light there
    params = (1.5, thickness, 0.25, 0.7)
    gpu = evaluate_transmission("DIFFUSE_TRANSMISSION_LIGHT", x, {"u_params": params}, diffuse=True)
    cpu = np.empty((len(x), 3))
    for i, (nl, nv, t, phi) in enumerate(x):
        m = Material(base_color=(0.9, 0.6, 0.3), metallic=0.25, roughness=0.4, specular_f0=(0.05, 0.04, 0.03), ior=1.5,
                     transmission=t, thickness=thickness, attenuation_color=(1.0, 0.8, 0.5), attenuation_distance=0.7,
                     diffuse_transmission=0.7, diffuse_transmission_color=(0.2, 0.9, 0.6))
        p = Pairs(n=np.array([[0.0, 0.0, 1.0]]), v=_view_at(np.array([nv])), l=_light_at(np.array([nl]), np.array([phi])))
        cpu[i] = diffuse_transmission_light(m, p)[0, 0]
    close(gpu[:, :3], cpu, rtol=2e-4, atol=1e-6)
    close(gpu[:, 3], np.full(len(x), front_weight(m)))
    assert np.all(gpu[:20, :3] == 0) and (gpu[20:, 1] > 0).all()
