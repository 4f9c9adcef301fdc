"""End-to-end tests of the ``alight`` command line (``python -m alight ...``) through subprocesses.

Success paths check the written images against docs/conventions.md's output rules; bad input must
give exit status 2, exactly one ``alight: error:`` line naming the file or option, no traceback,
and nothing written (not even a temporary file). GL renders are kept at 64x64 and low quality.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

OpenImageIO = pytest.importorskip("OpenImageIO")
oiio = OpenImageIO

REPO = Path(__file__).resolve().parents[1]
SHARED_DATA = REPO.parent / "shared" / "data"  # same place conftest's shared_data fixture checks
BAD_DIR = SHARED_DATA / "bad"
BAD_MESHES = sorted(p.name for p in BAD_DIR.iterdir() if p.is_file()) if BAD_DIR.is_dir() else []
MUST_REFUSE = {"empty.obj", "empty_nodes.glb"}  # no triangles in them
MUST_RENDER = {"polygonfaces.obj", "negative_indices.obj"}

SIZE = 64
FAST = ("--size", str(SIZE), "--quality", "low")
PRESETS = ["water", "plastic_glass_low", "plastic_high", "glass_high_ruby", "diamond",
           "iron", "copper", "gold", "aluminium", "silver"]


# ----------------------------------------------------------------------------- helpers

def run(*args, timeout: float = 120) -> subprocess.CompletedProcess:
    """``python -m alight ARGS`` from the repository root, keeping the environment (ALIGHT_CACHE_DIR)."""
    return subprocess.run([sys.executable, "-m", "alight", *map(str, args)], cwd=REPO, env=dict(os.environ),
                          capture_output=True, text=True, timeout=timeout)


def render(out: Path, *args, fast: bool = True) -> subprocess.CompletedProcess:
    """``render --out OUT ARGS`` (64 px, low quality unless ``fast`` is False); asserts success."""
    proc = run("render", *(FAST if fast else ()), *args, "--out", out)
    assert_ok(proc, out)
    return proc


def assert_ok(proc: subprocess.CompletedProcess, out: Path) -> None:
    assert proc.returncode == 0, f"exit {proc.returncode}\nstdout: {proc.stdout}\nstderr: {proc.stderr}"
    assert "Traceback" not in proc.stdout + proc.stderr
    assert str(out) in proc.stdout, f"stdout does not name {out}: {proc.stdout!r}"
    assert out.is_file()


def assert_refused(proc: subprocess.CompletedProcess, names: list[str], out_dir: Path) -> None:
    """Exit 2, one ``alight: error:`` line naming each of ``names``, no traceback, nothing written."""
    everything = proc.stdout + proc.stderr
    assert proc.returncode == 2, f"exit {proc.returncode}\nstdout: {proc.stdout}\nstderr: {proc.stderr}"
    assert "Traceback" not in everything, everything
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, f"expected exactly one stderr line, got {lines!r}"
    assert lines[0].startswith("alight: error: "), lines[0]
    for name in names:
        assert name in lines[0], f"{name!r} not named in {lines[0]!r}"
    assert proc.stdout == "", proc.stdout
    leftovers = sorted(p.name for p in out_dir.iterdir())
    assert leftovers == [], f"files left in the output folder: {leftovers}"


def read(path: Path, fmt=None) -> tuple[np.ndarray, "oiio.ImageSpec"]:
    """Pixels (rows top first, H x W x C) and the file's spec; uint8 for PNG, float for EXR."""
    buf = oiio.ImageBuf(str(path))
    spec = buf.spec()
    assert not buf.has_error, buf.geterror()
    if fmt is None:
        fmt = oiio.FLOAT if path.suffix.lower() == ".exr" else oiio.UINT8
    pixels = np.asarray(buf.get_pixels(fmt))
    assert pixels.shape == (spec.height, spec.width, spec.nchannels)
    return pixels, spec


def probe_disk(w: int) -> np.ndarray:
    """docs/conventions.md's probe view: pixel (i, j) is on the sphere iff x*x + y*y < 1."""
    j, i = np.mgrid[0:w, 0:w]
    x = 2.0 * (i + 0.5) / w - 1.0
    y = 1.0 - 2.0 * (j + 0.5) / w
    return x * x + y * y < 1.0


def centre(a: np.ndarray, r: int = 2) -> np.ndarray:
    """Mean of the (2r x 2r) block at the image centre, per channel, as float."""
    h, w = a.shape[:2]
    return a[h // 2 - r:h // 2 + r, w // 2 - r:w // 2 + r].reshape(-1, a.shape[2]).astype(np.float64).mean(0)


@pytest.fixture
def out_dir(tmp_path: Path) -> Path:
    d = tmp_path / "out"
    d.mkdir()
    return d


# ----------------------------------------------------------------------------- success paths

def test_default_render_png(out_dir):
    out = out_dir / "x.png"
    render(out, "--size", SIZE, fast=False)  # the plain default: only --size and --out
    px, spec = read(out)
    assert (spec.width, spec.height, spec.nchannels) == (SIZE, SIZE, 3)
    assert spec.format == oiio.UINT8
    # The ball is lit and the studio is not black.
    assert centre(px).mean() > 20
    assert sorted(p.name for p in out_dir.iterdir()) == ["x.png"]  # no temporary left behind


def test_exr_is_float_rgba_with_coverage_alpha(out_dir):
    out = out_dir / "x.exr"
    render(out)
    px, spec = read(out)
    assert spec.format == oiio.FLOAT
    assert (spec.width, spec.height, spec.nchannels) == (SIZE, SIZE, 4)
    assert np.isfinite(px).all()
    assert px[SIZE // 2, SIZE // 2, 3] == 1.0
    for r, c in [(0, 0), (0, SIZE - 1), (SIZE - 1, 0), (SIZE - 1, SIZE - 1)]:
        assert px[r, c, 3] == 0.0, (r, c)
    assert (px[..., :3] >= 0).all()


def test_probe_exr_alpha_is_the_disk_and_background_is_zero(out_dir):
    out = out_dir / "p.exr"
    render(out, "--view", "probe")
    px, spec = read(out)
    assert spec.format == oiio.FLOAT and spec.nchannels == 4
    disk = probe_disk(SIZE)
    alpha = px[..., 3]
    assert np.array_equal(alpha == 1.0, disk), "alpha is not 1 exactly on the x^2+y^2<1 disk"
    assert (alpha[~disk] == 0.0).all()
    assert (px[~disk][:, :3] == 0.0).all(), "probe background radiance must be 0"
    assert np.isfinite(px).all() and (px[disk][:, :3] > 0).any()


def test_transparent_background_png_has_alpha(out_dir):
    out = out_dir / "t.png"
    render(out, "--background", "transparent")
    px, spec = read(out)
    assert spec.nchannels == 4 and (spec.width, spec.height) == (SIZE, SIZE)
    assert px[0, 0, 3] == 0 and px[SIZE - 1, SIZE - 1, 3] == 0
    assert px[SIZE // 2, SIZE // 2, 3] == 255


def test_background_help_says_what_each_output_has(out_dir):
    """``render --help`` said of --background 'alpha is 0 there in every mode', but a .png with
    the default background has no alpha: the help now says what each file holds, as written."""
    text = " ".join(run("render", "--help").stdout.split())
    assert "alpha is 0 there in every mode" not in text
    assert "A .png is RGB with the background drawn in, except with transparent: RGBA" in text, text
    assert "a .exr is RGBA in every mode, alpha 0 there" in text, text
    png, exr = out_dir / "env.png", out_dir / "env.exr"
    render(png)   # the default background, env
    render(exr)
    assert read(png)[1].nchannels == 3
    px, spec = read(exr)
    assert spec.nchannels == 4 and px[0, 0, 3] == 0.0 and px[0, 0, :3].max() > 0.0
    assert px[SIZE // 2, SIZE // 2, 3] == 1.0


def test_background_color_red(out_dir):
    out = out_dir / "red.png"
    render(out, "--background", "color", "--background-color", "1,0,0", "--tonemap", "none")
    px, spec = read(out)
    assert spec.nchannels == 3
    for r, c in [(0, 0), (SIZE - 1, SIZE - 1)]:
        red, green, blue = (int(v) for v in px[r, c])
        assert red >= 250 and green <= 5 and blue <= 5, px[r, c]


def test_presets_gold_and_water_on_probe(out_dir):
    gold, water = out_dir / "gold.png", out_dir / "water.png"
    render(gold, "--view", "probe", "--preset", "gold")
    render(water, "--view", "probe", "--preset", "water")
    g = centre(read(gold)[0])
    w = centre(read(water)[0])
    assert g[0] > g[2] + 25 and g[1] > g[2], f"gold centre not yellow: {g}"
    # Water is clear (transmissive): its centre shows what is behind, a little bluer since
    # water absorbs red; nothing of gold's yellow.
    assert w[2] >= w[0] and not (w[0] > w[2] + 25), f"water centre {w} is not clear or bluish"


def test_field_flags_override_preset(out_dir):
    out = out_dir / "blue.png"
    render(out, "--view", "probe", "--preset", "gold", "--base-color", "0,0,1")
    c = centre(read(out)[0])
    assert c[2] > c[0] + 25 and c[2] > c[1] + 25, f"gold with base colour 0,0,1 is not blue: {c}"


def test_exposure_brightens(out_dir):
    dark, bright = out_dir / "e0.png", out_dir / "e2.png"
    render(dark, "--exposure", "0")
    render(bright, "--exposure", "2")
    assert read(bright)[0].astype(np.float64).mean() > read(dark)[0].astype(np.float64).mean() + 10


def test_tonemaps(out_dir):
    images = {}
    for tm in ("none", "aces", "neutral"):
        out = out_dir / f"{tm}.png"
        render(out, "--tonemap", tm)
        px, spec = read(out)
        assert (spec.width, spec.height, spec.nchannels) == (SIZE, SIZE, 3)
        images[tm] = px.astype(np.int64)
    assert not np.array_equal(images["none"], images["aces"])
    assert not np.array_equal(images["aces"], images["neutral"])


@pytest.mark.parametrize("aa", ["none", "msaa", "ssaa"])
def test_antialiasing_modes(out_dir, aa):
    out = out_dir / f"{aa}.exr"
    render(out, "--aa", aa)
    px, spec = read(out)
    assert (spec.width, spec.height, spec.nchannels) == (SIZE, SIZE, 4)
    assert np.isfinite(px).all()
    assert px[SIZE // 2, SIZE // 2, 3] == 1.0 and px[0, 0, 3] == 0.0
    if aa == "none":  # no blending: coverage is exactly 0 or 1
        assert set(np.unique(px[..., 3]).tolist()) <= {0.0, 1.0}


def test_point_light_without_ibl_on_probe(out_dir):
    out = out_dir / "pl.exr"
    render(out, "--view", "probe", "--light", "point:pos=0,0,3:intensity=20", "--no-ibl")
    px, _ = read(out)
    disk = probe_disk(SIZE)
    lum = px[..., :3].mean(axis=2)
    assert lum[SIZE // 2, SIZE // 2] > 0.2, "the light in front does not light the centre"
    # The limb's normals face sideways or away from a light at (0,0,3): no light reaches them.
    j, i = np.mgrid[0:SIZE, 0:SIZE]
    x = 2.0 * (i + 0.5) / SIZE - 1.0
    y = 1.0 - 2.0 * (j + 0.5) / SIZE
    edge = disk & (x * x + y * y > 0.95)
    assert edge.sum() > 0
    assert lum[edge].max() < 0.01 * lum[SIZE // 2, SIZE // 2], "the probe's edge is lit"
    assert (px[~disk][:, :3] == 0.0).all()


def test_env_rotation_changes_image(out_dir):
    a, b = out_dir / "r0.png", out_dir / "r90.png"
    render(a)
    render(b, "--env-rotation", "90")
    diff = np.abs(read(a)[0].astype(np.int64) - read(b)[0].astype(np.int64))
    assert diff.mean() > 1.0, "rotating the environment by 90 degrees changed nothing"


@pytest.mark.parametrize("model", ["Duck.glb", "fuze.obj"])
def test_mesh_from_shared_data(shared_data, out_dir, model):
    out = out_dir / "m.png"
    render(out, "--mesh", shared_data / "models" / model, "--background", "transparent")
    px, spec = read(out)
    assert (spec.width, spec.height, spec.nchannels) == (SIZE, SIZE, 4)
    covered = (px[..., 3] > 0).mean()
    assert 0.01 < covered < 1.0, f"{model}: {covered:.3f} of the frame covered"


def test_bake_writes_all_maps(tmp_path):
    out = tmp_path / "baked"  # created by bake
    proc = run("bake", "--env", "studio", "--out", out, "--quality", "low", "--width", 64)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr
    assert str(out) in proc.stdout
    names = sorted(p.name for p in out.iterdir())
    assert not [n for n in names if n.startswith(".")], f"temporary files left: {names}"
    stems = {Path(n).stem for n in names}
    for stem in stems:
        assert f"{stem}.png" in names and f"{stem}.exr" in names, stem
    assert {"environment", "irradiance", "brdf_lut"} <= stems
    steps = sorted(s for s in stems if s.startswith("prefiltered_step"))
    assert steps, names
    assert stems == {"environment", "irradiance", "brdf_lut", "brdf_lut_directions", *steps}, names
    numbers, roughness = [], []
    for s in steps:
        m = re.fullmatch(r"prefiltered_step(\d\d)_r(\d\.\d{3})", s)
        assert m, s
        numbers.append(int(m.group(1)))
        roughness.append(float(m.group(2)))
    assert numbers == list(range(len(steps)))
    assert roughness == sorted(roughness) and roughness[-1] == 1.0
    for name in names:
        px, spec = read(out / name)
        assert np.isfinite(px).all(), name
        if name.endswith(".exr"):
            assert spec.format == oiio.FLOAT, name
        if not name.startswith("brdf_lut"):
            assert (spec.width, spec.height) == (64, 32), name


def test_a_flat_mesh_seen_edge_on_is_said(out_dir):
    """The default camera (on +Z, docs/conventions.md) sees a y = 0 plane edge-on: one warning says so
    and names the way out; from above (--elevation) it shows, without the warning."""
    plane = SHARED_DATA / "bad" / "singlevn.obj"
    edge_on = render(out_dir / "edge_on.png", "--mesh", plane)
    assert "edge-on" in edge_on.stderr and "--elevation" in edge_on.stderr
    above = render(out_dir / "above.png", "--mesh", plane, "--elevation", "30")
    assert "edge-on" not in above.stderr
    alpha_above = oiio.ImageBuf(str(out_dir / "above.png")).get_pixels(oiio.FLOAT)
    assert alpha_above.std() > 0.01                     # the plane shows
    assert "edge-on" not in render(out_dir / "ball.png").stderr


def test_edit_help_names_every_script_field():
    """'alight edit --help' lists every --script field EditorState.apply_edit takes, each map slot."""
    import re

    from alight.core.texture_maps import MAP_SLOTS
    from alight.frontends.editor import state

    text = " ".join(run("edit", "--help").stdout.split())
    source = Path(state.__file__).read_text()
    body = source[source.index("def apply_edit"):source.index("def _finite")]
    fields = set(re.findall(r'key == "([a-z_]+)"', body))
    for group in re.findall(r"key in \(([^)]*)\)", body):
        fields |= set(re.findall(r'"([a-z_]+)"', group))
    assert {"roughness", "open", "debug_mip", "uv_offset"} <= fields
    for name in sorted(fields | set(MAP_SLOTS)):
        assert re.search(rf"\b{name}\b", text), name


def test_a_misspelt_preset_names_the_closest(tmp_path):
    """A newcomer typed --preset gld: the error listed all sixteen presets and left the match to
    them. The one line now names the closest preset first."""
    out = tmp_path / "x.png"
    proc = run("render", "--preset", "gld", "--size", "8", "--out", str(out))
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert "gld: no preset or file of that name (did you mean gold?)" in proc.stderr, proc.stderr
    assert not out.exists()


def test_presets_lists_all_ten():
    proc = run("presets")
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr
    rows = [line.split()[0] for line in proc.stdout.splitlines()[1:] if line.strip()]
    assert rows[:10] == PRESETS, rows
    # Each row's metallic and roughness are the preset's own (car_paint's 0.6 once printed as 1).
    from alight.exchange.presets import load_preset

    for line in proc.stdout.splitlines()[1:]:
        name, metallic, roughness = line.split()[:3]
        m = load_preset(name)
        assert (float(metallic), float(roughness)) == (round(m.metallic, 2), round(m.roughness, 2)), line


# ----------------------------------------------------------------------------- bad input

def _make_inputs(inp: Path, shared: Path) -> None:
    inp.mkdir(exist_ok=True)
    rng = np.random.default_rng(1234)
    (inp / "x.hdr").write_bytes(rng.integers(0, 256, 4096, dtype=np.uint8).tobytes())
    full = (shared / "env" / "royal_esplanade_1k.hdr").read_bytes()
    (inp / "truncated.hdr").write_bytes(full[:len(full) // 2])
    (inp / "corrupt.glb").write_bytes(b"glTF" + rng.integers(0, 256, 300, dtype=np.uint8).tobytes())
    good = {"name": "p", "base_color": [0.5, 0.5, 0.5], "metallic": 0.0, "roughness": 0.5,
            "specular_f0": [0.04, 0.04, 0.04], "emissive": [0.0, 0.0, 0.0]}
    missing = {k: v for k, v in good.items() if k != "roughness"}
    (inp / "missing_field.json").write_text(json.dumps(missing))
    (inp / "rough.json").write_text(json.dumps({**good, "roughness": 1.5}))
    (inp / "notjson.json").write_text("{ this is not json\n")
    (inp / "short_vertex.obj").write_text("v 1 2\nf 1 2 3\n")            # a vertex of two coordinates
    (inp / "word_normal.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 zero 1\nf 1//1 2//1 3//1\n")
    (inp / "face_past_end.obj").write_text("v 0 0 0\nv 1 0 0\nf 1 2 9\n")   # trimesh: numpy's 0-based IndexError
    # A mesh no node places (no scene, no nodes): it said "no triangles in the file".
    (inp / "unplaced.gltf").write_text('{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 5}}]}]}')


# (args, things the one error line must name). {in}: the inputs folder, {data}: shared data,
# {out}: the (empty) output folder. --out {out}/x.png is added when a case has no --out.
BAD_INPUT = [
    pytest.param(["--env", "{in}/missing.hdr"], ["{in}/missing.hdr"], id="missing-env"),
    pytest.param(["--env", "{in}/x.hdr"], ["{in}/x.hdr"], id="corrupt-hdr"),
    pytest.param(["--env", "{in}/truncated.hdr"], ["{in}/truncated.hdr"], id="truncated-hdr"),
    pytest.param(["--env", "{data}/env/memorial.exr"], ["{data}/env/memorial.exr"], id="not-2to1-exr"),
    pytest.param(["--preset", "{in}/missing_field.json"], ["{in}/missing_field.json", "roughness"],
                 id="preset-missing-field"),
    pytest.param(["--preset", "{in}/rough.json"], ["{in}/rough.json", "roughness"], id="preset-roughness-range"),
    pytest.param(["--preset", "{in}/notjson.json"], ["{in}/notjson.json"], id="preset-not-json"),
    pytest.param(["--preset", "no_such_preset"], ["no_such_preset"], id="unknown-preset"),
    pytest.param(["--preset", ""], ["no preset"], id="empty-preset"),
    pytest.param(["--mesh", "{in}/missing.obj"], ["{in}/missing.obj"], id="missing-mesh"),
    # a folder or a file of the wrong kind: what the flag takes, not the reader library's words
    pytest.param(["--mesh", "{in}"], ["{in}: is a folder, not a mesh file", ".glb"], id="mesh-folder"),
    pytest.param(["--env", "{data}/bad/empty.obj"], ["{data}/bad/empty.obj: not an image alight reads", ".hdr or .exr"],
                 id="env-not-an-image"),
    pytest.param(["--mesh", "{in}/corrupt.glb"], ["{in}/corrupt.glb"], id="corrupt-glb"),
    pytest.param(["--roughness", "1.5"], ["--roughness"], id="roughness-range"),
    pytest.param(["--metallic", "abc"], ["--metallic"], id="metallic-nan"),
    pytest.param(["--size", "0"], ["--size"], id="size-zero"),
    pytest.param(["--base-color", "1,2"], ["--base-color"], id="base-color-2"),
    pytest.param(["--light", "nonsense"], ["--light"], id="light-nonsense"),
    pytest.param(["--out", "{out}/x.jpg"], ["{out}/x.jpg"], id="out-jpg"),
    pytest.param(["--out", "{out}/no_such_folder/x.png"], ["{out}/no_such_folder"], id="out-missing-folder"),
    pytest.param(["--view", "probe", "--size", "64x32"], ["--size"], id="probe-not-square"),
    # --view probe draws the material on its unit sphere through its own camera: what it would ignore is refused
    pytest.param(["--mesh", "{data}/models/Duck.glb", "--camera", "gltf", "--view", "probe"],
                 ["--camera gltf: not with --view probe", "orthographic camera"], id="probe-gltf-camera"),
    pytest.param(["--view", "probe", "--orbit", "30"], ["--orbit: not with --view probe"], id="probe-orbit"),
    pytest.param(["--view", "probe", "--ground"], ["--ground: not with --view probe"], id="probe-ground"),
    pytest.param(["--view", "probe", "--mesh", "cube"], ["--mesh cube: not with --view probe"], id="probe-mesh"),
    pytest.param(["--view", "probe", "--shadows", "on"], ["--shadows on: not with --view probe"], id="probe-shadows"),
    pytest.param(["--view", "probe", "--occlusion", "gtao"], ["--occlusion gtao: not with --view probe"],
                 id="probe-occlusion"),
    pytest.param(["--view", "probe", "--mesh-shading", "vbuffer"], ["--mesh-shading vbuffer: not with --view probe"],
                 id="probe-mesh-shading"),
    pytest.param(["--mesh", "sphere", "--camera", "gltf"],
                 ["--camera gltf: the built-in mesh 'sphere' has no glTF camera"], id="builtin-gltf-camera"),
    pytest.param(["--mesh", "{in}/short_vertex.obj"], ["{in}/short_vertex.obj: line 1: a vertex needs 3 coordinates"],
                 id="obj-short-vertex"),
    pytest.param(["--mesh", "{in}/word_normal.obj"], ["{in}/word_normal.obj: line 4: 'zero' is not a number"],
                 id="obj-word-in-normal"),
    pytest.param(["--mesh", "{in}/face_past_end.obj"],
                 ["{in}/face_past_end.obj: line 3: the face names vertex 9, but the file has 2 vertices"],
                 id="obj-face-past-the-end"),
    pytest.param(["--mesh", "{in}/unplaced.gltf"], ["{in}/unplaced.gltf: no node places a mesh"], id="gltf-no-node"),
]


@pytest.mark.parametrize("args, names", BAD_INPUT)
def test_bad_input_is_refused(shared_data, tmp_path, out_dir, args, names):
    inp = tmp_path / "in"
    _make_inputs(inp, shared_data)
    subst = {"{in}": str(inp), "{data}": str(shared_data), "{out}": str(out_dir)}

    def fill(text: str) -> str:
        for k, v in subst.items():
            text = text.replace(k, v)
        return text

    argv = ["render", "--quality", "low"]
    if "--size" not in args:
        argv += ["--size", str(SIZE)]
    argv += [fill(a) for a in args]
    if "--out" not in args:
        argv += ["--out", str(out_dir / "x.png")]
    assert_refused(run(*argv), [fill(n) for n in names], out_dir)


def test_bad_folder_listing(shared_data):
    names = {p.name for p in (shared_data / "bad").iterdir()}
    assert MUST_REFUSE <= names and MUST_RENDER <= names, names


@pytest.mark.parametrize("name", BAD_MESHES)
def test_bad_mesh_loads_or_is_refused(shared_data, out_dir, name):
    mesh = shared_data / "bad" / name
    out = out_dir / "m.png"
    proc = run("render", *FAST, "--mesh", mesh, "--out", out)
    if name in MUST_REFUSE:
        assert proc.returncode == 2, f"{name} has no triangles but was rendered"
    if name in MUST_RENDER:
        assert proc.returncode == 0, f"{name} should render: {proc.stderr}"
    if proc.returncode != 0:
        assert_refused(proc, [str(mesh)], out_dir)
        return
    assert_ok(proc, out)
    px, spec = read(out)
    assert (spec.width, spec.height, spec.nchannels) == (SIZE, SIZE, 3)
    # The same mesh as linear EXR: every value finite, coverage alpha in [0, 1].
    exr = out_dir / "m.exr"
    proc = run("render", *FAST, "--mesh", mesh, "--out", exr)
    assert_ok(proc, exr)
    lin, spec = read(exr)
    assert spec.nchannels == 4
    assert np.isfinite(lin).all(), f"{name}: non-finite pixels"
    assert ((lin[..., 3] >= 0) & (lin[..., 3] <= 1)).all()
    assert (lin[..., :3] >= 0).all()
    if name in MUST_RENDER:
        assert (lin[..., 3] > 0).any(), f"{name}: nothing of the mesh is visible"


def test_failed_render_leaves_existing_output_untouched(out_dir):
    out = out_dir / "keep.png"
    original = b"not really a png, but it must survive byte for byte\n" * 10
    out.write_bytes(original)
    proc = run("render", *FAST, "--env", out_dir.parent / "missing.hdr", "--out", out)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stdout + proc.stderr
    assert out.read_bytes() == original
    assert sorted(p.name for p in out_dir.iterdir()) == ["keep.png"]


def test_failed_exr_render_leaves_existing_output_untouched(shared_data, out_dir):
    out = out_dir / "keep.exr"
    original = bytes(range(256)) * 4
    out.write_bytes(original)
    proc = run("render", *FAST, "--env", shared_data / "env" / "memorial.exr", "--out", out)
    assert proc.returncode == 2
    assert out.read_bytes() == original
    assert sorted(p.name for p in out_dir.iterdir()) == ["keep.exr"]


# ----------------------------------------------------------------------------- help

HELP_OPTIONS = ["--mesh", "--env", "--env-rotation", "--env-intensity", "--preset", "--base-color",
                "--metallic", "--roughness", "--specular-f0", "--emissive", "--light", "--view", "--size",
                "--tonemap", "--exposure", "--background", "--quality", "--ibl", "--out"]


def test_render_help_documents_every_option():
    proc = run("render", "--help")
    assert proc.returncode == 0, proc.stderr
    text = proc.stdout
    for option in HELP_OPTIONS:
        # The option itself, not a longer one it is a prefix or suffix of (--env vs --env-rotation, --ibl vs --no-ibl).
        assert re.search(rf"(?<![\w-]){re.escape(option)}(?![\w-])", text), f"{option} not in render --help"


def test_sigterm_during_a_write_leaves_nothing_behind(tmp_path):
    """`kill` (SIGTERM) while a tiled image is being written: the temporary file beside the
    output is removed, as on Ctrl-C, and the exit status says so (128 + 15)."""
    import signal
    import time

    out = tmp_path / "huge.png"
    proc = subprocess.Popen([sys.executable, "-m", "alight", "render", "--size", "8192", "--aa", "none",
                             "--quality", "low", "--out", str(out)], cwd=REPO, env=dict(os.environ),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 300
        while not list(tmp_path.glob(".huge.*")) and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert list(tmp_path.glob(".huge.*")), "the render never started writing"
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 128 + 15, err
    assert err.strip().splitlines()[-1] == "alight: terminated"
    assert list(tmp_path.iterdir()) == []


def test_a_ground_with_nothing_to_catch_says_so(shared_data, out_dir):
    """--ground in the built-in studio with no light draws nothing (no shadow to catch): one
    warning line says so and how to get one (a new user's transparent render equalled the one
    without --ground, silently); with a directional light, no such line."""
    duck = str(shared_data / "models" / "Duck.glb")
    bare = run("render", "--mesh", duck, "--ground", "--background", "transparent", "--quality", "low",
               "--size", "48", "--out", str(out_dir / "a.png"))
    assert bare.returncode == 0, bare.stderr
    lines = [x for x in bare.stderr.splitlines() if "--ground" in x]
    assert len(lines) == 1 and lines[0].startswith("alight: warning: --ground: nothing casts a shadow"), bare.stderr
    assert "--light" in lines[0]
    lit = run("render", "--mesh", duck, "--ground", "--light", "directional:dir=-0.5,-1,-0.3", "--quality", "low",
              "--size", "48", "--out", str(out_dir / "b.png"))
    assert lit.returncode == 0 and "--ground" not in lit.stderr, lit.stderr


@pytest.mark.parametrize("flag,what", [("--mesh", "mesh"), ("--env", "environment"), ("--out", "output")])
def test_an_empty_path_is_said_to_be_empty(tmp_path, flag, what):
    """A path left empty (a script's unset variable: --mesh "$DIR/") is named as empty, not as
    the current folder ('': is a folder) or a missing file with no name: one line, exit 2."""
    args = {"--mesh": "sphere", "--env": "studio", "--out": str(tmp_path / "x.png")}
    args[flag] = ""
    result = run("render", "--size", "16", *[x for kv in args.items() for x in kv])
    assert result.returncode == 2, result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"alight: error: {what}: the path is empty"), result.stderr
    assert not list(tmp_path.iterdir())
