"""Texture sets by name (app/exchange/texture_sets.py) through ``alight render --texture-set`` and
``--map``, the Python API and batch; materials that leave with their maps (app/exchange/gltf_export.py,
app/exchange/material_files.py) through ``--preset``, ``--mesh`` and ``alight export``.

Every map is written here with Pillow; a set under each tool's names must render (EXR, no tone
mapping) as the same maps given one by one, with the conversions (DirectX normal, gloss, ORM)
checked against twins written in the glTF layout.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from alight.accuracy.metrics import read_linear, relative_mae
from alight.core.texture_maps import TextureMaps
from alight.errors import AlightError
from alight.exchange.texture_sets import assign_files, assign_folder, load_slot_image, role_of
from tests.test_editor import display  # noqa: F401  (Xvfb for the editor)
from tests.test_gltf_material import validate  # noqa: F401  (the Khronos validator fixture)

REPO = Path(__file__).resolve().parents[1]
FAST = ("--size", "64", "--quality", "low", "--aa", "none", "--tonemap", "none")
TOL = 1e-4


def run(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "alight", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd or REPO, env=dict(os.environ), timeout=300)


def render(out: Path, *args) -> np.ndarray:
    proc = run("render", *FAST, *args, "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    return read_linear(out)


def canonical() -> dict[str, np.ndarray]:
    """One material's maps in glTF's layout (8-bit RGB): colour, OpenGL normal, roughness,
    metal, occlusion, emission; smooth patterns so that a wrong slot or a wrong channel shows."""
    n = 32
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / n
    u8 = lambda a: np.clip(np.rint(a * 255.0), 0, 255).astype(np.uint8)
    grey = lambda a: np.repeat(u8(a)[:, :, None], 3, axis=2)
    normal = np.dstack([0.4 * np.sin(6.28 * x), 0.4 * np.cos(6.28 * y), np.ones_like(x)])
    normal /= np.linalg.norm(normal, axis=2, keepdims=True)
    return {
        "color": u8(np.dstack([0.2 + 0.7 * x, 0.3 + 0.5 * y, 0.6 - 0.4 * x * y])),
        "normal": u8(normal * 0.5 + 0.5),
        "rough": grey(0.15 + 0.7 * y),
        "metal": grey((x > 0.5).astype(float)),
        "ao": grey(0.4 + 0.6 * x),
        "emissive": u8(np.dstack([0.3 * y, 0.1 * x, 0.2 * np.ones_like(x)])),
    }


def write(path: Path, pixels: np.ndarray) -> str:
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.ascontiguousarray(pixels)).save(path)
    return str(path)


def dx(normal: np.ndarray) -> np.ndarray:
    out = normal.copy()
    out[:, :, 1] = 255 - out[:, :, 1]
    return out


def packed(c: dict) -> np.ndarray:
    return np.dstack([c["ao"][:, :, 0], c["rough"][:, :, 0], c["metal"][:, :, 0]])


def metal_rough(c: dict) -> np.ndarray:
    """glTF's metallicRoughness image: R unused (here the colour's R, which a grey roughness slot
    would read), G roughness, B metal."""
    return np.dstack([c["color"][:, :, 0], c["rough"][:, :, 0], c["metal"][:, :, 0]])


def gloss(c: dict) -> np.ndarray:
    return 255 - c["rough"]


# Each tool's names for a set, and what each file holds (a canonical map or a conversion of one).
SETS = {
    "substance": {"Mat_BaseColor.png": "color", "Mat_Normal.png": "normal", "Mat_Roughness.png": "rough",
                  "Mat_Metallic.png": "metal", "Mat_AO.png": "ao", "Mat_Emissive.png": "emissive",
                  "Mat_Height.png": "rough", "Mat_Opacity.png": "ao"},
    "substance_long_ao": {"mat_base_color.png": "color", "mat_normal.png": "normal",
                          "mat_AmbientOcclusion.png": "ao", "mat_roughness.png": "rough"},
    "ambientcg": {"Rock023_2K_Color.png": "color", "Rock023_2K_NormalGL.png": "normal",
                  "Rock023_2K_NormalDX.png": "normal_dx", "Rock023_2K_Roughness.png": "rough",
                  "Rock023_2K_Metalness.png": "metal", "Rock023_2K_AmbientOcclusion.png": "ao",
                  "Rock023_2K_Displacement.png": "rough"},
    "ambientcg_dx_only": {"Rock023_1K-Color.png": "color", "Rock023_1K-NormalDX.png": "normal_dx",
                          "Rock023_1K-Roughness.png": "rough"},
    "polyhaven": {"rock_wall_diff_1k.png": "color", "rock_wall_nor_gl_1k.png": "normal",
                  "rock_wall_rough_1k.png": "rough", "rock_wall_metal_1k.png": "metal", "rock_wall_ao_1k.png": "ao"},
    "polyhaven_arm_dx": {"rock_wall_diff_2k.png": "color", "rock_wall_nor_dx_2k.png": "normal_dx",
                         "rock_wall_arm_2k.png": "orm"},
    "quixel_orm": {"T_Rock_Albedo.png": "color", "T_Rock_Normal.png": "normal", "T_Rock_ORM.png": "orm"},
    "quixel_gloss": {"T_Rock_4K_Albedo.png": "color", "T_Rock_4K_Normal.png": "normal", "T_Rock_4K_Gloss.png": "gloss"},
    "quixel_roughness": {"Rock_Albedo.png": "color", "Rock_Normal.png": "normal", "Rock_Roughness.png": "rough"},
    "plain_albedo": {"albedo.png": "color", "normal.png": "normal", "roughness.png": "rough"},
    "plain_diffuse": {"Diffuse.png": "color", "Metallic.png": "metal"},
    "plain_basecolor": {"BASECOLOR.png": "color", "AO.png": "ao"},
    # As glTF exports and the Khronos samples name them (DamagedHelmet's Default_metalRoughness.jpg
    # went to the grey roughness slot, which reads R: a mirror).
    "gltf_metal_rough": {"Default_albedo.png": "color", "Default_normal.png": "normal",
                         "Default_metalRoughness.png": "mr", "Default_AO.png": "ao", "Default_emissive.png": "emissive"},
    "gltf_metallic_roughness": {"Mat_baseColor.png": "color", "Mat_metallicRoughness.png": "mr"},
    "khronos_orm": {"Helmet_BaseColor.png": "color", "Helmet_OcclusionRoughMetal.png": "orm"},
}
# The --map options that give the same maps one by one, in glTF's layout.
SLOT_OF = {"color": "base_color", "normal": "normal", "normal_dx": "normal", "rough": "roughness",
           "gloss": "roughness", "metal": "metallic", "ao": "occlusion", "emissive": "emissive"}
LEFT_OUT = {"Mat_Height.png", "Mat_Opacity.png", "Rock023_2K_Displacement.png", "Rock023_2K_NormalDX.png"}


def write_set(folder: Path, files: dict[str, str], c: dict) -> None:
    made = {**c, "normal_dx": dx(c["normal"]), "gloss": gloss(c), "orm": packed(c), "mr": metal_rough(c)}
    for name, what in files.items():
        write(folder / name, made[what])


def one_by_one(folder: Path, files: dict[str, str], c: dict) -> list[str]:
    """--map options with the canonical (glTF layout) twins of the set's files."""
    args = []
    for name, what in files.items():
        if name in LEFT_OUT:
            continue
        if what in ("orm", "mr"):
            parts = (("ao", "occlusion"),) if what == "orm" else ()
            for part, slot in (*parts, ("rough", "roughness"), ("metal", "metallic")):
                args += ["--map", f"{slot}={write(folder / 'twins' / f'{part}.png', c[part])}"]
            continue
        source = "normal" if what == "normal_dx" else "rough" if what == "gloss" else what
        args += ["--map", f"{SLOT_OF[what]}={write(folder / 'twins' / f'{source}.png', c[source])}"]
    return args


# ------------------------------------------------------------------------ names, no rendering

@pytest.mark.parametrize("name,role", [
    ("Mat_BaseColor.png", "base_color"), ("mat-base-color.PNG", "base_color"), ("Rock023_2K_Color.jpg", "base_color"),
    ("rock_diff_1k.jpg", "base_color"), ("T_Rock_Albedo.tga", "base_color"), ("diffuse.png", "base_color"),
    ("RockBaseColor.png", "base_color"), ("Rock_NormalGL.png", "normal"), ("rock_nor_gl_4k.png", "normal"),
    ("Rock_NormalDX.png", "normal_dx"), ("rock_nor_dx.png", "normal_dx"), ("Rock_Roughness.png", "roughness"),
    ("rock_rough.png", "roughness"), ("T_Rock_Gloss.png", "gloss"), ("Mat_Metallic.png", "metallic"),
    ("Rock_Metalness.png", "metallic"), ("rock_metal_2k.png", "metallic"), ("Mat_AO.png", "occlusion"),
    ("Rock_AmbientOcclusion.png", "occlusion"), ("T_Rock_ORM.png", "orm"), ("rock_arm_1k.png", "orm"),
    ("Mat_Emissive.png", "emissive"), ("Mat_Height.png", "height"), ("Rock_Displacement.png", "height"),
    ("Mat_Opacity.png", "opacity"), ("Default_metalRoughness.jpg", "metallic_roughness"),
    ("Mat_metallicRoughness.png", "metallic_roughness"), ("Helmet_OcclusionRoughMetal.png", "orm"),
    ("Mat_Occlusion_Roughness_Metallic.png", "orm"), ("T_Rock_RoughnessMetallic.png", "metallic_roughness"),
])
def test_names_of_each_tool(name, role):
    assert role_of(name)[0] == role


def test_names_that_are_not_maps():
    assert role_of("gunmetal.png") is None and role_of("photo.jpg") is None and role_of("rock_2k.png") is None


def test_assignment_reports_every_file(tmp_path):
    c = canonical()
    write_set(tmp_path / "s", SETS["ambientcg"], c)
    found = assign_folder(tmp_path / "s")
    by_name = {Path(a.path).name: a for a in found.files}
    assert by_name["Rock023_2K_NormalGL.png"].slots == ("normal",)
    assert by_name["Rock023_2K_NormalDX.png"].slots == () and "twin" in by_name["Rock023_2K_NormalDX.png"].note
    assert "displacement" in by_name["Rock023_2K_Displacement.png"].note
    assert set(found.slots) == {"base_color", "normal", "roughness", "metallic", "occlusion"}
    assert not found.maps.normal_dx
    assert len(found.notes()) == 2 and all("left out" in line for line in found.notes())


def test_directx_normal_equals_its_gl_twin_after_the_flip(tmp_path):
    c = canonical()
    maps = TextureMaps(normal=write(tmp_path / "n_dx.png", dx(c["normal"])), normal_dx=True)
    assert np.array_equal(load_slot_image(maps, "normal")[:, :, :3], c["normal"])


def test_gloss_equals_one_minus_roughness(tmp_path):
    c = canonical()
    found = assign_files([write(tmp_path / "T_Rock_Gloss.png", gloss(c))])
    assert found.maps.roughness_gloss and found.slots == ("roughness",)
    assert np.array_equal(load_slot_image(found.maps, "roughness")[:, :, :3], c["rough"])


def test_orm_fills_occlusion_and_metal_rough_with_the_channels_gltf_reads(tmp_path):
    c = canonical()
    found = assign_files([write(tmp_path / "T_Rock_ORM.png", packed(c))])
    assert set(found.slots) == {"occlusion", "metallic_roughness"}
    image = load_slot_image(found.maps, "metallic_roughness")
    assert np.array_equal(image[:, :, 0], c["ao"][:, :, 0])      # occlusion: R
    assert np.array_equal(image[:, :, 1], c["rough"][:, :, 0])   # roughness: G
    assert np.array_equal(image[:, :, 2], c["metal"][:, :, 0])   # metal: B


def test_a_folder_without_maps_is_refused(tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(AlightError, match="no texture map of a known name"):
        assign_folder(tmp_path / "empty")
    with pytest.raises(AlightError, match="no such folder"):
        assign_folder(tmp_path / "missing")


# ---------------------------------------------------------------------------- rendering (CLI)

@pytest.mark.parametrize("convention", sorted(SETS))
def test_each_tools_set_renders_as_its_maps_one_by_one(tmp_path, convention):
    c = canonical()
    folder = tmp_path / convention
    write_set(folder, SETS[convention], c)
    by_set = render(tmp_path / "set.exr", "--texture-set", folder)
    by_maps = render(tmp_path / "maps.exr", *one_by_one(tmp_path, SETS[convention], c))
    plain = render(tmp_path / "plain.exr", "--base-color", "1,1,1", "--metallic", "1", "--roughness", "1")
    assert relative_mae(by_set, by_maps) <= TOL
    assert relative_mae(by_maps, plain) > 0.02   # the maps change the picture: the comparison means something


def test_cli_reports_the_assignment_and_what_is_left_out(tmp_path):
    c = canonical()
    write_set(tmp_path / "s", SETS["substance"], c)
    proc = run("render", *FAST, "--texture-set", tmp_path / "s", "-v", "--out", tmp_path / "a.exr")
    assert proc.returncode == 0, proc.stderr
    assert "Mat_BaseColor.png -> base_color" in proc.stderr
    assert sum("warning:" in line and "left out" in line for line in proc.stderr.splitlines()) == 2


@pytest.mark.parametrize("args,problem", [
    (("--map", "colour=x.png"), "unknown texture slot 'colour'"),
    (("--map", "base_color=MISSING.png"), "no such file"),
    (("--map", "base_color"), "expected SLOT=PATH"),
    (("--texture-set", "NO_SUCH_DIR"), "no such folder"),
])
def test_cli_bad_maps_are_one_line_exit_2(tmp_path, args, problem):
    proc = run("render", *FAST, *args, "--out", tmp_path / "x.exr", cwd=tmp_path)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and problem in lines[0] and "Traceback" not in proc.stderr
    assert not (tmp_path / "x.exr").exists()


def test_loaded_maps_set_their_factors_to_1():
    from alight.frontends.options import build_look

    class Args:
        preset, texture_set, verbose = "gold", None, False
        base_color = metallic = roughness = specular_f0 = emissive = ior = None
        clearcoat = clearcoat_roughness = sheen_color = sheen_roughness = None
        anisotropy_strength = anisotropy_rotation = transmission = thickness = None
        attenuation_color = attenuation_distance = None
        map = [f"base_color={REPO / 'docs' / 'editor_window.png'}"]

    m, _, maps = build_look(Args())
    assert m.base_color == (1.0, 1.0, 1.0) and maps.base_color
    Args.roughness = 0.25   # a flag still wins over the map's factor
    assert build_look(Args())[0].roughness == 0.25


# ----------------------------------------------------------------- materials leave with their maps

def full_maps(tmp_path: Path) -> list[str]:
    c = canonical()
    args = []
    for what, slot in (("color", "base_color"), ("normal", "normal"), ("rough", "roughness"), ("metal", "metallic"),
                       ("ao", "occlusion"), ("emissive", "emissive")):
        args += ["--map", f"{slot}={write(tmp_path / 'maps' / f'{what}.png', c[what])}"]
    return args


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
def test_saved_material_reopens_to_the_same_pixels(tmp_path, suffix, validate):
    maps = full_maps(tmp_path)
    tiling = ("--emissive", "0.5,0.5,0.5", "--roughness", "0.8")
    original = render(tmp_path / "original.exr", *maps, *tiling)
    saved = tmp_path / "out" / f"saved{suffix}"
    saved.parent.mkdir()
    proc = run("export", *maps, *tiling, "--mesh", "sphere", "--out", saved)
    assert proc.returncode == 0, proc.stderr
    report = validate(saved)[0]
    assert report["errors"] == 0 and report["warnings"] == 0, report["messages"]
    doc = _json(saved)
    attributes = doc["meshes"][0]["primitives"][0]["attributes"]
    assert {"POSITION", "NORMAL", "TANGENT", "TEXCOORD_0"} <= set(attributes)
    gm = doc["materials"][0]
    assert {"baseColorTexture", "metallicRoughnessTexture"} <= set(gm["pbrMetallicRoughness"])
    assert {"normalTexture", "occlusionTexture", "emissiveTexture"} <= set(gm)
    if suffix == ".gltf":
        assert sorted(p.name for p in saved.parent.iterdir()) == sorted(
            ["saved.gltf", "saved.bin", *(f"saved_{s}.png" for s in
                                          ("base_color", "metallic_roughness", "normal", "occlusion", "emissive"))])
    # --preset: the file's material and maps on the built-in ball, as the maps one by one.
    assert relative_mae(render(tmp_path / "preset.exr", "--preset", saved), original) <= TOL
    # --mesh: the file's own mesh and material, as the maps given on that mesh.
    by_file = render(tmp_path / "mesh.exr", "--mesh", saved)
    by_maps = render(tmp_path / "mesh_maps.exr", "--mesh", saved, *maps, *tiling)
    assert relative_mae(by_file, by_maps) <= TOL
    assert relative_mae(by_file, render(tmp_path / "plain.exr", "--mesh", saved, "--preset", "gold")) > 0.02


def test_jpeg_maps_leave_as_the_same_jpeg_files_and_converted_ones_as_png(tmp_path, validate):
    """A JPEG set (as photo-scanned sets come) was re-encoded as PNG on export: several times
    the size, and slow. A map that loads unconverted leaves as its own bytes; the DirectX normal
    (its green flipped on load) and the packed metal-roughness leave as PNG of what is drawn."""
    c = canonical()
    folder = tmp_path / "set"
    folder.mkdir()
    for name, what in {"Rock_1K-Color.jpg": "color", "Rock_1K-NormalDX.jpg": "normal_dx",
                       "Rock_1K-Roughness.jpg": "rough", "Rock_1K-AmbientOcclusion.jpg": "ao"}.items():
        made = dx(c["normal"]) if what == "normal_dx" else c[what]
        Image.fromarray(np.ascontiguousarray(made)).save(folder / name, quality=90)
    original = render(tmp_path / "original.exr", "--texture-set", folder)
    saved = tmp_path / "out" / "saved.gltf"
    saved.parent.mkdir()
    proc = run("export", "--texture-set", folder, "--mesh", "sphere", "--out", saved)
    assert proc.returncode == 0, proc.stderr
    report = validate(saved)[0]
    assert report["errors"] == 0 and report["warnings"] == 0, report["messages"]
    names = sorted(p.name for p in saved.parent.iterdir())
    assert names == sorted(["saved.gltf", "saved.bin", "saved_base_color.jpg", "saved_occlusion.jpg",
                            "saved_normal.png", "saved_metallic_roughness.png"]), names
    assert (saved.parent / "saved_base_color.jpg").read_bytes() == (folder / "Rock_1K-Color.jpg").read_bytes()
    assert (saved.parent / "saved_occlusion.jpg").read_bytes() == (folder / "Rock_1K-AmbientOcclusion.jpg").read_bytes()
    images = _json(saved)["images"]
    assert sorted(i["uri"] for i in images) == sorted(n for n in names if n.startswith("saved_"))
    assert relative_mae(render(tmp_path / "preset.exr", "--preset", saved), original) <= TOL
    glb = tmp_path / "saved.glb"
    assert run("export", "--texture-set", folder, "--mesh", "sphere", "--out", glb).returncode == 0
    assert sorted(i["mimeType"] for i in _json(glb)["images"]) == ["image/jpeg", "image/jpeg", "image/png", "image/png"]
    assert relative_mae(render(tmp_path / "preset_glb.exr", "--preset", glb), original) <= TOL


def test_material_only_gltf_and_tiling_round_trip(tmp_path, validate):
    """A material-only .gltf (no mesh) keeps maps and KHR_texture_transform tiling."""
    from alight.core.material import Material
    from alight.exchange.gltf_export import export_gltf
    from alight.exchange.material_files import load_material_file

    c = canonical()
    (tmp_path / "m").mkdir()
    maps = TextureMaps(base_color=write(tmp_path / "c.png", c["color"]), normal=write(tmp_path / "n.png", dx(c["normal"])),
                       normal_dx=True, uv_scale=(2.0, 3.0), uv_offset=(0.25, 0.1))
    out, _ = export_gltf(Material(base_color=(1, 1, 1)), tmp_path / "m" / "m.gltf", maps)
    report = validate(out)[0]
    assert report["errors"] == 0 and report["warnings"] == 0, report["messages"]
    m, back, warnings = load_material_file(out)
    from alight.frontends.editor.state import EditorState

    editor = EditorState()   # the editor's open= / drop of a material-only .gltf: a material, not a mesh
    assert editor.open_file(str(out)), editor.error
    assert editor.texture_maps == back and editor.material == m and editor.mesh is None
    assert warnings == [] and back.uv_scale == (2.0, 3.0) and back.uv_offset == pytest.approx((0.25, 0.1), abs=1e-12)
    assert np.array_equal(load_slot_image(back, "normal"), load_slot_image(maps, "normal"))
    a = render(tmp_path / "a.exr", "--preset", out)
    untiled = render(tmp_path / "b.exr", "--map", f"base_color={maps.base_color}", "--map", f"normal_dx={maps.normal}",
                     "--base-color", "1,1,1")
    assert relative_mae(a, untiled) > 0.01   # the tiling shows
    # The same maps and tiling given to the API draw what the file draws.
    from alight.frontends.api import Renderer

    with Renderer(64, quality="low", aa="none", tonemap="none") as r:
        r.set_material(out)
        via_file = r.render(linear=True)
        r.set_material(Material(base_color=(1, 1, 1)), maps=maps)
        via_maps = r.render(linear=True)
    assert relative_mae(via_file, via_maps) <= TOL
    assert relative_mae(a, via_file) <= TOL


def test_old_json_presets_still_load_and_json_refuses_maps(tmp_path):
    from alight.core.material import Material
    from alight.exchange.material_files import load_material_file, save_material_file

    m, maps, _ = load_material_file("gold")
    assert m.name == "gold" and maps.paths() == {}
    save_material_file(Material(), tmp_path / "p.json")
    assert load_material_file(tmp_path / "p.json")[0] == Material()
    with pytest.raises(AlightError, match="save it as .gltf or .glb"):
        save_material_file(Material(), tmp_path / "q.json", TextureMaps(base_color=str(tmp_path / "x.png")))
    assert not (tmp_path / "q.json").exists()


def _json(path: Path) -> dict:
    from alight.exchange.gltf_material import read_gltf_json

    return read_gltf_json(path)


# ---------------------------------------------------------------------------------- batch, editor

def test_batch_spec_takes_a_texture_set_and_maps(tmp_path):
    import io

    from alight.frontends.batch import main

    c = canonical()
    write_set(tmp_path / "rock", SETS["polyhaven_arm_dx"], c)
    twins = one_by_one(tmp_path, SETS["polyhaven_arm_dx"], c)
    maps = dict(arg.split("=", 1) for arg in twins[1::2])
    spec = tmp_path / "spec.toml"
    spec.write_text(
        'out = "renders"\nsize = 64\nquality = "low"\naa = "none"\ntonemap = "none"\nmeshes = ["sphere"]\n'
        'environments = ["studio"]\ncontact_sheet = false\n'
        'materials = [{name = "set", texture_set = "rock"}, {name = "maps", maps = {'
        + ", ".join(f'{k} = "{v}"' for k, v in maps.items()) + '}}, {name = "rough", texture_set = "rock", roughness = 0.2}]\n')
    assert main(str(spec), executor="inline", log=io.StringIO()) == 0
    images = {p.name.split("__")[2]: np.asarray(Image.open(p), np.float64) for p in (tmp_path / "renders").glob("*.png")}
    assert set(images) == {"set", "maps", "rough"}
    assert np.abs(images["set"] - images["maps"]).max() <= 1.0
    assert np.abs(images["set"] - images["rough"]).mean() > 1.0   # the spec's field wins over the map's factor


def test_editor_drop_of_several_files_is_a_texture_set(tmp_path, validate):
    """The window's drop routes several images to EditorState.open_texture_set (not all to
    base colour); save writes the glTF writer's file, which reopens as the same material."""
    from alight.frontends.editor.state import EditorState
    from alight.frontends.editor.window import EditorWindow

    c = canonical()
    write_set(tmp_path / "set", SETS["substance"], c)
    paths = sorted(str(p) for p in (tmp_path / "set").iterdir())

    class Fake:
        state = EditorState()
        drop_texture_set = EditorWindow.drop_texture_set
        _drop = EditorWindow._drop

    fake = Fake()
    fake.state.material = fake.state.material.__class__(base_color=(1.0, 0.8, 0.3), metallic=1.0, roughness=0.2)
    EditorWindow.drop(fake, paths)
    s = fake.state
    assert s.error == "", s.error
    assert Path(s.texture_maps.base_color).name == "Mat_BaseColor.png"
    assert Path(s.texture_maps.normal).name == "Mat_Normal.png"
    assert Path(s.texture_maps.occlusion).name == "Mat_AO.png"
    assert s.material.base_color == (1.0, 1.0, 1.0) and s.material.roughness == 1.0   # not tinted by gold
    assert "Mat_Height.png -> left out" in s.message
    s.load_mesh("sphere")
    (tmp_path / "saved").mkdir()
    s.save_material(str(tmp_path / "saved" / "look.gltf"))
    report = validate(tmp_path / "saved" / "look.gltf")[0]
    assert report["errors"] == 0 and report["warnings"] == 0, report["messages"]
    fresh = EditorState()
    assert fresh.open_file(str(tmp_path / "saved" / "look.gltf")), fresh.error   # reopens as a mesh with its material
    assert fresh.mesh.parts[0].material.base_color_texture is not None
    other = EditorState()
    other.load_material(str(tmp_path / "saved" / "look.gltf"))
    assert set(other.texture_maps.paths()) == {"base_color", "metallic_roughness", "normal", "occlusion", "emissive"}
    # The editor's .json preset keeps the factors and says the maps were left out (the CLI refuses).
    note = s.save_material(str(tmp_path / "look.json"))
    assert "6 maps left out" in note and ".gltf or .glb" in note, note   # a slot each
    assert EditorState().open_file(str(tmp_path / "look.json"))


def test_editor_texture_set_field_names_a_set_of_files_by_its_stem_and_count(tmp_path):
    """A set loaded as files (a drop of several, files typed with ';', an older session) showed
    their paths one after another, and the field's width the first: one map's path, read as the
    one map loaded. It names the set (the files' shared name, their count, their folder), the
    tooltip lists each file with its slots, and 'load set' on the field as shown reads the files."""
    from alight.frontends.cli import build_parser
    from alight.frontends.editor.run import build_state
    from alight.frontends.editor.state import EditorState

    c = canonical()
    folder = tmp_path / "Bricks"
    names = {"Bricks_2K_Color.png": "color", "Bricks_2K_NormalGL.png": "normal", "Bricks_2K_ORM.png": "orm",
             "Bricks_2K_Height.png": "rough"}
    write_set(folder, names, c)
    paths = sorted(str(p) for p in folder.iterdir())
    s = EditorState()
    s.open_texture_set(paths)   # (the height map is left out: three maps)
    assert s.texture_set_text() == f"Bricks_2K_* (3 maps) in {folder}", s.texture_set_text()
    assert s.texture_set_spec().split(";") == [str(folder / n) for n in
                                               ("Bricks_2K_Color.png", "Bricks_2K_NormalGL.png", "Bricks_2K_ORM.png")]
    assert s.texture_set_listing().splitlines() == [
        f"3 maps in {folder}:", "  Bricks_2K_Color.png: base colour", "  Bricks_2K_NormalGL.png: normal (tangent)",
        "  Bricks_2K_ORM.png: metal-rough (G rough, B metal), occlusion (R)"], s.texture_set_listing()
    again = EditorState()
    again.open_texture_set(s.texture_set_spec().split(";"))
    assert again.texture_maps == s.texture_maps
    # The folder read as a set: the field names the folder, as before (and 'alight edit --texture-set').
    s.open_texture_folder(str(folder))
    assert s.texture_set_text() == s.texture_set_spec() == str(folder)
    assert s.texture_set_listing().startswith(f"3 maps in {folder}:\n")
    started = build_state(build_parser().parse_args(["edit", "--texture-set", str(folder)]))
    assert started.texture_set_text() == str(folder), started.texture_set_text()
    # One map: its path. Files sharing no name, or in two folders: the count and where.
    s = EditorState()
    s.set_map("roughness", str(folder / "Bricks_2K_Height.png"))
    assert s.texture_set_text() == s.texture_set_spec() == str(folder / "Bricks_2K_Height.png")
    assert s.texture_set_listing() == f"1 map in {folder}:\n  Bricks_2K_Height.png: roughness (grey)"
    s.set_map("base_color", write(folder / "albedo.png", c["color"]))
    assert s.texture_set_text() == f"2 maps in {folder}", s.texture_set_text()
    s.set_map("normal", write(tmp_path / "other" / "normal.png", c["normal"]))
    assert s.texture_set_text() == "3 maps from 2 folders", s.texture_set_text()
    assert str(tmp_path / "other" / "normal.png") + ": normal (tangent)" in s.texture_set_listing()


def test_editor_opens_a_texture_set_maps_and_a_saved_gltf_as_render_does(tmp_path, display):
    """``alight edit --texture-set / --map / --preset FILE.gltf`` (screenshots under Xvfb): the
    set, its maps one by one and the exported file give the same picture."""
    from tests.test_editor import screenshot

    c = canonical()
    write_set(tmp_path / "set", SETS["polyhaven_arm_dx"], c)
    twins = one_by_one(tmp_path, SETS["polyhaven_arm_dx"], c)
    saved = tmp_path / "saved" / "look.gltf"
    saved.parent.mkdir()
    assert run("export", "--texture-set", tmp_path / "set", "--out", saved).returncode == 0
    by_set = screenshot(tmp_path, "set", "--texture-set", str(tmp_path / "set"))
    by_maps = screenshot(tmp_path, "maps", *map(str, twins))
    by_file = screenshot(tmp_path, "file", "--preset", str(saved))
    plain = screenshot(tmp_path, "plain", "--base-color", "1,1,1", "--metallic", "1", "--roughness", "1")
    assert np.abs(by_set - by_maps).max() <= 1.0
    assert np.abs(by_file - by_set).max() <= 1.0
    assert np.abs(by_set - plain).mean() > 5.0


def test_api_set_material_takes_sets_maps_and_files(tmp_path):
    from alight.frontends.api import Renderer

    c = canonical()
    write_set(tmp_path / "s", SETS["quixel_gloss"], c)
    files = sorted(str(p) for p in (tmp_path / "s").iterdir())
    r = Renderer(32)
    r.set_material("gold", texture_set=files, metallic=0.5)
    assert r.material.base_color == (1.0, 1.0, 1.0) and r.material.roughness == 1.0 and r.material.metallic == 0.5
    assert r.texture_maps.roughness_gloss and r.last_texture_set.slots == ("base_color", "roughness", "normal")
    assert not r.scene.use_file_materials and set(r.scene.texture_images) == set(files)
    r.set_material(roughness=0.3)   # fields only: the maps stay
    assert r.texture_maps is not None and r.material.roughness == 0.3
    with pytest.raises(AlightError, match="unknown texture slot 'albedo'"):
        r.set_material("gold", maps={"albedo": files[0]})
    with pytest.raises(AlightError, match="no such file"):
        r.set_material("gold", maps={"orm": str(tmp_path / "nope.png")})
    r.set_material("gold")          # a new material without maps clears them
    assert r.texture_maps is None and r.scene.texture_images == {}


def test_a_set_laid_over_maps_reports_only_its_own_slots(tmp_path):
    c = canonical()
    base = TextureMaps(emissive=write(tmp_path / "glow.png", c["emissive"]))
    found = assign_files([write(tmp_path / "x_Albedo.png", c["color"]), write(tmp_path / "notes.png", c["ao"])], base)
    assert found.slots == ("base_color",) and found.maps.emissive == base.emissive
    assert assign_files([str(tmp_path / "notes.png")], base).slots == ()


def test_a_textured_khronos_model_exported_again_is_validator_clean_and_renders_the_same(tmp_path, shared_data, validate):
    """DamagedHelmet (.gltf with JPEG maps beside it) through 'alight export --material-from
    --mesh' to .glb: every map, UVs and tangents go out; the validator is clean; same pixels."""
    helmet = shared_data / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
    if not helmet.is_file():
        pytest.skip("DamagedHelmet is not in the shared data")
    out = tmp_path / "helmet.glb"
    proc = run("export", "--material-from", helmet, "--mesh", helmet, "--out", out)
    assert proc.returncode == 0, proc.stderr
    report = validate(out)[0]
    assert report["errors"] == 0 and report["warnings"] == 0, report["messages"]
    gm = _json(out)["materials"][0]
    assert {"normalTexture", "occlusionTexture", "emissiveTexture"} <= set(gm)
    assert relative_mae(render(tmp_path / "a.exr", "--mesh", out), render(tmp_path / "b.exr", "--mesh", helmet)) <= TOL


def test_editor_one_map_sets_its_factor_to_1_and_a_session_keeps_saved_factors(tmp_path):
    from alight.core.material import Material
    from alight.frontends.editor.state import EditorState

    c = canonical()
    s = EditorState()
    s.material = Material(base_color=(1.0, 0.8, 0.3), metallic=1.0, roughness=0.2)
    s.set_map("roughness", write(tmp_path / "r.png", c["rough"]))
    assert s.material.roughness == 1.0 and s.material.base_color == (1.0, 0.8, 0.3)
    s.material = Material(roughness=0.4)
    s.set_map("roughness", str(tmp_path / "r.png"), factor_to_1=False)
    assert s.material.roughness == 0.4
