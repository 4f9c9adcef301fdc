"""glTF material round trip (app/exchange/gltf_material.py, alight export), checked by the Khronos validator."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from alight.core.material import LAYER_FIELDS, Material
from alight.errors import AlightError
from alight.exchange.gltf_material import (
    EXT_ANISOTROPY,
    EXT_CLEARCOAT,
    EXT_EMISSIVE,
    EXT_IOR,
    EXT_SHEEN,
    EXT_SPECULAR,
    EXT_TRANSMISSION,
    EXT_VOLUME,
    export_material_gltf,
    import_material,
    read_gltf_json,
)
from alight.exchange.gltf_export import export_mesh_glb
from alight.exchange.meshes import load_mesh
from alight.exchange.presets import list_presets, load_preset

REPO = Path(__file__).resolve().parents[1]
VALIDATOR_PACKAGE = REPO / "tools" / "node" / "node_modules" / "gltf-validator"
FIELDS = ("base_color", "metallic", "roughness", "specular_f0", "emissive", "ior", *LAYER_FIELDS)


@pytest.fixture(scope="session")
def validate():
    """Runs tools/validate_gltf.js; installs the npm package as tools/setup.sh does when missing."""
    if shutil.which("node") is None:
        pytest.skip("node is not installed: the Khronos glTF validator (npm gltf-validator) needs it")
    if not VALIDATOR_PACKAGE.is_dir():
        subprocess.run(["npm", "install", "--no-save", "--prefix", str(REPO / "tools" / "node"), "gltf-validator"],
                       check=True, capture_output=True)

    def run(*paths: Path) -> list[dict]:
        out = subprocess.run(["node", str(REPO / "tools" / "validate_gltf.js"), *map(str, paths)],
                             capture_output=True, text=True)
        reports = [json.loads(line) for line in out.stdout.splitlines()]
        assert len(reports) == len(paths), out.stderr
        return reports

    return run


def assert_same(a: Material, b: Material, tol: float = 1e-6) -> None:
    for f in FIELDS:
        x, y = np.atleast_1d(getattr(a, f)), np.atleast_1d(getattr(b, f))
        if np.isinf(x).any() or np.isinf(y).any():
            assert np.array_equal(x, y), (f, getattr(a, f), getattr(b, f))
            continue
        assert np.abs(x - y).max() <= tol, (f, getattr(a, f), getattr(b, f))
    assert a.name == b.name


def edge_materials() -> list[Material]:
    """Beyond the presets: coloured F0, no F0, F0 past the ior limit, emission above 1."""
    rng = np.random.default_rng(5)
    out = [
        Material(specular_f0=(0.02, 0.05, 0.08), name="coloured_f0"),
        Material(specular_f0=(0.0, 0.0, 0.0), name="no_f0"),
        Material(specular_f0=(0.95, 1.0, 0.5), name="f0_above_ior_limit"),
        Material(emissive=(3.5, 0.25, 0.0), name="bright"),
        Material(emissive=(0.5, 0.25, 0.0), name="dim"),
    ]
    for i in range(20):
        out.append(Material(base_color=tuple(rng.random(3)), metallic=float(rng.random()),
                            roughness=float(rng.random()), specular_f0=tuple(rng.random(3) * 0.3),
                            emissive=tuple(rng.random(3) * 5 * (i % 2)), name=f"random{i}"))
    return out + layered_materials()


def layered_materials() -> list[Material]:
    """Each layer alone, every layer at once, an ior apart from the specular colour, and random
    layered materials (the layers' extensions)."""
    rng = np.random.default_rng(11)
    out = [
        Material(clearcoat=1.0, clearcoat_roughness=0.03, name="clearcoat"),
        Material(sheen_color=(0.9, 0.2, 0.4), sheen_roughness=0.5, name="sheen"),
        Material(metallic=1.0, anisotropy_strength=0.8, anisotropy_rotation=-2.5, name="anisotropy"),
        Material(transmission=1.0, ior=1.33, roughness=0.0, name="transmission"),
        Material(transmission=0.9, thickness=0.5, attenuation_color=(0.8, 0.3, 0.1), attenuation_distance=0.2,
                 ior=1.76, name="volume"),
        Material(transmission=0.5, thickness=1.5, name="volume_without_attenuation"),
        Material(ior=2.4, specular_f0=(0.1, 0.12, 0.14), name="ior_with_specular_colour"),
        Material(ior=1.0, specular_f0=(0.0, 0.0, 0.0), transmission=1.0, name="ior_1"),
        Material(ior=1.2, clearcoat=0.3, clearcoat_roughness=0.4, sheen_color=(0.5, 0.5, 0.5),
                 sheen_roughness=1.0, anisotropy_strength=0.2, anisotropy_rotation=0.3, transmission=0.6,
                 thickness=0.01, attenuation_color=(0.0, 1.0, 0.5), attenuation_distance=30.0, name="every_layer"),
    ]
    for i in range(8):
        out.append(Material(base_color=tuple(rng.random(3)), metallic=float(rng.random()), roughness=float(rng.random()),
                            ior=float(1.0 + 2.0 * rng.random()), transmission=float(rng.random()),
                            thickness=float(rng.random() * 3), attenuation_color=tuple(rng.random(3)),
                            attenuation_distance=float(0.01 + rng.random() * 10), clearcoat=float(rng.random()),
                            clearcoat_roughness=float(rng.random()), sheen_color=tuple(rng.random(3)),
                            sheen_roughness=float(rng.random()), anisotropy_strength=float(rng.random()),
                            anisotropy_rotation=float((rng.random() - 0.5) * 20), name=f"random_layers{i}"))
    return out


ALL = [load_preset(n) for n in list_presets()] + edge_materials()


@pytest.mark.parametrize("material", ALL, ids=lambda m: m.name)
def test_round_trip_preserves_every_field(material, tmp_path):
    export_material_gltf(material, tmp_path / "m.gltf")
    assert_same(material, import_material(tmp_path / "m.gltf"))
    export_mesh_glb(load_mesh("cube"), material, tmp_path / "m.glb")
    assert_same(material, import_material(tmp_path / "m.glb"))


def test_every_exported_file_passes_the_khronos_validator(validate, tmp_path, shared_data):
    files = []
    for m in ALL:
        files.append(export_material_gltf(m, tmp_path / f"{m.name}.gltf"))
    for mesh in ("sphere", "cube", "plane", str(shared_data / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"),
                 str(shared_data / "models" / "Duck.glb")):
        files.append(export_mesh_glb(load_mesh(mesh), ALL[len(files) % len(ALL)], tmp_path / f"{Path(mesh).stem}.glb"))
    for report in validate(*files):
        assert report["errors"] == 0, report
        assert report["warnings"] == 0, report


def test_validator_catches_a_broken_file(validate, tmp_path):
    """So that 0 errors above means something: an out-of-range factor is an error."""
    bad = tmp_path / "bad.gltf"
    bad.write_text(json.dumps({"asset": {"version": "2.0"}, "materials": [
        {"pbrMetallicRoughness": {"metallicFactor": 2.0}}]}))
    assert validate(bad)[0]["errors"] > 0


@pytest.mark.parametrize("preset, ior", [("water", 1.33), ("diamond", 2.40), ("glass_high_ruby", 1.79)])
def test_dielectric_f0_is_written_as_ior(preset, ior, tmp_path):
    m = load_preset(preset)
    doc = read_gltf_json(export_material_gltf(m, tmp_path / "m.gltf"))
    gm = doc["materials"][0]
    assert EXT_IOR in doc["extensionsUsed"]
    written = gm["extensions"][EXT_IOR]["ior"]
    assert written == pytest.approx(ior, abs=0.01)
    assert ((written - 1) / (written + 1)) ** 2 == pytest.approx(m.specular_f0[0], abs=1e-9)


def test_default_f0_writes_no_extension(tmp_path):
    doc = read_gltf_json(export_material_gltf(load_preset("gold"), tmp_path / "m.gltf"))
    assert "extensionsUsed" not in doc and "extensions" not in doc["materials"][0]


def test_coloured_f0_uses_specular_colour(tmp_path):
    doc = read_gltf_json(export_material_gltf(Material(specular_f0=(0.02, 0.05, 0.08)), tmp_path / "m.gltf"))
    ext = doc["materials"][0]["extensions"]
    # The ior is the F0's luminance's (the ior rule), so the colour factor's luminance is 1 and
    # its channels keep the F0's ratios (above 1 where brighter than the mean: the validator
    # accepts it, and the extension's min(F0 x colour, 1) is what it is there for).
    colour = ext[EXT_SPECULAR]["specularColorFactor"]
    assert 0.2126 * colour[0] + 0.7152 * colour[1] + 0.0722 * colour[2] == pytest.approx(1.0)
    assert colour[0] / colour[2] == pytest.approx(0.25)


def test_bright_emission_uses_emissive_strength(tmp_path):
    doc = read_gltf_json(export_material_gltf(Material(emissive=(4.0, 2.0, 0.0)), tmp_path / "m.gltf"))
    gm = doc["materials"][0]
    assert gm["emissiveFactor"] == [1.0, 0.5, 0.0]
    assert gm["extensions"][EXT_EMISSIVE]["emissiveStrength"] == 4.0


def test_import_reads_the_extensions_as_the_spec_defines_them(tmp_path):
    gm = {"name": "x", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.125, 0.5]},
          "emissiveFactor": [0.5, 0.5, 0.0],
          "extensions": {EXT_IOR: {"ior": 2.0}, EXT_SPECULAR: {"specularFactor": 0.5,
                                                               "specularColorFactor": [1.0, 20.0, 0.5]},
                         EXT_EMISSIVE: {"emissiveStrength": 3.0}}}
    p = tmp_path / "x.gltf"
    p.write_text(json.dumps({"asset": {"version": "2.0"}, "materials": [gm]}))
    m = import_material(p)
    f0 = (1 / 3) ** 2
    # min(F0 * colour, 1) * factor, per channel
    assert m.specular_f0 == pytest.approx((f0 * 0.5, 1.0 * 0.5, f0 * 0.5 * 0.5))
    assert m.metallic == 1.0 and m.roughness == 1.0  # glTF's defaults
    assert m.base_color == (0.5, 0.25, 0.125)
    assert m.emissive == (1.5, 1.5, 0.0)


def test_import_sample_models(shared_data):
    """The factors come in; the maps a Material cannot hold are named in one warning line (a new
    user's Duck exported white with no word), and load_material_file, which reads them, says nothing."""
    from alight.exchange.material_files import load_material_file

    from tests.warned import alight_warnings

    with alight_warnings() as lines:
        helmet = import_material(shared_data / "models" / "DamagedHelmet" / "DamagedHelmet.gltf")
        duck = import_material(shared_data / "models" / "Duck.glb")
    assert helmet.emissive == (1.0, 1.0, 1.0) and helmet.specular_f0 == pytest.approx((0.04,) * 3)
    assert duck.metallic == 0.0
    assert len(lines) == 2, lines
    assert "DamagedHelmet.gltf: materials[0]:" in lines[0] and "normalTexture" in lines[0], lines[0]
    assert "Duck.glb: materials[0]: baseColorTexture not taken" in lines[1], lines[1]
    with alight_warnings() as lines:
        load_material_file(shared_data / "models" / "Duck.glb")
    assert not [x for x in lines if "not taken" in x], lines


def test_glb_carries_the_mesh(tmp_path, shared_data):
    src = load_mesh(str(shared_data / "models" / "Duck.glb"))
    out = export_mesh_glb(src, load_preset("gold"), tmp_path / "duck.glb")
    back = load_mesh(str(out))
    assert sum(len(p.indices) for p in back.parts) == sum(len(p.indices) for p in src.parts)
    np.testing.assert_allclose(back.bounds()[0], src.bounds()[0], atol=1e-5)
    np.testing.assert_allclose(back.bounds()[1], src.bounds()[1], atol=1e-5)


@pytest.mark.parametrize("content, problem", [
    (b"", "not valid glTF JSON"),
    (b"{}", "no 'asset'"),
    (b'{"asset": {"version": "2.0"}}', "no materials"),
    (b'{"asset": {"version": "2.0"}, "materials": [{"pbrMetallicRoughness": {"metallicFactor": "1"}}]}',
     "metallicFactor"),
    (b'{"asset": {"version": "2.0"}, "materials": [{"pbrMetallicRoughness": {"roughnessFactor": 3}}]}',
     "out of range"),
    (b"glTF\x02\x00\x00\x00", "truncated"),
])
def test_bad_files_are_one_line_errors(content, problem, tmp_path):
    p = tmp_path / "bad.glb"
    p.write_bytes(content)
    with pytest.raises(AlightError) as exc:
        import_material(p)
    assert str(p) in str(exc.value) and problem in str(exc.value) and "\n" not in str(exc.value)


def cli(*args, cwd=None):
    import os

    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "alight", *args], capture_output=True, text=True, cwd=cwd, env=env)


def test_cli_export_gltf_and_glb(tmp_path, validate):
    r = cli("export", "--preset", "water", "--roughness", "0.3", "--out", str(tmp_path / "w.gltf"))
    assert r.returncode == 0, r.stderr
    m = import_material(tmp_path / "w.gltf")
    assert m.roughness == 0.3 and m.specular_f0 == pytest.approx((0.02,) * 3, abs=1e-12)
    r = cli("export", "--material-from", str(tmp_path / "w.gltf"), "--metallic", "1", "--mesh", "cube",
            "--out", str(tmp_path / "w.glb"))
    assert r.returncode == 0, r.stderr
    m2 = import_material(tmp_path / "w.glb")
    assert m2.metallic == 1.0 and m2.roughness == 0.3 and m2.name == "water"
    assert all(rep["errors"] == 0 for rep in validate(tmp_path / "w.gltf", tmp_path / "w.glb"))


@pytest.mark.parametrize("args, problem", [
    (["--out", "m.obj"], "unsupported output format"),
    (["--map", "base_color=missing.png", "--out", "m.gltf"], "no such file"),
    (["--preset", "nosuch", "--out", "m.gltf"], "no preset"),
    (["--material-from", "missing.glb", "--out", "m.gltf"], "cannot read"),
    (["--preset", "gold", "--material-from", "x.glb", "--out", "m.gltf"], "not both"),
    (["--mesh", "nosuch.obj", "--out", "m.glb"], "no such file"),
    (["--base-color", "2,0,0", "--out", "m.gltf"], "above 1"),
])
def test_cli_export_bad_input(args, problem, tmp_path):
    r = cli("export", *args, cwd=tmp_path)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and problem in r.stderr and "Traceback" not in r.stderr
    assert list(tmp_path.iterdir()) == []


def test_editor_state_exports_the_edited_material(validate, tmp_path):
    """The editor's export (EditorState.export_gltf, the panel's 'export glTF' button)."""
    from alight.core.material import with_overrides
    from alight.exchange.gltf_material import import_material
    from alight.frontends.editor.state import EditorState

    state = EditorState()
    state.load_mesh("cube")
    state.material = with_overrides(load_preset("diamond"), roughness=0.33, base_color=(0.2, 0.3, 0.4))
    state.export_gltf(str(tmp_path / "edited.gltf"))
    state.export_gltf(str(tmp_path / "edited.glb"))
    for path in (tmp_path / "edited.gltf", tmp_path / "edited.glb"):
        assert_same(import_material(path), state.material)
    for report in validate(tmp_path / "edited.gltf", tmp_path / "edited.glb"):
        assert report["errors"] == 0, report
    with pytest.raises(AlightError):
        state.export_gltf(str(tmp_path / "no_such_folder" / "x.gltf"))
    assert not (tmp_path / "no_such_folder").exists()


def test_every_layer_is_written_as_its_extension(tmp_path):
    doc = read_gltf_json(export_material_gltf(layered_materials()[8], tmp_path / "m.gltf"))
    ext = doc["materials"][0]["extensions"]
    assert set(doc["extensionsUsed"]) == {EXT_IOR, EXT_TRANSMISSION, EXT_VOLUME, EXT_CLEARCOAT, EXT_SHEEN, EXT_ANISOTROPY}
    assert ext[EXT_TRANSMISSION] == {"transmissionFactor": 0.6}
    assert ext[EXT_VOLUME] == {"thicknessFactor": 0.01, "attenuationDistance": 30.0, "attenuationColor": [0.0, 1.0, 0.5]}
    assert ext[EXT_CLEARCOAT] == {"clearcoatFactor": 0.3, "clearcoatRoughnessFactor": 0.4}
    assert ext[EXT_SHEEN] == {"sheenColorFactor": [0.5, 0.5, 0.5], "sheenRoughnessFactor": 1.0}
    assert ext[EXT_ANISOTROPY] == {"anisotropyStrength": 0.2, "anisotropyRotation": 0.3}
    assert ext[EXT_IOR] == {"ior": 1.2}
    # A layer at its defaults writes nothing.
    doc = read_gltf_json(export_material_gltf(Material(clearcoat_roughness=0.5), tmp_path / "n.gltf"))
    assert doc["materials"][0]["extensions"] == {EXT_CLEARCOAT: {"clearcoatRoughnessFactor": 0.5}}


def test_import_reads_the_layer_extensions_with_their_defaults(tmp_path):
    gm = {"extensions": {EXT_TRANSMISSION: {}, EXT_VOLUME: {"thicknessFactor": 2},
                         EXT_CLEARCOAT: {"clearcoatFactor": 1}, EXT_SHEEN: {"sheenRoughnessFactor": 0.5},
                         EXT_ANISOTROPY: {"anisotropyStrength": 0.5}, EXT_IOR: {"ior": 0}}}
    p = tmp_path / "x.gltf"
    p.write_text(json.dumps({"asset": {"version": "2.0"}, "materials": [gm]}))
    m = import_material(p)
    assert (m.transmission, m.thickness, m.attenuation_distance, m.attenuation_color) == (0.0, 2.0, float("inf"), (1.0,) * 3)
    assert (m.clearcoat, m.clearcoat_roughness, m.sheen_color, m.sheen_roughness) == (1.0, 0.0, (0.0,) * 3, 0.5)
    assert (m.anisotropy_strength, m.anisotropy_rotation, m.ior) == (0.5, 0.0, 1.5)   # legacy ior 0: glTF's 1.5


@pytest.mark.parametrize("ext, body, problem", [
    (EXT_CLEARCOAT, {"clearcoatFactor": 2.0}, "clearcoat"),
    (EXT_SHEEN, {"sheenColorFactor": [1, 1]}, "sheenColorFactor"),
    (EXT_VOLUME, {"attenuationDistance": -1}, "attenuation_distance"),
    (EXT_TRANSMISSION, [], EXT_TRANSMISSION),
])
def test_bad_layer_extensions_are_one_line_errors(tmp_path, ext, body, problem):
    p = tmp_path / "x.gltf"
    p.write_text(json.dumps({"asset": {"version": "2.0"}, "materials": [{"extensions": {ext: body}}]}))
    with pytest.raises(AlightError) as e:
        import_material(p)
    assert str(e.value).startswith(str(p)) and problem in str(e.value) and "\n" not in str(e.value)


def test_ior_1_with_reflectance_is_refused_on_export(tmp_path):
    with pytest.raises(AlightError, match="glTF cannot hold both"):
        export_material_gltf(Material(ior=1.0, specular_f0=(0.04,) * 3), tmp_path / "m.gltf")
    assert not (tmp_path / "m.gltf").exists()


def test_mesh_files_bring_their_layers(shared_data):
    """ClearCoatTest's coated spheres carry KHR_materials_clearcoat into the mesh's parts."""
    mesh = load_mesh(str(shared_data / "models" / "khronos" / "ClearCoatTest" / "glTF-Binary" / "ClearCoatTest.glb"))
    coated = [p for p in mesh.parts if p.material is not None and p.material.layers.get("clearcoat")]
    assert coated, [p.name for p in mesh.parts]
    assert {p.material.layers["clearcoat"] for p in coated} == {1.0}
