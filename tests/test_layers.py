"""The layers' shared plumbing: the material fields, the ior rule, preset files, the
API and CLI, the compile-time defines, and the exact layered BRDF's base against the ground
truth's own. Each layer's shading has its own tests (test_clearcoat.py, ...)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import alight
from alight.core.layers import LAYER_DEFINES, layer_defines
from alight.core.material import (
    LAYER_FIELDS,
    LAYERS,
    Material,
    f0_from_ior,
    ior_from_f0,
    material_from_dict,
    validate_material,
    with_overrides,
)
from alight.errors import AlightError
from alight.exchange.presets import list_presets, load_preset, save_preset

REPO = Path(__file__).resolve().parents[1]

# Every layer on, with values away from their defaults.
ALL_LAYERS = Material(base_color=(0.6, 0.2, 0.1), roughness=0.4, ior=1.45, specular_f0=(0.05, 0.04, 0.03), transmission=0.5, thickness=0.25,
                      attenuation_color=(0.9, 0.5, 0.2), attenuation_distance=0.75, clearcoat=0.8,
                      clearcoat_roughness=0.2, sheen_color=(0.3, 0.4, 0.5), sheen_roughness=0.6,
                      anisotropy_strength=0.7, anisotropy_rotation=1.25, iridescence=0.6, iridescence_ior=1.6,
                      iridescence_thickness_minimum=80.0, iridescence_thickness_maximum=450.0, dispersion=0.4,
                      diffuse_transmission=0.3, diffuse_transmission_color=(0.7, 0.9, 0.4), name="all_layers")


def test_defaults_are_gltf_and_turn_every_layer_off():
    m = Material()
    assert m.layers() == frozenset()
    assert (m.ior, m.specular_f0) == (1.5, (0.04, 0.04, 0.04))
    assert (m.transmission, m.thickness, m.attenuation_color, m.attenuation_distance) == (0.0, 0.0, (1.0,) * 3, math.inf)
    assert (m.clearcoat, m.clearcoat_roughness, m.sheen_color, m.sheen_roughness) == (0.0, 0.0, (0.0,) * 3, 0.0)
    assert (m.anisotropy_strength, m.anisotropy_rotation) == (0.0, 0.0)
    assert (m.dispersion, m.diffuse_transmission, m.diffuse_transmission_color) == (0.0, 0.0, (1.0,) * 3)
    assert ALL_LAYERS.layers() == frozenset(LAYERS)
    # A layer's secondary fields alone do not turn it on.
    assert Material(clearcoat_roughness=0.5, sheen_roughness=0.5, anisotropy_rotation=1.0, thickness=1.0).layers() == frozenset()
    assert Material(thickness=1.0, transmission=0.1).layers() == {"transmission", "volume"}
    assert Material(dispersion=1.0, transmission=0.1).layers() == {"transmission"}   # dispersion needs a volume


def test_the_ior_rule():
    # Neither: glTF's pair. One: the other follows. Both: as given.
    assert Material(specular_f0=(0.02,) * 3).ior == pytest.approx(ior_from_f0(0.02))
    assert Material(ior=1.33).specular_f0 == (f0_from_ior(1.33),) * 3
    both = Material(ior=1.5, specular_f0=(0.02, 0.03, 0.04))
    assert (both.ior, both.specular_f0) == (1.5, (0.02, 0.03, 0.04))
    assert f0_from_ior(1.5) == 0.04 and ior_from_f0(0.04) == 1.5 and ior_from_f0(0.0) == 1.0
    # Edits: an ior alone keeps the specular colour; a specular_f0 alone sets the ior.
    coloured = Material(specular_f0=(0.02, 0.04, 0.04))
    edited = with_overrides(coloured, ior=2.0)
    lum = 0.2126 * 0.5 + 0.7152 + 0.0722   # the colour (0.5, 1, 1)'s luminance: it keeps the ior's F0
    assert edited.specular_f0 == pytest.approx(tuple(f0_from_ior(2.0) * c / lum for c in (0.5, 1.0, 1.0)))
    assert with_overrides(Material(ior=2.0), specular_f0=(0.02,) * 3).ior == pytest.approx(ior_from_f0(0.02))
    assert with_overrides(Material(ior=2.0), roughness=0.3).ior == 2.0   # other edits leave it
    for f0 in (0.0, 0.01, 0.04, 0.17, 0.5):
        assert f0_from_ior(ior_from_f0(f0)) == pytest.approx(f0, abs=1e-11)


def test_presets_load_without_layer_fields_and_keep_their_files():
    """Today's preset files have no layer field: they load with every layer off, and saving them
    writes the same fields as before."""
    for name in list_presets():
        m = load_preset(name)
        assert m.layers() == frozenset() or name in ("car_paint", "velvet", "brushed_aluminium", "water", "oil_film",
                                                     "plastic_glass_low", "glass_high_ruby", "diamond", "flint_glass",
                                                     "leaf")
        d = m.to_dict()
        if not m.layers():
            assert set(d) == {"name", "base_color", "metallic", "roughness", "specular_f0", "emissive"}


def test_preset_file_with_layers_round_trips(tmp_path):
    save_preset(ALL_LAYERS, tmp_path / "m.json")
    text = (tmp_path / "m.json").read_text()
    for field in LAYER_FIELDS + ("ior",):
        assert f'"{field}"' in text
    assert load_preset(tmp_path / "m.json") == ALL_LAYERS


def test_preset_file_may_give_ior_instead_of_specular_f0():
    d = {"name": "x", "base_color": [0.5, 0.5, 0.5], "metallic": 0, "roughness": 0.5, "ior": 1.33,
         "emissive": [0, 0, 0], "clearcoat": 1}
    m = material_from_dict(d, "x.json")
    assert m.specular_f0 == (f0_from_ior(1.33),) * 3 and m.clearcoat == 1.0 and m.layers() == {"clearcoat"}


@pytest.mark.parametrize("field, value, reason", [
    ("ior", 0.9, "field 'ior': 0.9 is out of range [1, inf)"),
    ("transmission", 1.5, "field 'transmission': 1.5 is out of range [0, 1]"),
    ("thickness", -1, "field 'thickness': -1 is out of range [0, inf)"),
    ("attenuation_distance", 0, "field 'attenuation_distance': 0 is out of range (0, inf]"),
    ("attenuation_color", [1, 2, 1], "field 'attenuation_color', component 1: 2 is out of range [0, 1]"),
    ("clearcoat", "1", "field 'clearcoat': expected a number, got string"),
    ("clearcoat_roughness", True, "field 'clearcoat_roughness': expected a number, got boolean"),
    ("sheen_color", [0.5, 0.5], "field 'sheen_color': expected an array of 3 numbers, got array of 2"),
    ("sheen_roughness", -0.1, "field 'sheen_roughness': -0.1 is out of range [0, 1]"),
    ("anisotropy_strength", 2, "field 'anisotropy_strength': 2 is out of range [0, 1]"),
])
def test_bad_layer_fields_are_one_line_errors(tmp_path, field, value, reason):
    d = {**Material().to_dict(), field: value}
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(d))
    with pytest.raises(AlightError) as e:
        load_preset(p)
    assert str(e.value).startswith(f"{p}: {reason}") and "\n" not in str(e.value)


def test_non_finite_rotation_refused_and_infinite_distance_allowed_in_code():
    with pytest.raises(AlightError, match="anisotropy_rotation"):
        validate_material(Material(anisotropy_rotation=math.nan))
    assert validate_material(Material(attenuation_distance=math.inf)).attenuation_distance == math.inf


def test_layer_defines_only_for_used_layers():
    assert layer_defines([Material()]) == {}
    assert layer_defines([Material(clearcoat=0.0, clearcoat_roughness=0.7)]) == {}
    assert layer_defines([Material(), Material(sheen_color=(0.1, 0, 0))]) == {"HAS_SHEEN": None}
    assert layer_defines([ALL_LAYERS]) == {d: None for d in LAYER_DEFINES.values()}


def test_api_takes_layer_fields():
    with alight.Renderer(32, quality="low") as r:
        r.set_material("gold", clearcoat=0.5, clearcoat_roughness=0.1, ior=1.6)
        m = r.material
        assert (m.clearcoat, m.clearcoat_roughness, m.ior) == (0.5, 0.1, 1.6)
        with pytest.raises(AlightError, match="sheen_roughness"):
            r.set_material(sheen_roughness=3.0)


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "alight", *map(str, args)], cwd=REPO, env=dict(os.environ),
                          capture_output=True, text=True, timeout=300)


def test_cli_layer_flags_reach_the_material(tmp_path):
    out = tmp_path / "m.gltf"
    proc = _cli("export", "--preset", "plastic_high", "--clearcoat", "0.5", "--clearcoat-roughness", "0.2",
                "--sheen-color", "0.1,0.2,0.3", "--sheen-roughness", "0.4", "--anisotropy-strength", "0.6",
                "--anisotropy-rotation", "0.5", "--transmission", "0.7", "--thickness", "0.1",
                "--attenuation-color", "0.5,0.6,0.7", "--attenuation-distance", "2", "--ior", "1.7", "--out", out)
    assert proc.returncode == 0, proc.stderr
    from alight.exchange.gltf_material import import_material

    m = import_material(out)
    assert (m.clearcoat, m.clearcoat_roughness, m.sheen_roughness, m.anisotropy_strength) == (0.5, 0.2, 0.4, 0.6)
    assert m.sheen_color == pytest.approx((0.1, 0.2, 0.3)) and m.attenuation_color == pytest.approx((0.5, 0.6, 0.7))
    assert (m.anisotropy_rotation, m.transmission, m.thickness, m.attenuation_distance) == (0.5, 0.7, 0.1, 2.0)
    assert m.ior == 1.7 and m.specular_f0 == pytest.approx((f0_from_ior(1.7),) * 3)


@pytest.mark.parametrize("args, problem", [
    (("--clearcoat", "2"), "--clearcoat"),
    (("--ior", "0.5"), "--ior"),
    (("--sheen-color", "1,2,1"), "--sheen-color"),
    (("--attenuation-distance", "0"), "--attenuation-distance"),
    (("--anisotropy-rotation", "nan"), "--anisotropy-rotation"),
])
def test_cli_bad_layer_flags(tmp_path, args, problem):
    out = tmp_path / "x.png"
    proc = _cli("render", "--size", "16", "--quality", "low", *args, "--out", out)
    lines = [x for x in proc.stderr.splitlines() if x.strip()]
    assert proc.returncode == 2 and len(lines) == 1 and lines[0].startswith("alight: error: ")
    assert problem in lines[0] and "Traceback" not in proc.stderr and not out.exists()


# --- the shaders and the exact answer's plumbing --------------------------------------------

def test_every_layer_variant_compiles():
    """Each HAS_* alone and all together, in every program that shades (forward mesh and probe,
    debug views, the reference)."""
    from tests.gpu import renderer

    shaders = renderer().shaders
    for defines in [{d: None} for d in LAYER_DEFINES.values()] + [{d: None for d in LAYER_DEFINES.values()}]:
        shaders.program("render/fullscreen.vert", "render/probe.frag", {**defines, "IBL_MODEL": 4})
        for model in (0, 4):
            shaders.program("render/pbr.vert", "render/pbr.frag", {**defines, "IBL_MODEL": model, "MATERIAL_MAPS_MASK": 127})
        shaders.program("render/pbr.vert", "render/pbr.frag", {**defines, "DEBUG_VIEW": None})
        shaders.compute("accuracy/reference.comp", defines)


def test_a_material_without_layers_renders_exactly_as_its_zero_strength_twin():
    """Layer fields at zero strength compile nothing: the image is bit for bit the base's."""
    from tests.gpu import renderer
    from alight.core.scene import Light, Scene

    r = renderer()
    base = Material(base_color=(0.7, 0.3, 0.2), roughness=0.35)
    off = Material(base_color=(0.7, 0.3, 0.2), roughness=0.35, clearcoat_roughness=0.5, sheen_roughness=0.3,
                   anisotropy_rotation=0.4, thickness=2.0, attenuation_color=(0.2, 0.4, 0.6))
    lights = [Light("point", (2.0, 3.0, 4.0), (1.0, 1.0, 1.0), 20.0)]
    a = r.render(Scene(mesh=None, material=base, view="probe", lights=lights), None, 32, 32).linear
    b = r.render(Scene(mesh=None, material=off, view="probe", lights=lights), None, 32, 32).linear
    assert np.array_equal(a, b)


def test_layered_sum_of_a_base_material_equals_the_ground_truth(shared_data):
    """The exact layered BRDF (alight.core.layers.stack) on a material without layers is
    docs/conventions.md's BRDF: its texel sum equals the S1..S4 ground truth."""
    from alight.accuracy.ground_truth import layered_ground_truth, probe_points, reflectance_ground_truth
    from alight.ibl.environment import load_environment

    env = load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr"))
    from alight.core.equirect import box_reduce

    radiance = box_reduce(env.radiance, 8)      # 128x64: the comparison, not the map, is under test
    pts, _ = probe_points(12)
    for m in (Material(base_color=(0.8, 0.2, 0.1), roughness=0.3, emissive=(0.1, 0.0, 0.0)),
              Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=0.6)):
        a = layered_ground_truth(radiance, pts, (0, 0, 1), m, rotation_deg=30.0, intensity=1.5)
        b = reflectance_ground_truth(radiance, pts, (0, 0, 1), m.base_color, m.metallic, m.roughness, m.specular_f0,
                                     m.emissive, rotation_deg=30.0, intensity=1.5)
        np.testing.assert_allclose(a, b, rtol=2e-5, atol=1e-7)


def test_probe_tangents_match_the_built_in_sphere():
    """The probe's tangent frame is the sphere mesh's u direction (so anisotropy agrees)."""
    from alight.core.layers.stack import probe_tangents
    from alight.core.mesh import sphere

    part = sphere(32, 16).parts[0]
    inner = np.abs(part.normals[:, 1]) < 0.99
    np.testing.assert_allclose(probe_tangents(part.normals[inner].astype(np.float64)), part.tangents[inner, :3], atol=1e-5)


def test_editor_script_edits_take_layer_fields():
    """--script FIELD=VALUE reaches every layer field, with the ior rule and one-line errors."""
    from alight.frontends.editor.state import EditorState

    s = EditorState()
    s.apply_edit("clearcoat=0.7")
    s.apply_edit("sheen_color=0.5,0.2,0.1")
    s.apply_edit("attenuation_distance=2.5")
    s.apply_edit("ior=1.33")
    m = s.material
    assert (m.clearcoat, m.sheen_color, m.attenuation_distance, m.ior) == (0.7, (0.5, 0.2, 0.1), 2.5, 1.33)
    assert m.specular_f0 == (f0_from_ior(1.33),) * 3 and m.layers() == {"clearcoat", "sheen"}
    with pytest.raises(AlightError, match=r"^--script: field 'clearcoat': 2 is out of range \[0, 1\]$"):
        s.apply_edit("clearcoat=2")
    assert s.material == m


def test_reference_refuses_a_mirror_coat(tmp_path):
    """The coat's lobe must span texels as the base's must (docs/layer_clearcoat.md)."""
    out = tmp_path / "r.exr"
    proc = _cli("reference", "--view", "probe", "--size", "8", "--clearcoat", "1", "--clearcoat-roughness", "0.05",
                "--out", out)
    lines = [x for x in proc.stderr.splitlines() if x.strip()]
    assert proc.returncode == 2 and len(lines) == 1 and not out.exists()
    assert lines[0].startswith("alight: error: --clearcoat-roughness: clearcoat_roughness 0.05 < 0.1")


def test_a_coloured_specular_f0_gives_the_ior_of_its_luminance_everywhere():
    """The rule reads a coloured F0 by its luminance (the editor's panel and the command line
    alike): one channel at 0.32 over 0.04 is ior 1.92, not the red channel's 3.6; an ior edit
    keeps the tint at the ior's luminance."""
    from alight.core.material import luminance

    tinted = (0.32, 0.04, 0.04)
    m = Material(specular_f0=tinted)
    assert m.ior == pytest.approx(ior_from_f0(luminance(tinted))) and 1.9 < m.ior < 1.95
    assert with_overrides(Material(), specular_f0=tinted).ior == pytest.approx(m.ior)
    edited = with_overrides(m, ior=1.5)
    assert luminance(edited.specular_f0) == pytest.approx(0.04)
    assert edited.specular_f0[0] / edited.specular_f0[1] == pytest.approx(8.0)
    assert "ior" not in m.to_dict()   # derived by the rule: left out of a preset file
