"""KHR_materials_anisotropy (docs/layer_anisotropy.md): the GLSL terms against their numpy twins,
the exact BRDF's limits (strength 0 is docs/conventions.md's BRDF; a white metal never reflects more
than it receives), and the exact answer on the GPU against numpy."""

from __future__ import annotations

import numpy as np
import pytest

from alight.core import shading
from alight.core.ibl_models import DEFAULT_IBL_MODEL
from alight.core.layers import anisotropy
from alight.core.layers.stack import Pairs, layered_brdf_cos
from alight.core.material import Material
from tests.gpu import evaluate

rng = np.random.default_rng(11)
SHADER = "accuracy/evaluate_anisotropy.comp"
DEFINES = {"HAS_ANISOTROPY": None}
TERM_ALPHA, TERM_D, TERM_PROJECTED, TERM_PUNCTUAL, TERM_SPECULAR = range(5)


def aniso(term, inputs, **uniforms):
    return evaluate(term, inputs, uniforms, shader=SHADER, defines=DEFINES)


def unit_xy(count):
    """Directions in the upper hemisphere as their (x, y), z = sqrt(1 - x^2 - y^2) > 0.05."""
    d = shading._normalize(rng.normal(size=(count, 3)))
    d[:, 2] = np.abs(d[:, 2]) + 0.05
    d = shading._normalize(d)
    return d


def test_alpha_d_and_projected_alpha_match_their_twins():
    x = np.column_stack([rng.uniform(0, 1, 300), rng.uniform(0, 1, 300)])
    at, ab = anisotropy.anisotropic_alpha(x[:, 0], x[:, 1])
    np.testing.assert_allclose(aniso(TERM_ALPHA, x)[:, :2], np.column_stack([at, ab]), rtol=2e-6, atol=1e-7)
    h = unit_xy(400)
    alphas = np.column_stack([rng.uniform(0.05, 1, 400), rng.uniform(0.02, 1, 400)])
    gpu = aniso(TERM_D, np.column_stack([h[:, :2], alphas]))[:, 0]
    np.testing.assert_allclose(gpu, anisotropy.D_GGX_anisotropic(h[:, 0], h[:, 1], h[:, 2], alphas[:, 0], alphas[:, 1]),
                               rtol=5e-4)
    gpu = aniso(TERM_PROJECTED, np.column_stack([h[:, :2], alphas]))[:, 0]
    np.testing.assert_allclose(gpu, anisotropy.projected_alpha(h[:, 0], h[:, 1], alphas[:, 0], alphas[:, 1]), rtol=2e-6)


def test_the_anisotropic_d_is_normalised_and_isotropic_at_equal_alphas():
    # int D(h) (n.h) dh = 1 over the hemisphere, for any pair of alphas (midpoint rule in theta, phi).
    th = (np.arange(1500) + 0.5) * (np.pi / 2 / 1500)
    ph = (np.arange(600) + 0.5) * (2 * np.pi / 600)
    T, P = np.meshgrid(th, ph, indexing="ij")
    h = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1)
    dw = np.sin(T) * (np.pi / 2 / 1500) * (2 * np.pi / 600)
    for at, ab in ((0.3, 0.3), (0.6, 0.1), (1.0, 0.25)):
        D = anisotropy.D_GGX_anisotropic(h[..., 0], h[..., 1], h[..., 2], at, ab)
        assert float(np.sum(D * h[..., 2] * dw)) == pytest.approx(1.0, abs=2e-3)
    r = rng.uniform(0.1, 1, 50)
    np.testing.assert_allclose(anisotropy.D_GGX_anisotropic(0.3, 0.4, np.sqrt(0.75), r * r, r * r),
                               shading.D_GGX(np.sqrt(0.75), r), rtol=1e-12)


def _pairs(v, l, rotation=0.0):
    n = np.array([[0.0, 0.0, 1.0]])
    return Pairs(n=n, v=v[None, :], l=l, t=np.array([[1.0, 0.0, 0.0]]), b=np.array([[0.0, 1.0, 0.0]]))


@pytest.mark.parametrize("rotation", [0.0, 0.7])
def test_punctual_and_exact_lobes_match_their_twins(rotation):
    v = shading._normalize(np.array([0.5, -0.3, 0.8]))
    l = unit_xy(300)
    rough = rng.uniform(0.0, 1.0, 300)
    strength = rng.uniform(0.0, 1.0, 300)
    inputs = np.column_stack([l[:, :2], rough, strength])
    base = np.array([0.8, 0.5, 0.2])
    for metallic in (0.0, 1.0):
        gpu = aniso(TERM_PUNCTUAL, inputs, u_view=tuple(v), u_base_color=tuple(base), u_metallic=metallic,
                    u_anisotropy_rotation=rotation)[:, :3]
        cpu = np.empty_like(gpu, dtype=np.float64)
        for i in range(len(l)):
            m = Material(base_color=tuple(base), metallic=metallic, roughness=float(rough[i]),
                         anisotropy_strength=float(strength[i]), anisotropy_rotation=rotation)
            p = _pairs(v, l[i:i + 1])
            F = shading.F_Schlick(p.v_dot_h, np.asarray(m.f0()))
            spec = anisotropy.anisotropic_specular(m, p, F, punctual=True)[0, 0]
            kd = (1.0 - F[0, 0]) * (1.0 - metallic)
            cpu[i] = (kd * base / np.pi + spec) * l[i, 2]
        np.testing.assert_allclose(gpu, cpu, rtol=2e-3, atol=1e-5)
    gpu = aniso(TERM_SPECULAR, inputs, u_view=tuple(v), u_spread=0.0, u_anisotropy_rotation=rotation)[:, :3]
    keep = rough >= 0.05
    cpu = np.array([anisotropy.anisotropic_specular(
        Material(roughness=float(rough[i]), anisotropy_strength=float(strength[i]), anisotropy_rotation=rotation),
        _pairs(v, l[i:i + 1]), np.ones((1, 1, 3)))[0, 0] for i in range(len(l))])
    np.testing.assert_allclose(gpu[keep], cpu[keep], rtol=2e-3, atol=1e-5)


def _sphere(n_theta=400, n_phi=800):
    th = (np.arange(n_theta) + 0.5) * (np.pi / n_theta)
    ph = (np.arange(n_phi) + 0.5) * (2 * np.pi / n_phi)
    T, P = np.meshgrid(th, ph, indexing="ij")
    l = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    return l, (np.sin(T) * (np.pi / n_theta) * (2 * np.pi / n_phi)).reshape(-1)


def test_strength_zero_is_conventions_brdf_exactly():
    l, _ = _sphere(60, 120)
    v = shading._normalize(np.array([0.3, 0.2, 0.9]))
    for r in (0.1, 0.4, 1.0):
        iso = Material(base_color=(0.9, 0.6, 0.3), metallic=0.5, roughness=r)
        # A strength of 1e-12 turns the layer on (Material.layers) with an isotropic lobe.
        on = Material(base_color=(0.9, 0.6, 0.3), metallic=0.5, roughness=r, anisotropy_strength=1e-12,
                      anisotropy_rotation=0.4)
        assert "anisotropy" in on.layers() and "anisotropy" not in iso.layers()
        np.testing.assert_allclose(layered_brdf_cos(on, _pairs(v, l)), layered_brdf_cos(iso, _pairs(v, l)),
                                   rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("strength", [0.5, 1.0])
def test_white_metal_furnace_never_exceeds_one(strength):
    # The exact BRDF of a metal with F0 = 1 under radiance 1: its directional albedo, over views
    # from normal to grazing and the view's azimuth against the direction.
    l, dw = _sphere()
    worst = 0.0
    for r in (0.1, 0.3, 0.6, 1.0):
        m = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=r, anisotropy_strength=strength)
        for nv in (1.0, 0.7, 0.3, 0.05):
            for azimuth in (0.0, 0.8, np.pi / 2):
                s = np.sqrt(1 - nv * nv)
                v = np.array([s * np.cos(azimuth), s * np.sin(azimuth), nv])
                albedo = float(np.sum(layered_brdf_cos(m, _pairs(v, l))[0, :, 0] * dw))
                worst = max(worst, albedo)
    assert worst <= 1.0


def test_anisotropic_ground_truth_sums_agree_with_the_pairwise_sum():
    # The S1..S4 factorisation (ground_truth.anisotropic_ground_truth_terms) against the layered
    # BRDF summed pair by pair (ground_truth.layered_ground_truth), and against the isotropic
    # sums at strength 0, on a random 24x48 map.
    from alight.accuracy import ground_truth as gt

    radiance = rng.uniform(0.0, 2.0, (24, 48, 3))
    normals = shading._normalize(rng.normal(size=(40, 3)) + np.array([0.0, 0.0, 2.0]))
    view = (0.2, 0.1, 0.97)
    tangents = shading._normalize(rng.normal(size=(40, 3)))
    cases = [(0.3, 0.8, 0.5), (0.6, 1.0, -1.0), (0.45, 0.0, 0.0)]
    terms = gt.anisotropic_ground_truth_terms(radiance, normals, view, tangents, cases, rotation_deg=30.0)
    for (r, strength, rotation), term in zip(cases, terms):
        m = Material(base_color=(0.7, 0.4, 0.2), metallic=0.3, roughness=r, anisotropy_strength=strength,
                     anisotropy_rotation=rotation)
        got = term.combine(m.base_color, m.metallic, m.specular_f0)
        t = tangents - normals * np.sum(normals * tangents, -1, keepdims=True)
        want = gt.layered_ground_truth(radiance, normals, view, m, t, rotation_deg=30.0) if strength else \
            gt.reflectance_ground_truth(radiance, normals, view, m.base_color, m.metallic, r, m.specular_f0,
                                        rotation_deg=30.0)
        np.testing.assert_allclose(got, want, rtol=2e-5, atol=1e-7)


# ---- image-based light ------------------------------------------------------------------------

def test_energy_lut_matches_its_quadrature_and_is_one_at_strength_zero():
    from alight.accuracy.converged import anisotropy_lut_converged
    from tests.gpu import renderer

    lut = renderer().anisotropy_lut
    table = lut.table()                                # (2, strength, roughness, n.v, azimuth)
    nx, ny, nz = lut.size
    np.testing.assert_allclose(table[:, 0], 1.0, atol=1e-5)   # strength 0: exactly the round lobe's
    for (i, j, k, az) in ((20, 5, nz - 1, 0), (10, 8, nz - 1, 3), (28, 4, nz // 2, 1), (6, 12, nz - 1, 2)):
        n_dot_v, rough, strength = (i + 0.5) / nx, (j + 0.5) / ny, k / (nz - 1)
        ra, rb = anisotropy_lut_converged(n_dot_v, rough, strength, np.radians(30.0 * az))
        assert table[0, k, j, i, az] == pytest.approx(ra, rel=0.02), (n_dot_v, rough, strength, az)
        assert table[1, k, j, i, az] == pytest.approx(rb, rel=0.05, abs=0.02), (n_dot_v, rough, strength, az)


def _probe(r, maps, material, width, model="alight", **scene):
    from alight.core.scene import Scene

    return r.render(Scene(material=material, view="probe", ibl_model=model, **scene), maps, width, width,
                    read_srgb=False).linear


@pytest.mark.parametrize("rotation", [0.0, 1.2])
def test_probe_within_bound_of_its_converged_twin(shared_data, rotation):
    # The implementation's own error (bake, LUTs, grid blending) against the numpy twin of the
    # same lookup with converged parts, on royal_esplanade reduced by 4: the bound of
    # test_probe_accuracy.py for a metal (2%).
    from alight.accuracy.converged import downsample_equirect, ibl_converged
    from alight.ibl.environment import Environment, load_environment
    from tests.gpu import renderer

    width = 24
    radiance = downsample_equirect(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")).radiance, 4)
    env = Environment(np.ascontiguousarray(radiance, np.float32), "royal/4")
    r = renderer()
    maps = r.bake(env, "medium")
    normals, inside = shading.probe_normals(width)
    for rough, strength in ((0.35, 0.8), (0.6, 1.0)):
        m = Material(base_color=(0.91, 0.92, 0.92), metallic=1.0, roughness=rough, anisotropy_strength=strength,
                     anisotropy_rotation=rotation)
        got = _probe(r, maps, m, width)[..., :3][inside]
        ideal = ibl_converged(DEFAULT_IBL_MODEL, radiance, normals[inside], (0.0, 0.0, 1.0), m.base_color, m.metallic, rough,
                              m.specular_f0, material=m)
        error = float(np.abs(got - ideal).sum() / np.abs(ideal).sum())
        print(f"r={rough} strength={strength} rotation={rotation}: {100 * error:.2f}%")
        assert error <= 0.02


def test_white_furnace_stays_at_or_below_one():
    # A white metal (F0 = 1) under radiance 1: the stretched lobe's energy (the LUT ratios times
    # the round lobe's A + B) never exceeds 1; with multiple scattering it is 1.
    from alight.ibl.environment import constant_environment
    from tests.gpu import renderer

    r = renderer()
    maps = r.bake(constant_environment(1.0), "medium")
    width = 32
    _, inside = shading.probe_normals(width)
    for rough in (0.2, 0.5, 1.0):
        for strength in (0.5, 1.0):
            m = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=rough, anisotropy_strength=strength,
                         anisotropy_rotation=0.4)
            single = _probe(r, maps, m, width)[..., :3][inside]
            multiple = _probe(r, maps, m, width, multiple_scattering=True)[..., :3][inside]
            print(f"r={rough} strength={strength}: single {single.min():.4f}-{single.max():.4f}, "
                  f"multiple {multiple.min():.4f}-{multiple.max():.4f}")
            assert single.max() <= 1.0 + 2e-3, (rough, strength, float(single.max()))
            assert np.abs(multiple - 1.0).max() <= 5e-3, (rough, strength, float(np.abs(multiple - 1.0).max()))


def test_a_zero_strength_part_drawn_with_the_layer_compiled_in_changes_nothing(shared_data):
    # A mesh whose parts mix an anisotropic material with a plain one compiles HAS_ANISOTROPY for
    # both; the plain part then runs the layer's code at strength 0 (punctual lights, the compact
    # sources and the environment). It must match the same part drawn without the layer within
    # 0.2% (the layers' zero-strength bound).
    import dataclasses

    from alight.core.mesh import FileMaterial, Mesh, sphere
    from alight.core.scene import Camera, Light, Scene
    from alight.ibl.environment import load_environment
    from tests.gpu import renderer

    def part(offset, layers):
        p = sphere(64, 32).parts[0]
        fm = FileMaterial(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.4, emissive=(0.0, 0.0, 0.0),
                          alpha=1.0, base_color_texture=None, metallic_roughness_texture=None, normal_texture=None,
                          normal_scale=1.0, emissive_texture=None, occlusion_texture=None, occlusion_strength=1.0,
                          layers=layers)
        return dataclasses.replace(p, positions=p.positions + np.float32(offset), material=fm, name=str(offset))

    plain = part((1.2, 0.0, 0.0), {})
    stretched = part((-1.2, 0.0, 0.0), {"anisotropy_strength": 0.9, "anisotropy_rotation": 0.5})
    camera = Camera(position=(0.0, 0.0, 6.0), target=(0.0, 0.0, 0.0))
    lights = [Light(vector=(2.0, 3.0, 4.0), intensity=30.0)]
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "quarry_01_1k.hdr")), "medium")   # a sun: suns_exact too

    def draw(parts):
        # Light that is blocked (one ball shadows and occludes the other) is not what this measures.
        scene = Scene(mesh=Mesh(parts, "two"), camera=camera, lights=lights, shadows="off", occlusion="off")
        return r.render(scene, maps, 192, 96, aa="none").linear

    both = draw([stretched, plain])
    alone = draw([plain])
    mask = (alone[..., 3] > 0) & (np.arange(192)[None, :] >= 96)   # the plain part's half of the image
    assert mask.sum() > 1000
    error = np.abs(both[mask, :3] - alone[mask, :3]).sum() / np.abs(alone[mask, :3]).sum()
    print(f"zero-strength part: {100 * error:.4f}%")
    assert error <= 0.002, error
    # ... and the anisotropic part does change.
    left = (both[..., 3] > 0) & (np.arange(192)[None, :] < 96)
    assert np.abs(both[left, :3] - draw([dataclasses.replace(stretched, material=plain.material)])[left, :3]).mean() > 0.01


def test_reference_on_the_gpu_matches_the_numpy_ground_truth(shared_data):
    # alight reference (accuracy/reference.comp through the layer's anisotropic_specular) against
    # anisotropic_ground_truth_terms, on a probe over royal_esplanade reduced by 8 and turned by
    # 30 degrees (the stretch's direction goes into the map's frame with the normal).
    from alight.accuracy.converged import downsample_equirect
    from alight.accuracy.ground_truth import anisotropic_ground_truth_terms, probe_points
    from alight.accuracy.reference import ReferenceRenderer
    from alight.core.scene import Scene
    from alight.ibl.environment import load_environment
    from tests.gpu import renderer

    radiance = downsample_equirect(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")).radiance, 8)
    m = Material(base_color=(0.9, 0.5, 0.2), metallic=0.6, roughness=0.45, anisotropy_strength=0.9,
                 anisotropy_rotation=0.7)
    width = 20
    ref = ReferenceRenderer(renderer())
    scene = Scene(material=m, view="probe", env_rotation_deg=30.0)
    got = ref.render(scene, radiance.astype(np.float32), width, width, env_level=0).linear
    pts, inside = probe_points(width)
    terms = anisotropic_ground_truth_terms(radiance, pts, (0.0, 0.0, 1.0), None,
                                           [(m.roughness, m.anisotropy_strength, m.anisotropy_rotation)],
                                           rotation_deg=30.0)[0]
    want = terms.combine(m.base_color, m.metallic, m.specular_f0)
    np.testing.assert_allclose(got[..., :3][inside], want, rtol=2e-4, atol=1e-6)


def test_compare_anisotropy_model_forward_and_reference_agree_under_a_point_light(shared_data):
    # CompareAnisotropy.glb: two parts with anisotropy (one with anisotropyTexture, a spiral) and
    # two without. Under a point light alone the forward pass and alight reference evaluate the
    # same punctual BRDF, so they agree pixel for pixel when both read the map's direction and
    # strength and leave the plain parts isotropic (render/gbuffer.frag, accuracy/reference.comp).
    from alight.accuracy.reference import ReferenceRenderer
    from alight.core.scene import Light, Scene
    from alight.exchange.meshes import load_mesh
    from tests.gpu import renderer

    path = shared_data / "models" / "khronos" / "CompareAnisotropy" / "glTF-Binary" / "CompareAnisotropy.glb"
    mesh = load_mesh(str(path))
    textured = [p for p in mesh.parts if p.material is not None and p.material.anisotropy_texture is not None]
    assert len(textured) == 1 and textured[0].material.anisotropy_texture.image.shape[2] == 4
    assert sum(bool(p.material.layers) for p in mesh.parts) == 2
    scene = Scene(mesh=mesh, lights=[Light(vector=(1.0, 2.0, 4.0), intensity=40.0)], ibl_enabled=False)
    r = renderer()
    forward = r.render(scene, None, 256, 144, aa="none").linear
    reference = ReferenceRenderer(r).render(scene, None, 256, 144).linear
    covered = (forward[..., 3] > 0) & (reference[..., 3] > 0)
    assert covered.sum() > 4000
    error = np.abs(forward[covered, :3] - reference[covered, :3]).sum() / np.abs(reference[covered, :3]).sum()
    print(f"forward vs reference: {100 * error:.4f}%")
    assert error < 1e-3, error
