"""alight batch (app/frontends/batch.py): names, failures, reruns, contact sheet, turntables, the process pool."""

from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from PIL import Image

from alight.errors import AlightError
from alight.frontends.batch import main, plan, run, summary

REPO = Path(__file__).resolve().parents[1]

SPEC = """
size = [40, 32]
quality = "low"
meshes = ["sphere", "duck.glb"]
environments = ["studio"]
materials = ["gold", {name = "rough_copper", preset = "copper", roughness = 0.8}]
camera_angles = [0, 90]
"""


def write_spec(folder: Path, text: str = SPEC, name: str = "spec.toml") -> Path:
    p = folder / name
    p.write_text(text)
    return p


@pytest.fixture
def folder(tmp_path, shared_data):
    shutil.copy(shared_data / "models" / "Duck.glb", tmp_path / "duck.glb")
    return tmp_path


def test_plan_names_are_predictable(folder):
    p = plan(write_spec(folder))
    names = sorted(i.name for i in p.stills)
    assert len(names) == 2 * 1 * 2 * 2
    assert names[0] == "duck__studio__gold__cam000_env000.png"
    assert "sphere__studio__rough_copper__cam090_env000.png" in names
    assert p.out_dir == folder / "spec" and not p.frames


def test_batch_renders_reports_failures_and_goes_on(folder, shared_data):
    # A file that is there but cannot be read fails its items, and the batch goes on (a missing
    # one stops the plan before anything renders: test_a_missing_input_stops_the_plan).
    shutil.copy(shared_data / "bad" / "empty.obj", folder / "missing.obj")
    spec = write_spec(folder, SPEC.replace('"duck.glb"]', '"duck.glb", "missing.obj"]'))
    log = io.StringIO()
    status = main(str(spec), executor="local", workers=2, log=log)
    out = log.getvalue()
    assert status == 1
    good = sorted((folder / "spec").glob("*.png"))
    assert len(good) == 8 + 1  # 8 stills and the contact sheet
    with Image.open(folder / "spec" / "sphere__studio__gold__cam000_env000.png") as im:
        assert im.size == (40, 32)
    assert "12/12" in out and "left" in out  # progress: count and time left
    assert "8 rendered, 0 up to date, 4 failed" in out
    assert out.count("FAILED missing__studio__") == 4 and "missing.obj: no triangles in the file" in out
    with Image.open(folder / "spec" / "contact_sheet.png") as sheet:
        assert sheet.size[0] > 0 and sheet.size[1] > 0
        # 12 cells (failed ones blank but labelled): a 4 x 3 grid of 160-pixel thumbnails
        assert sheet.size == (4 * 160, 3 * (160 + 28))


def test_rerun_skips_up_to_date_and_redoes_stale(folder):
    spec = write_spec(folder)
    assert main(str(spec), executor="inline", log=io.StringIO()) == 0
    log = io.StringIO()
    assert main(str(spec), executor="inline", log=log) == 0
    assert "0 rendered, 8 up to date, 0 failed" in log.getvalue()
    # An input changes: only the items that read it are rendered again.
    later = max(p.stat().st_mtime for p in (folder / "spec").glob("*.png")) + 10
    os.utime(folder / "duck.glb", (later, later))
    log = io.StringIO()
    assert main(str(spec), executor="inline", log=log) == 0
    assert "4 rendered, 4 up to date" in log.getvalue()
    # The spec changes: everything is stale.
    os.utime(spec, (later + 10, later + 10))
    log = io.StringIO()
    main(str(spec), executor="inline", log=log)
    assert "8 rendered, 0 up to date" in log.getvalue()


def test_turntable_png_sequence_and_animation(folder):
    text = SPEC.replace('camera_angles = [0, 90]', 'camera_angles = [0]').replace(
        '"duck.glb"]', ']').replace(', {name = "rough_copper", preset = "copper", roughness = 0.8}', "")
    text += '\n[turntable]\nframes = 5\nrotate = "environment"\nformat = "gif"\n'
    spec = write_spec(folder, text)
    assert main(str(spec), executor="inline", log=io.StringIO()) == 0
    frames = sorted((folder / "spec" / "turntable" / "sphere__studio__gold").glob("frame_*.png"))
    assert [f.name for f in frames] == [f"frame_{i:03d}.png" for i in range(5)]
    with Image.open(folder / "spec" / "turntable" / "sphere__studio__gold.gif") as gif:
        assert gif.n_frames == 5
    # The environment turns: frames differ.
    a, b = (Image.open(f).tobytes() for f in frames[:2])
    assert a != b


def test_json_spec_and_apng(folder):
    spec = write_spec(folder, json.dumps({"size": 24, "quality": "low", "materials": ["silver"],
                                          "turntable": {"frames": 3, "format": "apng"}}), "spec.json")
    assert main(str(spec), executor="inline", log=io.StringIO()) == 0
    with Image.open(folder / "spec" / "turntable" / "sphere__studio__silver.apng") as anim:
        assert anim.n_frames == 3


@pytest.mark.parametrize("text, problem", [
    ("size = 32\nmeshs = ['sphere']\n", "unknown key 'meshs'"),
    ("size = [32\n", "not valid TOML"),
    ("size = 0\n", "'size'"),
    ("quality = 'best'\n", "'quality'"),
    ("meshes = []\n", "non-empty list"),
    ("meshes = ['a/x.obj', 'b/x.obj']\n", "share the name 'x'"),
    ("materials = [{preset = 'gold', shininess = 3}]\n", "unknown field 'shininess'"),
    ("[turntable]\nframes = 0\n", "frames"),
])
def test_bad_specs_are_one_line_errors(folder, text, problem):
    with pytest.raises(AlightError, match=problem):
        plan(write_spec(folder, text))


@pytest.mark.parametrize("line, where", [
    ('materials = ["gold", "water.gltf"]', "materials[1]: "),
    ('materials = [{preset = "gold", maps = {base_color = "nosuch.png"}}]', "materials[0]: "),
    ('materials = [{name = "set", texture_set = "no_folder"}]', "materials[0]: "),
    ('meshes = ["sphere", "nosuch.glb"]', "meshes[1]: "),
    ('environments = ["studio", "nosuch.hdr"]', "environments[1]: "),
    ('materials = ["gold", "goldd"]', "materials[1]: 'goldd' is neither a preset nor a file (did you mean gold?) (presets: aluminium, "),
])
def test_a_missing_input_stops_the_plan(folder, line, where):
    """A new user ran the batch guide's example, whose water.gltf is not shipped: every item that
    used it failed in turn (212 FAILED lines). Every file the spec names is looked for first;
    one missing stops the plan with one line naming the entry and the path, exit 2, nothing
    rendered."""
    write_spec(folder, 'size = 32\nquality = "low"\n' + line + "\n")
    r = cli("spec.toml", cwd=folder)
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert where in r.stderr and ("no such file" in r.stderr or "nor a file" in r.stderr)
    assert not (folder / "spec").exists()


def test_the_guides_example_spec_plans(folder, shared_data):
    """docs/guides/batch.md's example spec, its ../shared paths pointed at the shared data,
    plans without an error (every file it names exists)."""
    page = (REPO / "docs" / "guides" / "batch.md").read_text()
    text = page.split("```toml\n", 1)[1].split("```", 1)[0]
    text = text.replace("../shared/data/", str(shared_data).rstrip("/") + "/")
    p = plan(write_spec(folder, text))
    assert p.stills and p.frames


def cli(*args, cwd):
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "alight", "batch", *args], capture_output=True, text=True,
                          cwd=cwd, env=env)


def test_cli_bad_spec_exit_2_and_nothing_written(folder):
    write_spec(folder, "meshs = 1\n")
    r = cli("spec.toml", cwd=folder)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "unknown key" in r.stderr
    assert not (folder / "spec").exists()
    r = cli("nosuch.yaml", cwd=folder)
    assert r.returncode == 2 and "is .toml or .json" in r.stderr


def test_cli_batch_with_process_pool(folder):
    write_spec(folder, SPEC.replace('"duck.glb"]', ']'))
    r = cli("spec.toml", "--workers", "2", cwd=folder)
    assert r.returncode == 0, r.stderr
    assert "4 rendered, 0 up to date, 0 failed" in r.stderr
    assert len(list((folder / "spec").glob("sphere__*.png"))) == 4
    assert not list(folder.rglob("*.tmp*"))  # atomic writes leave no temporaries


def test_failed_animation_and_summary_lines(folder, shared_data):
    shutil.copy(shared_data / "bad" / "empty.obj", folder / "missing.obj")   # there, unreadable
    text = 'size = 16\nquality = "low"\nmeshes = ["missing.obj"]\n[turntable]\nframes = 2\n'
    result = run(plan(write_spec(folder, text)), executor="inline", log=io.StringIO())
    text = summary(result)
    assert "0 rendered" in text and "missing__studio__gold.gif" in text and "not written" in text


def test_ray_executor_on_a_local_two_worker_cluster(folder, shared_data):
    """A real Ray cluster (head + 2 CPUs) started by this test; two actors, each its own GL context."""
    ray = pytest.importorskip("ray", reason="Ray is not installed (pip install 'alight[ray]')")
    shutil.copy(shared_data / "bad" / "empty.obj", folder / "missing.obj")   # there, unreadable
    spec = write_spec(folder, SPEC.replace('"duck.glb"]', '"duck.glb", "missing.obj"]'))
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, object_store_memory=80 * 1024 * 1024)
    try:
        assert ray.cluster_resources()["CPU"] == 2
        log = io.StringIO()
        result = run(plan(spec), executor="ray", workers=2, log=log)
    finally:
        ray.shutdown()
    assert len(result.rendered) == 8 and len(result.failed) == 4
    assert all("missing.obj: no triangles in the file" in reason for _, reason in result.failed)
    # The same images as an in-process render.
    ray_images = {p.name: Image.open(p).tobytes() for p in (folder / "spec").glob("*__cam*.png")}
    assert len(ray_images) == 8
    local = run(plan(spec, folder / "inline"), executor="inline", log=io.StringIO())
    assert len(local.rendered) == 8
    for name, data in ray_images.items():
        with Image.open(folder / "inline" / name) as im:
            assert im.tobytes() == data, name


def test_file_warnings_are_printed_once_per_batch(folder):
    """What a mesh file is drawn without (here an OBJ's missing mtllib) is said once, however
    many items and workers read the file."""
    (folder / "tri.obj").write_text("mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    spec = write_spec(folder, SPEC.replace('"duck.glb"]', '"tri.obj"]'))
    log = io.StringIO()
    assert main(str(spec), executor="local", workers=2, log=log) == 0
    lines = [line for line in log.getvalue().splitlines() if line.startswith("alight: warning:")]
    assert len(lines) == 1 and "mtllib 'gone.mtl' not found" in lines[0], lines


@pytest.mark.parametrize("text, said", [
    ('environments = ["stuido"]\n', "environments[0]: {folder}/stuido: no such file or folder; did you mean studio?"),
    ('environments = ["maps/venise.hdr"]\n', "did you mean {folder}/maps/venice.hdr?"),
    ('materail = ["gold"]\n', "unknown key 'materail'; did you mean materials?"),
    ('size = 9000\n', "'size' must be an integer or [W, H], 1..8192 (each batch worker holds its whole image"),
], ids=["env-studio", "env-file-in-folder", "key", "size-cap-says-why"])
def test_cli_spec_typos_name_the_closest(folder, text, said):
    """One line naming the spec, the entry and the closest valid name; exit 2; nothing written."""
    (folder / "maps").mkdir()
    (folder / "maps" / "venice.hdr").write_bytes(b"")
    (folder / "maps" / "quarry.exr").write_bytes(b"")
    spec = write_spec(folder, 'size = 16\nquality = "low"\n' * ("size" not in text) + text)
    r = cli(str(spec), cwd=folder)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("alight: error: ") and "Traceback" not in r.stderr, lines
    assert str(spec) in lines[0] and said.replace("{folder}", str(folder.resolve())) in lines[0], lines[0]
    assert not (folder / "spec").exists()


def test_the_guides_spec_plans_with_every_key_it_shows(shared_data, tmp_path):
    """docs/guides/batch.md's spec (every key a spec takes) is a valid spec: it plans, the
    paths it names resolve from the checkout (relative to the spec's folder, as the page says)."""
    import re as _re

    from alight.frontends.batch import plan

    page = (REPO / "docs" / "guides" / "batch.md").read_text(encoding="utf-8")
    text = _re.search(r"```toml\n(.*?)```", page, _re.S).group(1)
    spec = tmp_path / "spec.toml"
    spec.write_text(text.replace("../shared/data", str(shared_data)), encoding="utf-8")
    made = plan(spec, out=tmp_path / "out")
    assert len(made.stills) == 2 * 2 * 3 * 2 and len(made.animations) == 2 * 2 * 3, (len(made.stills), len(made.animations))
