"""KHR_materials_dispersion (docs/layer_dispersion.md): zero strength, the furnace, the exact
answer (the fast per-channel sum, the per-pair sum and the GPU reference agree), the forward
pass against it, and the glTF files (the reader, the Khronos sample model)."""

from __future__ import annotations

import dataclasses
import json
import struct

import numpy as np
import pytest

import alight.render.variants as variants   # the layer defines a draw compiles (material_defines)
from alight.accuracy.converged import downsample_equirect
from alight.accuracy.ground_truth import (
    dispersion_transmission_terms,
    ground_truth_terms,
    layered_ground_truth,
    probe_points,
    transmission_combine,
)
from alight.core.btdf import beer_lambert
from alight.core.equirect import box_reduce
from alight.core.layers.dispersion import abbe_number, dispersion_iors
from alight.core.material import Material
from alight.core.mesh import sphere
from alight.core.scene import Light, Scene
from alight.ibl.environment import constant_environment, load_environment
from tests.gpu import bake as maps_for
from tests.gpu import probe, relative, renderer

# A dense flint glass: ior 1.7, Abbe number 20 (dispersion 1); the red and blue indices 1.6825, 1.7175.
FLINT = Material(base_color=(0.95, 0.95, 0.95), roughness=0.35, transmission=1.0, ior=1.7, thickness=0.5,
                 attenuation_color=(0.9, 0.8, 0.7), attenuation_distance=2.0, dispersion=1.0)


def test_the_layer_is_on_only_with_a_volume():
    assert "dispersion" in FLINT.layers()
    assert "dispersion" not in dataclasses.replace(FLINT, dispersion=0.0).layers()
    assert "dispersion" not in dataclasses.replace(FLINT, thickness=0.0).layers()   # a thin wall bends nothing
    assert abbe_number(1.0) == 20.0 and abbe_number(0.0) == float("inf")
    np.testing.assert_allclose(dispersion_iors(1.7, 1.0), [1.6825, 1.7, 1.7175])


# --- zero strength ------------------------------------------------------------------------------

@pytest.mark.parametrize("view", ["probe", "camera"])
def test_a_zero_dispersion_compiled_in_changes_nothing(monkeypatch, shared_data, view):
    """HAS_DISPERSION compiled in with dispersion 0 gives the image without it, under an
    environment and a punctual light, to float32 rounding (the compiler orders the unchanged
    arithmetic differently; measured: 1.6% of the values differ, by at most 3.5e-7 relative)."""
    env = load_environment(str(shared_data / "env" / "venice_sunset_1k.hdr"))
    maps = maps_for(env)
    m = dataclasses.replace(FLINT, dispersion=0.0)
    scene = dict(material=m, view=view, lights=[Light("point", (2.0, 3.0, 4.0), (1.0, 1.0, 1.0), 20.0)],
                 mesh=sphere() if view == "camera" else None)
    r = renderer()
    base = r.render(Scene(**scene), maps, 48, 48, aa="none").linear
    forced = {"HAS_TRANSMISSION": None, "HAS_VOLUME": None, "HAS_DISPERSION": None}
    monkeypatch.setattr(variants, "layer_defines", lambda materials: dict(forced))
    layered = r.render(Scene(**scene), maps, 48, 48, aa="none").linear
    np.testing.assert_allclose(layered[..., :3], base[..., :3], rtol=2e-6, atol=1e-7)


def _compare_dispersion(shared_data, tmp_path, dispersion):
    """CompareDispersion.glb with its dispersive material's extension set to ``dispersion``
    (None: removed, and from extensionsUsed), written to tmp_path."""
    data = (shared_data / "models" / "khronos" / "CompareDispersion" / "glTF-Binary" / "CompareDispersion.glb").read_bytes()
    length = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20:20 + length])
    rest = data[20 + length:]
    for material in doc["materials"]:
        ext = material.get("extensions", {})
        if "KHR_materials_dispersion" in ext:
            if dispersion is None:
                del ext["KHR_materials_dispersion"]
            else:
                ext["KHR_materials_dispersion"]["dispersion"] = dispersion
    if dispersion is None:
        doc["extensionsUsed"].remove("KHR_materials_dispersion")
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    path = tmp_path / f"compare_{dispersion}.glb"
    path.write_bytes(struct.pack("<III", 0x46546C67, 2, 20 + len(text) + len(rest))
                     + struct.pack("<II", len(text), 0x4E4F534A) + text + rest)
    return path


def _render_file(path, shared_data, size=96):
    from alight.exchange.meshes import load_mesh

    mesh = load_mesh(str(path))
    env = load_environment(str(shared_data / "env" / "venice_sunset_1k.hdr"))
    return renderer().render(Scene(mesh=mesh), maps_for(env), size, size // 2, aa="none").linear, mesh


def test_a_file_with_dispersion_0_renders_as_the_file_without_the_extension(shared_data, tmp_path):
    """The sample model with dispersion 0 against the same file without the extension: the
    same pixels; with its own dispersion 5 the dispersive gem changes in red and blue."""
    zero, _ = _render_file(_compare_dispersion(shared_data, tmp_path, 0.0), shared_data)
    without, _ = _render_file(_compare_dispersion(shared_data, tmp_path, None), shared_data)
    np.testing.assert_array_equal(zero, without)
    five, _ = _render_file(_compare_dispersion(shared_data, tmp_path, 5.0), shared_data)
    changed = np.abs(five[..., :3] - without[..., :3]).max(axis=(0, 1))
    print("max change per channel", changed)
    assert changed[0] > 0.002 and changed[2] > 0.002 and changed[1] < 1e-5   # green refracts at the ior itself


def test_the_sample_model_brings_its_dispersion(shared_data):
    from alight.exchange.meshes import load_mesh

    path = shared_data / "models" / "khronos" / "CompareDispersion" / "glTF-Binary" / "CompareDispersion.glb"
    mesh = load_mesh(str(path))
    assert not any("KHR_materials_dispersion" in w for w in mesh.warnings)
    values = sorted(p.material.layers.get("dispersion", 0.0) for p in mesh.parts if p.material is not None)
    assert values[-1] == 5.0 and values[0] == 0.0


def test_gltf_material_round_trip(tmp_path):
    from alight.exchange.gltf_material import export_material_gltf, import_material

    out = export_material_gltf(FLINT, tmp_path / "flint.gltf")
    doc = json.loads(out.read_text())
    assert doc["materials"][0]["extensions"]["KHR_materials_dispersion"] == {"dispersion": 1.0}
    assert "KHR_materials_dispersion" in doc["extensionsUsed"]
    back = import_material(out)
    assert back.dispersion == 1.0 and "dispersion" in back.layers()


# --- the furnace --------------------------------------------------------------------------------

@pytest.mark.parametrize("roughness", [0.3, 0.7])
def test_each_channel_in_the_furnace_is_the_undispersed_material_at_its_index(roughness):
    """Under radiance 1 a white dispersive volume never adds energy, and each channel shows what
    the undispersed material shows at that channel's index (same F0): exactly in the exact
    answer, to the transmission LUT's interpolation in ior in the forward pass."""
    maps = maps_for(constant_environment(1.0, width=256))
    m = dataclasses.replace(FLINT, base_color=(1.0, 1.0, 1.0), roughness=roughness, attenuation_color=(1.0, 1.0, 1.0),
                            dispersion=4.0)
    image, inside, n = probe(m, maps)
    assert image[inside].max() <= 1.0 + 2e-3 and image[inside].min() > 0.3
    iors = dispersion_iors(m.ior, m.dispersion)
    pts = n[inside][::7]
    white = np.ones((64, 128, 3), np.float32)
    exact = layered_ground_truth(white, pts, (0, 0, 1), m)
    for c in (0, 2):
        at_index = dataclasses.replace(m, ior=float(iors[c]), dispersion=0.0)
        single, _, _ = probe(at_index, maps)
        np.testing.assert_allclose(image[inside][:, c], single[inside][:, c], atol=2e-3)
        np.testing.assert_allclose(exact[:, c], layered_ground_truth(white, pts, (0, 0, 1), at_index)[:, c], rtol=1e-12)


# --- the exact answer ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def small_map(shared_data):
    env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
    return box_reduce(env.radiance, 8)


def _fast_truth(radiance, pts, m, **kw):
    terms = ground_truth_terms(radiance, pts, (0, 0, 1), m.roughness, **kw)
    s_t = dispersion_transmission_terms(radiance, pts, (0, 0, 1), m.roughness, m.ior, m.dispersion, **kw)[0]
    attenuation = beer_lambert(m.attenuation_color, m.attenuation_distance, m.thickness)
    return np.asarray(m.emissive) + transmission_combine(terms.combine(m.base_color, m.metallic, m.specular_f0, parts=True),
                                                        s_t, m.base_color, m.metallic, m.specular_f0, m.transmission,
                                                        attenuation)


def test_fast_dispersed_sum_equals_the_per_pair_sum(small_map):
    """ground_truth.dispersion_transmission_terms (a matmul sum per channel's index) against the
    layered BRDF pair by pair (alight.core.layers.stack through transmission.py)."""
    pts, _ = probe_points(12)
    m = dataclasses.replace(FLINT, roughness=0.6, transmission=0.7, metallic=0.2, dispersion=3.0)
    slow = layered_ground_truth(small_map, pts, (0, 0, 1), m, rotation_deg=30.0, intensity=1.5)
    fast = _fast_truth(small_map, pts, m, rotation_deg=30.0, intensity=1.5)
    np.testing.assert_allclose(fast, slow, rtol=5e-5, atol=1e-7)


def test_reference_on_the_gpu_equals_the_numpy_sum(small_map):
    """alight reference (accuracy/reference.comp through transmission.glsl with HAS_DISPERSION)
    against the numpy per-pair sum, probe view."""
    from alight.accuracy.reference import ReferenceRenderer

    m = dataclasses.replace(FLINT, roughness=0.6, dispersion=3.0)
    ref = ReferenceRenderer(renderer()).render(Scene(material=m, view="probe"), small_map, 16, 16, env_level=0)
    pts, inside = probe_points(16)
    want = layered_ground_truth(small_map, pts, (0, 0, 1), m)
    np.testing.assert_allclose(ref.linear[..., :3][inside], want, rtol=2e-4, atol=1e-6)


# Measured (this change): 5.5% at r = 0.6 (docs/layer_dispersion.md); the bound is that, rounded up.
PROBE_BOUND = 0.065


def test_probe_against_the_exact_answer(shared_data):
    """The forward pass against the exact answer with dispersion 3 (V_d 6.7, a strong one): the
    layer's real-time error, on the map that docs/layer_transmission.md measures."""
    env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
    m = dataclasses.replace(FLINT, roughness=0.6, dispersion=3.0)
    got, inside, n = probe(m, maps_for(env))
    radiance = downsample_equirect(env.radiance, 2)
    truth = _fast_truth(radiance, n[inside], m)
    error = relative(got[inside], truth)
    plain = _fast_truth(radiance, n[inside], dataclasses.replace(m, dispersion=0.0))
    print(f"dispersion 3 r=0.6 vs truth: {error * 100:.2f}%; the truth moves {relative(plain, truth) * 100:.2f}% with it")
    assert error <= PROBE_BOUND
