"""The editor in a real window under Xvfb: screenshots from `alight edit`, and drops, undo and
presets driven in-process on the real glfw window. Xvfb is started here when DISPLAY is unset."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def display():
    """A display for the editor: the caller's, or a private Xvfb started for this module."""
    if os.environ.get("DISPLAY"):
        yield os.environ["DISPLAY"]
        return
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is not installed and DISPLAY is unset: the editor needs a display")
    read, write = os.pipe()
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", "1920x1080x24", "-nolisten", "tcp"],
                            pass_fds=(write,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write)
    with os.fdopen(read) as f:
        number = f.readline().strip()   # Xvfb writes its display number once it is ready
    assert number, "Xvfb did not start"
    os.environ["DISPLAY"] = f":{number}"
    try:
        yield os.environ["DISPLAY"]
    finally:
        del os.environ["DISPLAY"]
        proc.terminate()
        proc.wait(timeout=10)


def edit(*args: str, size: str = "320x240") -> subprocess.CompletedProcess:
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "alight", "edit", "--size", size, *args], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=120)


def screenshot(tmp_path: Path, name: str, *args: str) -> np.ndarray:
    import OpenImageIO as oiio

    out = tmp_path / f"{name}.png"
    result = edit(*args, "--screenshot", str(out), "--frames", "3")
    assert result.returncode == 0, result.stderr
    image = oiio.ImageBuf(str(out)).get_pixels(oiio.UINT8)
    assert image.shape == (240, 320, 3)
    return image.astype(np.float64)


def ball(image: np.ndarray) -> np.ndarray:
    """Pixels well inside the default ball (it fills the middle of the 320x240 view)."""
    h, w = image.shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    return image[(x - w / 2) ** 2 + (y - h / 2) ** 2 < (0.25 * h) ** 2]


def test_gold_to_water_and_roughness(display, tmp_path):
    gold = ball(screenshot(tmp_path, "gold", "--preset", "gold"))
    water = ball(screenshot(tmp_path, "water", "--preset", "gold", "--script", "preset=water"))
    # Gold's reflection is yellow (F0 of gold: R well above B); water's F0 is grey (0.02).
    assert gold[:, 0].mean() > 1.5 * gold[:, 2].mean()
    assert water[:, 0].mean() < 1.1 * water[:, 2].mean()
    # Roughness changed through the scripted edit path: a mirror-like ball shows the studio's
    # sharp panels (high local contrast); a rough one blurs them away.
    sharp = screenshot(tmp_path, "sharp", "--preset", "gold", "--script", "roughness=0.05")
    rough = screenshot(tmp_path, "rough", "--preset", "gold", "--script", "roughness=0.9")

    def contrast(img):   # mean horizontal luminance step inside the ball
        lum = img.mean(axis=2)
        step = np.zeros_like(lum)
        step[:, 1:] = np.abs(np.diff(lum, axis=1))
        return ball(step[:, :, None]).mean()

    assert contrast(sharp) > 1.5 * contrast(rough)


def test_editor_cli_bad_input_is_one_line(display, tmp_path):
    result = edit("--preset", "no_such_preset", "--screenshot", str(tmp_path / "x.png"))
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "alight: error:" in result.stderr
    assert not (tmp_path / "x.png").exists()


def test_a_mesh_opened_by_script_is_drawn_as_the_mesh_option_draws_it(display, tmp_path, shared_data):
    """--script open=FILE (as a drop) shows a glTF's own materials, as --mesh and 'alight render'
    do; a file that cannot be opened stops the script: one line, exit 2, no screenshot."""
    duck = str(shared_data / "models" / "Duck.glb")
    opened = screenshot(tmp_path, "opened", "--new", "--script", f"open={duck}")
    given = screenshot(tmp_path, "given", "--new", "--mesh", duck)
    # open= puts the mesh on the GPU in steps with mip levels made on the CPU (alight.render.mesh_upload:
    # an sRGB level within 1 of llvmpipe's, whose sRGB encoding is an approximation); --mesh lets
    # GL make them: a few pixels of the minified texture a hair apart (0.3%, 2/255 at most, here).
    diff = np.abs(opened.astype(int) - given)
    assert diff.max() <= 3 and (diff > 0).mean() < 0.01, (diff.max(), (diff > 0).mean())
    assert ball(opened)[:, 0].mean() > ball(opened)[:, 2].mean() + 30   # the duck's yellow, not grey
    missing = edit("--new", "--script", f"open={tmp_path / 'missing.glb'}", "--screenshot", str(tmp_path / "x.png"))
    assert missing.returncode == 2 and missing.stderr.count("\n") == 1 and "missing.glb" in missing.stderr
    assert not (tmp_path / "x.png").exists()


def test_a_scripts_material_edit_is_seen_on_a_mesh_with_its_own_materials(display, tmp_path, shared_data):
    """--script preset= and roughness= after open= untick the mesh file's own materials, as the
    panel's controls do: the duck is drawn in the scripted material, as --mesh with --preset and
    --roughness draws it, not in its own yellow with the edit hidden."""
    duck = str(shared_data / "models" / "Duck.glb")
    scripted = screenshot(tmp_path, "scripted", "--new", "--script", f"open={duck}", "--script", "preset=gold",
                          "--script", "roughness=0.3")
    given = screenshot(tmp_path, "given", "--new", "--mesh", duck, "--preset", "gold", "--roughness", "0.3")
    assert np.abs(scripted - given).max() <= 3
    own = screenshot(tmp_path, "own", "--new", "--script", f"open={duck}")
    assert np.abs(scripted - own).mean() > 5.0
    plain = ball(screenshot(tmp_path, "plain", "--new", "--script", f"open={duck}", "--script", "roughness=0.3"))
    # the panel's default material (white), not the duck's yellow texture
    assert abs(plain[:, 0].mean() - plain[:, 2].mean()) < 15, plain.mean(axis=0)


def test_the_editor_takes_renders_scene_options(display, tmp_path):
    """--light replaces the editor's three lights (given as specs here: the same picture),
    --env-rotation is the panel's rotation (as --script sets it); --view probe, which the editor
    cannot show, is refused in one line."""
    from alight.frontends.editor.state import default_lights

    specs = []
    for light in default_lights():
        where = ("dir" if light.kind == "directional" else "pos") + "=" + ",".join(map(str, light.vector))
        specs += ["--light", f"{light.kind}:{where}:color={','.join(map(str, light.color))}:intensity={light.intensity}"]
    default = screenshot(tmp_path, "default")
    assert np.abs(screenshot(tmp_path, "spelled", *specs) - default).max() <= 1
    one = screenshot(tmp_path, "one", "--light", "point:pos=0,0,5:intensity=2")
    assert np.abs(one - default).mean() > 2.0
    rotated = screenshot(tmp_path, "rotated", "--env-rotation", "90")
    np.testing.assert_array_equal(rotated, screenshot(tmp_path, "scripted", "--script", "env_rotation=90"))
    assert np.abs(rotated - default).mean() > 1.0
    probe = edit("--view", "probe", "--screenshot", str(tmp_path / "p.png"))
    assert probe.returncode == 2 and probe.stderr.count("\n") == 1 and not (tmp_path / "p.png").exists()
    helped = edit("--help")   # ... and not offered: the editor's help has no --view
    assert helped.returncode == 0 and "--view" not in helped.stdout and "probe" not in helped.stdout, helped.stdout


def test_window_checks_in_a_fresh_process(display):
    """The checks that drive the real window in-process (tests/editor_window_checks.py) run in
    their own interpreter: the other GPU tests keep a headless EGL context current on this
    thread, and a GLX window context cannot be made current beside it (X error BadAccess), nor
    should it steal the thread from them."""
    # No plugin autoloading: the checks need none.
    env = dict(os.environ, PYTEST_DISABLE_PLUGIN_AUTOLOAD="1")
    result = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                             str(REPO / "tests" / "editor_window_checks.py")],
                            cwd=REPO, env=env, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    assert " passed" in result.stdout and "skipped" not in result.stdout, result.stdout[-2000:]


def test_debug_views_show_values(display, tmp_path):
    """Data views bypass exposure and tone mapping: a pixel is the value itself, in 8 bits."""
    normal = screenshot(tmp_path, "normal", "--preset", "gold", "--script", "debug_view=normal")
    # The ball's centre faces the camera: n = (0, 0, 1) is shown as (0.5, 0.5, 1).
    assert np.abs(normal[118:122, 158:162] - [128, 128, 255]).max() <= 3
    rough = ball(screenshot(tmp_path, "rough", "--preset", "gold", "--script", "roughness=0.3",
                            "--script", "debug_view=roughness"))
    assert np.abs(rough - 0.3 * 255).max() <= 1.5


def test_without_a_display(tmp_path):
    """`alight` alone prints the help when there is no display; `alight edit` says why it cannot run."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    bare = subprocess.run([sys.executable, "-m", "alight"], cwd=REPO, env=env, capture_output=True, text=True,
                          timeout=60)
    assert bare.returncode == 0 and "usage: alight" in bare.stdout and " edit " in bare.stdout
    edit_ = subprocess.run([sys.executable, "-m", "alight", "edit"], cwd=REPO, env=env, capture_output=True,
                           text=True, timeout=60)
    assert edit_.returncode == 2 and edit_.stderr.startswith("alight: error: editor: no display")
    assert edit_.stderr.count("\n") == 1
    # A DISPLAY that names no server: glfw's own words in the one line (pyGLFW printed them as a
    # two-line Python warning before it)
    gone = subprocess.run([sys.executable, "-m", "alight", "edit"], cwd=REPO, env={**env, "DISPLAY": ":987"},
                          capture_output=True, text=True, timeout=60)
    assert gone.returncode == 2 and gone.stderr.count("\n") == 1, gone.stderr
    assert gone.stderr.startswith("alight: error: editor: cannot open a window (") and ":987" in gone.stderr
    assert "GLFWError" not in gone.stderr and "b'" not in gone.stderr, gone.stderr
    bad = subprocess.run([sys.executable, "-m", "alight", "edit", "--screenshot", str(tmp_path / "x.jpg")], cwd=REPO,
                         env=env, capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "unsupported output format" in bad.stderr


def test_ibl_model_and_multiple_scattering_reach_the_scene():
    """The panel's IBL model and multiple-scattering controls edit plain state that the scene
    carries to the renderer; a wrong name from a script is one line."""
    from alight.core.ibl_models import DEFAULT_IBL_MODEL
    from alight.errors import AlightError
    from alight.frontends.editor.state import EditorState

    state = EditorState()
    assert state.scene(None).ibl_model == DEFAULT_IBL_MODEL
    state.apply_edit("ibl_model=lecture")
    state.apply_edit("multiple_scattering=1")
    scene = state.scene(None)
    assert scene.ibl_model == "lecture" and scene.multiple_scattering
    with pytest.raises(AlightError, match="ibl_model 'nope'"):
        state.apply_edit("ibl_model=nope")


def test_quality_auto_in_the_editor(display, tmp_path):
    """Bake quality 'auto' in the editor: the window bakes the measured choice for the studio
    and a rough gold (not medium) and renders the same ball as a medium bake to within the
    implementation-error budget: the ball's mean colour moves by less than 3%."""
    auto = ball(screenshot(tmp_path, "auto", "--preset", "gold", "--roughness", "0.7", "--quality", "auto"))
    medium = ball(screenshot(tmp_path, "medium", "--preset", "gold", "--roughness", "0.7"))
    assert np.abs(auto.mean(axis=0) - medium.mean(axis=0)).max() < 0.03 * medium.mean()
    from alight.accuracy.auto_quality import (
        MaterialNeed,
        choose_quality,
        environment_features,
    )
    from alight.ibl.environment import load_environment

    # What the window chose for it (a metal in the roughness band 0.5-1): within the budget and
    # a cheaper bake than medium.
    choice = choose_quality([MaterialNeed(("metal",), 0.5, 1.0)],
                            environment_features(load_environment("studio").radiance))
    assert choice.meets_budget and "within" in choice.line(0.02)
    assert choice.predicted_seconds < 0.5 * choice_seconds_of_medium(choice)


def choice_seconds_of_medium(choice) -> float:
    from alight.accuracy.auto_quality import load_table, predicted_seconds

    return predicted_seconds(load_table(), "medium", 1.0, False)


def test_a_dropped_file_says_what_it_is_drawn_without(tmp_path, capfd):
    """Opening (dropping) a mesh file with warnings says them on stderr (the editor runs under
    the CLI's alight.errors.on_stderr) and in the panel's message (their text: the status row
    shows it), not only for the file given at start."""
    from alight.errors import on_stderr
    from alight.frontends.editor.state import EditorState

    (tmp_path / "tri3.obj").write_text("mtllib absent.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    state = EditorState()
    with on_stderr():
        assert state.open_file(str(tmp_path / "tri3.obj"))
    assert state.message.startswith("opened tri3.obj; warning: ") and "mtllib 'absent.mtl' not found" in state.message
    assert "mtllib 'absent.mtl' not found" in capfd.readouterr().err


def test_keys_are_translated_by_the_layouts_character():
    """The editor's own loop hands imgui the key the layout prints (app/frontends/editor/keys.py):
    on AZERTY the key at Q's place prints 'a', and Ctrl+A must reach imgui as A."""
    import glfw

    from alight.frontends.editor.keys import translate_key

    assert translate_key(glfw.KEY_Q, "a") == glfw.KEY_A and translate_key(glfw.KEY_A, "q") == glfw.KEY_Q
    assert translate_key(glfw.KEY_SEMICOLON, "m") == glfw.KEY_M and translate_key(glfw.KEY_Z, "y") == glfw.KEY_Y
    assert translate_key(glfw.KEY_1, "&") == glfw.KEY_1 and translate_key(glfw.KEY_MINUS, "-") == glfw.KEY_MINUS
    assert translate_key(glfw.KEY_KP_1, "1") == glfw.KEY_KP_1   # the keypad keeps its codes
    assert translate_key(glfw.KEY_F1, None) == glfw.KEY_F1 and translate_key(glfw.KEY_ENTER, None) == glfw.KEY_ENTER
    for c in "abcxyz0123456789`-=[]\\,;'./":   # every code as glfw.h numbers it
        expected = getattr(glfw, f"KEY_{c.upper()}", None) if c.isalnum() else None
        if expected is not None:
            assert translate_key(glfw.KEY_SPACE, c) == expected, c


def test_a_terminated_editor_keeps_its_session(display, tmp_path):
    """SIGTERM (a logout, a kill) ends the editor as a close does: the session is saved, then the
    CLI's one line and status 143; it was lost whole (a trial's hour of work)."""
    import json
    import signal
    import time

    if shutil.which("xdotool") is None:
        pytest.skip("xdotool is not installed (tools/setup.sh installs it)")   # tells when the window is up
    env = dict(os.environ, ALIGHT_CONFIG_DIR=str(tmp_path / "config"), ALIGHT_CACHE_DIR=str(tmp_path / "cache"),
               ALIGHT_DATA_DIR=str(tmp_path / "data"))
    proc = subprocess.Popen([sys.executable, "-m", "alight", "edit", "--size", "320x240", "--preset", "copper"],
                            cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            found = subprocess.run(["xdotool", "search", "--onlyvisible", "--pid", str(proc.pid)],
                                   capture_output=True, text=True)
            if found.stdout.strip():
                break
            time.sleep(0.5)
        time.sleep(2.0)   # a few frames drawn
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 143 and "alight: terminated" in err, (proc.returncode, err[-2000:])
    session = json.loads((tmp_path / "config" / "editor-session.json").read_text())
    assert session["material"]["name"] == "copper", session
