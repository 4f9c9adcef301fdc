"""The editor's occlusion through its real UI (tests/editor_ui_checks_occlusion.py under the Dear
ImGui Test Engine, a real window under Xvfb), and its occluded view against ``alight render`` of
the same scene, size and camera."""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from test_editor import display  # noqa: F401  (the Xvfb fixture)
from test_editor_ui import ui_test

REPO = Path(__file__).resolve().parents[1]
CHECKS = REPO / "tests" / "editor_ui_checks_occlusion.py"
LIGHT = "dir:dir=-0.3,-1,-0.5:intensity=1"   # one light, given to both (the editor's default is three)


def test_occlusion_through_the_panel_and_the_view_equals_alight_render(display, tmp_path):
    from alight.accuracy.scenes import write_scene

    bowl = write_scene("bowl", tmp_path)
    result = ui_test(tmp_path, CHECKS, "--new", "--mesh", str(bowl), "--occlusion", "off", "--light", LIGHT,
                     size="800x480")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    checks = [line for line in CHECKS.read_text().splitlines() if line.startswith("def test_")]
    assert f"{len(checks)} passed, 0 failed" in result.stdout, result.stdout
    for line in result.stdout.splitlines():
        if line.startswith("OCCLUSION_"):
            print(line)
    view = json.loads((tmp_path / "occlusion_view.json").read_text())
    w, h = view["size"]
    env = dict(os.environ, ALIGHT_CACHE_DIR=str(tmp_path / "cache"), ALIGHT_CONFIG_DIR=str(tmp_path / "config"))
    import OpenImageIO as oiio

    def read(name: str) -> np.ndarray:
        return oiio.ImageBuf(str(tmp_path / name)).get_pixels(oiio.UINT8)[:h, :w, :3].astype(np.float64)

    def render(occlusion: str) -> np.ndarray:
        """`alight render` of the bowl with the view's camera and size."""
        out = f"render_{occlusion}.png"
        done = subprocess.run([sys.executable, "-m", "alight", "render", "--mesh", str(bowl), "--light", LIGHT,
                               "--occlusion", occlusion, "--size", f"{w}x{h}", "--orbit", str(view["orbit"]),
                               "--elevation", str(view["elevation"]), "--distance", str(view["distance"]),
                               "--fov", str(view["fov"]), "--target", ",".join(map(str, view["target"])),
                               "--aa", "none", "--out", str(tmp_path / out)],
                              env=env, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr[-3000:]
        return read(out)

    rendered, shown, off = render("auto"), read("occlusion_view.png"), read("occlusion_off.png")
    diff = np.abs(shown - rendered)
    print(f"EDITOR_VS_RENDER mean={diff.mean():.4f} max={diff.max():.0f} over2={(diff.max(axis=2) > 2).mean():.5f}; "
          f"off vs render mean={np.abs(off - rendered).mean():.4f}")
    # The same picture (the editor's anti-aliasing 'none' given to both): far closer than the
    # unoccluded one is.
    assert diff.max() <= 1.0, (diff.mean(), diff.max(), (diff.max(axis=2) > 1).mean())
    assert np.abs(off - rendered).mean() > 5 * diff.mean() + 0.5
    # The combo's gtao (the last check, same camera) against `alight render --occlusion gtao`.
    gtao_rendered, gtao_shown = render("gtao"), read("occlusion_gtao.png")
    gdiff = np.abs(gtao_shown - gtao_rendered)
    print(f"EDITOR_VS_RENDER_GTAO mean={gdiff.mean():.4f} max={gdiff.max():.0f}; "
          f"off vs gtao render mean={np.abs(off - gtao_rendered).mean():.4f}")
    assert gdiff.max() <= 1.0, (gdiff.mean(), gdiff.max())
    # Under the studio's soft light GTAO changes the bowl little (0.33 levels on average when
    # measured; the occluders' radiance stands in for much of the sky they hide), yet the
    # editor's view is gtao's: far closer to it than the unoccluded view is.
    assert gdiff.mean() < 0.1 * np.abs(off - gtao_rendered).mean()


def test_the_occlusion_setting_is_kept_in_the_session_and_taken_from_the_command_line(tmp_path, monkeypatch):
    """The combo's value is saved and reopened (an older session without it: 'auto', as 'alight
    render'); `alight edit --occlusion` and `--script occlusion=` set it; a bad value is one line."""
    import pytest

    from alight.errors import AlightError
    from alight.frontends.cli import build_parser
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.run import _no_scene_options, build_state
    from alight.frontends.editor.session import restore_session, save_session, session_path
    from alight.frontends.editor.state import EditorState

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path))
    assert EditorState().occlusion == "auto" and EditorState().scene(None).occlusion == "auto"
    state = EditorState(occlusion="off")
    save_session(state, OrbitCamera())
    fresh = EditorState()
    assert restore_session(fresh, OrbitCamera()) == "" and fresh.occlusion == "off"
    data = json.loads(session_path().read_text())
    del data["settings"]["occlusion"]
    session_path().write_text(json.dumps(data))
    fresh = EditorState(occlusion="on")
    assert restore_session(fresh, OrbitCamera()) == "" and fresh.occlusion == "auto"
    state.apply_edit("occlusion=on")
    assert state.occlusion == "on"
    with pytest.raises(AlightError, match="occlusion 'maybe' is not one of auto, on, off"):
        state.apply_edit("occlusion=maybe")
    args = build_parser().parse_args(["edit", "--occlusion", "off"])
    assert build_state(args).occlusion == "off" and not _no_scene_options(args)   # (a scene option: no reopening)
    args = build_parser().parse_args(["edit"])
    assert build_state(args).occlusion == "auto" and _no_scene_options(args)


def test_held_lighting_keeps_the_last_sky_weight_and_a_recorded_decision_casts_no_ray(tmp_path):
    """OcclusionParts as the editor drives it: with ``hold_lighting`` a turned environment draws
    the baked parts with the last sky weight (none made: the child makes it); without, it is made;
    ``decide`` stands for the child's 'auto' decision."""
    import pytest

    pytest.importorskip("embreex")
    from alight.accuracy.scenes import write_scene
    from alight.core.material import Material
    from alight.core.scene import Scene, default_camera
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import studio_environment
    from tests.gpu import renderer

    mesh = load_mesh(str(write_scene("bowl", tmp_path)))
    r = renderer()
    maps = r.bake(studio_environment(), "low")
    parts = r.visibility_parts
    scene = Scene(mesh=mesh, material=Material(), camera=default_camera(mesh, 1.0), occlusion="on")
    r.render(scene, maps, 48, 48, aa="none")
    made = parts.sky_weights_run + parts.sky_weights_loaded
    assert made >= 1
    parts.hold_lighting = True
    try:
        r.render(dataclasses.replace(scene, env_rotation_deg=90.0), maps, 48, 48, aa="none")
    finally:
        parts.hold_lighting = False
    assert parts.sky_weights_run + parts.sky_weights_loaded == made   # the last weight drawn
    r.render(dataclasses.replace(scene, env_rotation_deg=90.0), maps, 48, 48, aa="none")
    assert parts.sky_weights_run + parts.sky_weights_loaded == made + 1   # the new rotation's weight
    other = load_mesh(str(write_scene("corner", tmp_path)))
    parts.decide(other, "auto", False)
    assert parts.wanted(other, "auto") is False   # (the corner occludes itself: cast, it would be True)
