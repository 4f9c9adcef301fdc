"""KHR_materials_variants: a file's material variants, chosen by name with --variant (render,
reference), Renderer.set_mesh(..., variant=) / set_variant, and alight batch --variant. By
equivalence through the real command: a file with red and blue variants renders, with --variant
blue, like a control file whose primitives carry the blue materials directly, and without
--variant like one with the primitives' own materials. The blue variant's material has a normal
map and a texture that no primitive uses without a variant (the reader must keep them)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.files_cases import read_exr, rel_mae, render_exr, run
from tests.gltf_builder import FLOAT, UINT, Gltf

VIEW = ("--elevation", "20")


def _bumps() -> np.ndarray:
    y, x = np.mgrid[0:8, 0:8] / 8.0
    return (np.stack([0.5 + 0.3 * np.sin(6.28 * x), 0.5 + 0.3 * np.cos(6.28 * y), np.full_like(x, 0.9)], -1)
            * 255).astype(np.uint8)


def variants_glb(path, pick: str | None = "variants"):
    """Two spheres side by side. Materials: 0 grey (the left sphere's own), 1 green (the right's
    own), 2 red, 3 blue (a stripe texture and a normal map). ``pick``: 'variants' writes the
    extension (red: both spheres red; blue: the left sphere blue, the right keeps its own green);
    'own', 'red', 'blue' write the control with those materials set directly."""
    from alight.core.mesh import sphere

    part = sphere(48, 24, 0.8).parts[0]
    g = Gltf()
    uv = np.asarray(part.uvs, np.float64).copy()
    uv[:, 1] = 1.0 - uv[:, 1]
    grey = g.material(pbrMetallicRoughness={"baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0,
                                            "roughnessFactor": 0.5})
    green = g.material(pbrMetallicRoughness={"baseColorFactor": [0.1, 0.7, 0.2, 1.0], "metallicFactor": 0.0,
                                             "roughnessFactor": 0.4})
    red = g.material(pbrMetallicRoughness={"baseColorFactor": [0.8, 0.1, 0.1, 1.0], "metallicFactor": 0.0,
                                           "roughnessFactor": 0.3})
    stripes = np.zeros((8, 8, 3), np.uint8)
    stripes[:, ::2] = (60, 90, 230)
    stripes[:, 1::2] = (220, 220, 240)
    blue = g.material(pbrMetallicRoughness={"baseColorTexture": {"index": g.image(stripes)}, "metallicFactor": 0.0,
                                            "roughnessFactor": 0.35},
                      normalTexture={"index": g.image(_bumps())})
    own = {"variants": (grey, green), "own": (grey, green), "red": (red, red), "blue": (blue, green)}[pick]
    primitives = []
    for k, x in enumerate((-0.9, 0.9)):
        prim = {"attributes": {"POSITION": g.accessor(part.positions + [x, 0.0, 0.0], FLOAT, bounds=True),
                               "NORMAL": g.accessor(part.normals), "TEXCOORD_0": g.accessor(uv)},
                "indices": g.accessor(part.indices.reshape(-1), UINT), "material": own[k]}
        if pick == "variants":
            mappings = [{"material": red, "variants": [0]}] + ([{"material": blue, "variants": [1]}] if k == 0 else [])
            prim["extensions"] = {"KHR_materials_variants": {"mappings": mappings}}
        primitives.append(prim)
    g.mesh(primitives)
    if pick == "variants":
        g.doc["extensions"] = {"KHR_materials_variants": {"variants": [{"name": "red"}, {"name": "blue"}]}}
        g.use("KHR_materials_variants")
    return g.save(path)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("variants")
    return {pick: variants_glb(d / f"{pick}.glb", pick) for pick in ("variants", "own", "red", "blue")}


@pytest.mark.parametrize("variant, control", [(None, "own"), ("red", "red"), ("blue", "blue")])
def test_variant_renders_like_its_control(tmp_path, files, variant, control):
    chosen = ("--variant", variant) if variant else ()
    a, warn = render_exr(tmp_path / "a.exr", "--mesh", files["variants"], *chosen, *VIEW)
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", files[control], *VIEW)
    assert warn == []
    assert rel_mae(a, b) < 0.002
    other = {"own": "blue", "red": "own", "blue": "red"}[control]
    c, _ = render_exr(tmp_path / "c.exr", "--mesh", files[other], *VIEW)
    assert rel_mae(a, c) > 0.05   # the controls differ: the test could fail


def _one_error_line(proc) -> str:
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    (line,) = proc.stderr.strip().splitlines()
    assert line.startswith("alight: error:")
    return line


def test_unknown_variant_lists_the_names(tmp_path, files):
    out = tmp_path / "x.png"
    line = _one_error_line(run("render", "--size", "16", "--mesh", files["variants"], "--variant", "green",
                               "--out", out))
    assert not out.exists()
    assert "variants.glb" in line and "'green'" in line and "'red', 'blue'" in line


@pytest.mark.parametrize("mesh", ["own", "sphere"])
def test_variant_on_a_file_without_variants_is_refused(tmp_path, files, mesh):
    out = tmp_path / "x.png"
    line = _one_error_line(run("render", "--size", "16", "--mesh", files.get(mesh, mesh), "--variant", "red",
                               "--out", out))
    assert not out.exists() and "--variant red" in line and "no material variants" in line


def test_variant_with_a_preset_warns_that_it_changes_nothing(tmp_path, files):
    proc = run("render", "--size", "16", "--quality", "low", "--mesh", files["variants"], "--variant", "red",
               "--preset", "gold", "--out", tmp_path / "x.png")
    assert proc.returncode == 0, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if "--variant" in ln]
    assert len(lines) == 1 and lines[0].startswith("alight: warning:") and "changes nothing" in lines[0]


def test_reference_takes_the_variant(tmp_path, files):
    """alight reference (the path tracer for a mesh file) draws the chosen variant too."""
    def ref(out, *args):
        proc = run("reference", "--size", "24", "--samples", "4", "--max-bounces", "1", *args, *VIEW, "--out", out)
        assert proc.returncode == 0, proc.stderr
        return read_exr(out)

    a = ref(tmp_path / "a.exr", "--mesh", files["variants"], "--variant", "red")
    b = ref(tmp_path / "b.exr", "--mesh", files["red"])
    c = ref(tmp_path / "c.exr", "--mesh", files["own"])
    assert rel_mae(a, b) < 1e-4 < 0.05 < rel_mae(a, c)


def test_python_api_variant(tmp_path, files):
    """set_mesh(path, variant=) and set_variant draw what --variant draws; the names are mesh.variants."""
    import alight

    def cli(*args):
        out = tmp_path / "cli.png"
        proc = run("render", "--size", "48", "--quality", "low", "--mesh", files["variants"], *args, *VIEW,
                   "--out", out)
        assert proc.returncode == 0, proc.stderr
        from PIL import Image

        return np.asarray(Image.open(out).convert("RGBA"), np.float64)

    with alight.Renderer(48, quality="low") as r:
        r.set_camera(orbit_deg=0.0, elevation_deg=20.0)
        r.set_mesh(files["variants"], variant="blue")
        assert r.mesh.variants == ["red", "blue"] and r.mesh.variant == "blue"
        blue = r.render(48, 48).astype(np.float64)
        red = r.set_variant("red").render(48, 48).astype(np.float64)
        own = r.set_variant(None).render(48, 48).astype(np.float64)
        with pytest.raises(alight.Error, match=r"no material variant named 'green'.*'red', 'blue'"):
            r.set_variant("green")
        assert r.mesh.variant is None
    for image, args in ((blue, ("--variant", "blue")), (red, ("--variant", "red")), (own, ())):
        assert np.abs(image - cli(*args)).mean() < 1.0
    assert np.abs(blue - red).mean() > 5.0


def _batch(tmp_path, name, meshes, *args, materials=None):
    import json

    spec = {"out": name, "size": 40, "quality": "low", "meshes": [str(m) for m in meshes], "contact_sheet": False}
    if materials is not None:
        spec["materials"] = materials
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(spec))
    return run("batch", path, "--executor", "inline", *args), tmp_path / name


def test_batch_variant_renders_like_the_control(tmp_path, files):
    from PIL import Image

    proc, out = _batch(tmp_path, "v", [files["variants"]], "--variant", "blue")
    assert proc.returncode == 0, proc.stderr
    proc_c, out_c = _batch(tmp_path, "c", [files["blue"]], materials=["own"])
    assert proc_c.returncode == 0, proc_c.stderr
    a = np.asarray(Image.open(out / "variants-blue__studio__own__cam000_env000.png"), np.float64)
    b = np.asarray(Image.open(out_c / "blue__studio__own__cam000_env000.png"), np.float64)
    assert np.abs(a - b).mean() < 1.0


@pytest.mark.parametrize("case, expect", [
    ("sphere", "has no material variants"), ("own", "has no material variants"),
    ("green", "no material variant named 'green'; its variants: 'red', 'blue'"),
    ("gold", 'add "own" to'),
])
def test_batch_variant_refusals(tmp_path, files, case, expect):
    mesh = {"sphere": "sphere", "own": files["own"]}.get(case, files["variants"])
    variant = "green" if case == "green" else "red"
    proc, out = _batch(tmp_path, "x", [mesh], "--variant", variant,
                       materials=["gold"] if case == "gold" else None)
    line = _one_error_line(proc)
    assert expect in line and "x.json" in line and not out.exists()
