"""The editor's real glfw window driven in-process: drops, undo/redo, presets, hot reload,
session, redraw policy. Run by tests/test_editor.py in a fresh interpreter with DISPLAY set
(see test_window_checks_in_a_fresh_process); not collected on its own."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from alight.errors import AlightError

REPO = Path(__file__).resolve().parents[1]


def ball(image: np.ndarray) -> np.ndarray:
    h, w = image.shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    return image[(x - w / 2) ** 2 + (y - h / 2) ** 2 < (0.25 * h) ** 2]


@pytest.fixture(scope="module")
def window():
    from alight.frontends.editor.state import EditorState
    from alight.frontends.editor.window import EditorWindow

    assert os.environ.get("DISPLAY"), "run through tests/test_editor.py, which provides a display"
    state = EditorState()
    state.load_mesh("sphere")
    state.load_env("studio")
    win = EditorWindow(state, (320, 240))
    win.frame()
    yield win
    win.close()


def test_drops_keep_previous_state_and_show_the_error(window, tmp_path, shared_data):
    from alight.exchange.meshes import load_mesh

    corrupt = tmp_path / "corrupt.hdr"
    corrupt.write_bytes(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 64 +X 128\n" + b"\x02\x02" * 40)
    bad_json = tmp_path / "bad.json"
    bad_json.write_text('{"name": "x", "rougness": 0.5}')
    files = sorted((shared_data / "bad").iterdir()) + [corrupt, bad_json, tmp_path / "notes.txt"]
    errors = 0
    for path in files:
        s = window.state
        before = (s.mesh, s.env, s.material)
        try:
            load_mesh(str(path))
            should_fail = path.suffix.lower() not in (".obj", ".glb", ".gltf", ".ply", ".stl")
        except AlightError:
            should_fail = True
        window.drop([str(path)])   # what glfw's drop callback calls
        window.frame()             # the editor keeps running and draws the panel
        while window.panel.file_jobs.busy:   # a mesh file is read on the panel's worker thread
            window.frame()
        window.frame()
        if should_fail:
            errors += 1
            assert (s.mesh, s.env, s.material) == before, path.name
            assert s.error and "\n" not in s.error
            assert window.panel.shown_error == s.error, "the panel did not draw the error"
            assert path.name in s.error
        else:
            assert s.error == "", s.error
            assert s.mesh is not before[0]    # a repaired mesh file is loaded
    assert errors >= 5   # empty.obj, empty_nodes.glb, the corrupt HDR, the bad preset, the .txt
    # A good drop afterwards clears the error and replaces the state.
    window.drop([str(REPO / "presets" / "copper.json")])
    window.frame()
    assert window.state.error == "" and window.state.material.name == "copper"


def test_a_dropped_mesh_and_a_script_open_are_read_on_the_worker(window, shared_data):
    """A mesh file dropped on the window and --script open= go through the panel's file jobs
    (a worker thread reads it and makes its upload's CPU side; frames put it on the GPU): the
    drop returns at once, frames are drawn meanwhile, and the mesh arrives whole."""
    from alight.frontends.editor import run

    jobs = window.panel.file_jobs
    duck = str(shared_data / "models" / "Duck.glb")
    box = str(shared_data / "models" / "BoxTextured.glb")
    for path, ask in ((duck, lambda p: window.drop([p])), (box, lambda p: window.state.apply_edit(f"open={p}"))):
        started, frames = jobs.started, jobs.frames_while_running
        ask(path)
        assert jobs.started == started + 1, "the file was not read on the panel's worker thread"
        assert window.state.mesh_spec != path   # not assigned in the call: a frame takes it
        if path == box:
            run._finish_open(window)   # what the script loop does after open=
        while jobs.busy:
            window.frame()
        assert window.state.mesh_spec == path and not window.state.error, (window.state.mesh_spec, window.state.error)
        assert jobs.frames_while_running > frames
    started = jobs.started   # a script's open= of a broken file stops the script: one line
    window.state.apply_edit(f"open={shared_data / 'bad' / 'empty.obj'}")
    with pytest.raises(AlightError, match="empty.obj"):
        run._finish_open(window)
    assert jobs.started == started + 1 and window.state.mesh_spec == box
    window.state.error = ""
    window.state.load_mesh("sphere")


def test_undo_redo_of_material_edits(window):
    import dataclasses

    s, h = window.state, window.history
    start = s.material
    s.material = dataclasses.replace(start, roughness=0.11)
    window.frame()                        # no widget active: the edit becomes one undo step
    s.material = dataclasses.replace(s.material, metallic=1.0 - start.metallic)
    window.frame()
    s.look = h.undo(s.look)
    assert (s.material.roughness, s.material.metallic) == (0.11, start.metallic)
    s.look = h.undo(s.look)
    assert s.material == start
    s.look = h.redo(s.look)
    s.look = h.redo(s.look)
    assert (s.material.roughness, s.material.metallic) == (0.11, 1.0 - start.metallic)
    # The same through the keyboard, as glfw delivers it: Ctrl+Z undoes, Ctrl+Shift+Z redoes.
    import glfw

    def key(k, action):
        window.impl.keyboard_callback(window.window, k, 0, action, 0)

    def chord(*keys):
        for k in keys:
            key(k, glfw.PRESS)
        window.frame()
        for k in reversed(keys):
            key(k, glfw.RELEASE)
        window.frame()

    chord(glfw.KEY_LEFT_CONTROL, glfw.KEY_Z)
    assert (s.material.roughness, s.material.metallic) == (0.11, start.metallic)
    chord(glfw.KEY_LEFT_CONTROL, glfw.KEY_LEFT_SHIFT, glfw.KEY_Z)
    assert (s.material.roughness, s.material.metallic) == (0.11, 1.0 - start.metallic)


def test_preset_saved_from_panel_state_loads_back_equal(window, tmp_path, monkeypatch):
    import dataclasses

    from alight.frontends.editor.state import EditorState

    s = window.state
    s.material = dataclasses.replace(s.material, name="mine", base_color=(0.7, 0.2, 0.1), roughness=0.37,
                                     metallic=0.25, emissive=(0.5, 0.0, 0.0))
    path = tmp_path / "mine.json"
    s.save_material(str(path))
    other = EditorState()
    assert other.open_file(str(path)), other.error
    assert other.material == s.material
    good = path.read_bytes()
    # An invalid material is refused before anything is written.
    s.material = dataclasses.replace(s.material, roughness=2.0)
    with pytest.raises(AlightError, match="roughness"):
        s.save_material(str(path))
    assert path.read_bytes() == good
    # A write that fails at the last step (the rename) leaves the old file whole and no temporary.
    s.material = dataclasses.replace(s.material, roughness=0.5)

    def broken_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr("alight.exchange.output.os.replace", broken_replace)
    with pytest.raises(AlightError, match="No space left"):
        s.save_material(str(path))
    assert path.read_bytes() == good
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.json"]


def test_shader_hot_reload_keeps_the_last_good_program(window, tmp_path):
    import dataclasses

    import OpenImageIO as oiio

    from alight.core.gpu import ShaderLibrary
    from alight.frontends.editor.hot_reload import ShaderWatcher

    def shot(name):
        window.frame()
        window.screenshot(str(tmp_path / name))
        return ball(oiio.ImageBuf(str(tmp_path / name)).get_pixels(oiio.UINT8).astype(np.float64))

    root = tmp_path / "shaders"
    shutil.copytree(REPO / "shaders", root)
    window.renderer.use_shaders(ShaderLibrary(window.ctx, root))
    window.shader_watcher = ShaderWatcher(root)
    s = window.state
    s.material = dataclasses.replace(s.material, roughness=0.6)
    before = shot("before.png")
    frag = root / "render" / "pbr.frag"
    text = frag.read_text()
    lines = text.splitlines()
    at = lines.index("layout(location = 0) out vec4 out_radiance;") + 1
    lines.insert(at, "this is not glsl;")
    frag.write_text("\n".join(lines) + "\n")
    window.check_shaders(force=True)
    assert f"render/pbr.frag:{at + 1}" in s.error, s.error
    # A nearly equal material forces a redraw: it is drawn, with the last good program.
    s.material = dataclasses.replace(s.material, roughness=0.601)
    during = shot("during.png")
    assert window.panel.shown_error == s.error
    assert np.abs(during - before).mean() < 2.0 and before.std() > 5.0
    # Saving a fix is picked up and clears the error.
    frag.write_text(text.replace("void main()", "// edited\nvoid main()", 1))
    window.check_shaders(force=True)
    assert s.error == "" and s.message == "shaders reloaded"
    after = shot("after.png")
    assert np.abs(after - before).mean() < 2.0
    window.renderer.use_shaders(ShaderLibrary(window.ctx))   # back to the repository's shaders


def test_session_reopens_and_screenshot_button(window, tmp_path, monkeypatch):
    import dataclasses

    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import restore_session, save_session
    from alight.frontends.editor.state import EditorState

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path / "config"))
    s = window.state
    s.load_mesh("cube")
    s.material = dataclasses.replace(s.material, roughness=0.42, name="session")
    window.orbit.orbit(40.0, -25.0)
    save_session(s, window.orbit)
    fresh, orbit = EditorState(), OrbitCamera()
    assert restore_session(fresh, orbit) == ""
    assert fresh.material == s.material and fresh.mesh_spec == "cube" and fresh.env_spec == s.env_spec
    assert (orbit.yaw_deg, orbit.pitch_deg, orbit.distance) == (window.orbit.yaw_deg, window.orbit.pitch_deg,
                                                                window.orbit.distance)
    # What the panel's screenshot button (and F12) asks for is written after the frame.
    out = tmp_path / "button.png"
    window.screenshot_request = str(out)
    window.frame()
    assert out.is_file() and s.message.startswith(f"wrote {out.name} (") and str(out.resolve().parent) in s.message, \
        s.message


def test_view_is_redrawn_only_when_needed_and_reduced_while_moving(window):
    s = window.state
    s.motion_scale = 0.5
    window.frame()
    window.frame()
    still = window.redraws
    window.frame()
    assert window.redraws == still                      # nothing changed: no scene redraw
    window.orbit.orbit(10.0, 0.0)
    window.frame()
    assert window.redraws == still + 1
    assert window._drawn_targets.width == round(window.view_area()[0] * 0.5)   # drawn reduced while moving
    window.frame()                                      # the camera stopped: redrawn sharp
    assert window.redraws == still + 2 and window._drawn_targets.width == window.view_area()[0]
    s.motion_scale = 1.0


def test_texture_maps_drop_undo_and_session(window, tmp_path, monkeypatch):
    """A dropped image fills the armed slot (base colour by default) and the view changes; a bad
    image shows its one-line error and keeps the maps; undo/redo and the session keep slots."""
    import dataclasses

    import OpenImageIO as oiio

    from alight.core.texture_maps import TextureMaps
    from alight.exchange.output import write_image
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import restore_session, save_session
    from alight.frontends.editor.state import EditorState

    def shot(name):
        window.frame()
        window.screenshot(str(tmp_path / name))
        return ball(oiio.ImageBuf(str(tmp_path / name)).get_pixels(oiio.UINT8).astype(np.float64))

    s, h = window.state, window.history
    s.load_mesh("sphere")
    s.material = dataclasses.replace(s.material, base_color=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.6)
    s.texture_maps = TextureMaps()
    i, j = np.indices((128, 128)) // 16
    grey = np.where((i + j) % 2 == 0, 20, 235).astype(np.uint8)
    checker = tmp_path / "checker.png"
    write_image(str(checker), np.repeat(grey[:, :, None], 3, axis=2), linear=False)
    plain = shot("plain.png")
    window.frame()                                   # settled: the plain look is an undo step
    assert s.armed_slot == "base_color"
    window.drop([str(checker)])
    assert s.error == "" and s.texture_maps.base_color == str(checker)
    mapped = shot("mapped.png")
    assert mapped.std() > 1.5 * plain.std()

    broken = tmp_path / "broken.png"
    broken.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4)
    before = s.texture_maps
    window.drop([str(broken)])
    window.frame()
    assert s.texture_maps == before and "broken.png" in s.error and "\n" not in s.error
    assert window.panel.shown_error == s.error

    s.look = h.undo(s.look)                          # the drop is one undo step
    assert s.texture_maps.base_color == ""
    assert np.abs(shot("undone.png") - plain).max() <= 1.0
    s.look = h.redo(s.look)
    assert s.texture_maps.base_color == str(checker)

    monkeypatch.setenv("ALIGHT_CONFIG_DIR", str(tmp_path / "config"))
    s.texture_maps = dataclasses.replace(s.texture_maps, uv_scale=(3.0, 2.0))
    save_session(s, window.orbit)
    fresh = EditorState()
    assert restore_session(fresh, OrbitCamera()) == ""
    assert fresh.texture_maps == s.texture_maps and str(checker) in fresh.map_images
    checker.unlink()                                 # moved since: restored without it, with a warning
    fresh = EditorState()
    assert "checker.png" in restore_session(fresh, OrbitCamera())
    assert fresh.texture_maps.base_color == "" and fresh.texture_maps.uv_scale == (3.0, 2.0)
    s.texture_maps = TextureMaps()


def test_bake_runs_across_frames_with_the_old_maps_in_use(window, shared_data):
    s = window.state
    s.error = ""
    window.finish_bake()
    old = window.maps()
    assert old is not None
    s.load_env(str(shared_data / "env" / "quarry_01_1k.hdr"))
    s.quality = "low"
    window.frame()
    seen = []
    while window.bake_progress is not None:          # one slice per frame; the panel shows it
        seen.append(window.bake_progress)
        assert window.maps() is old                  # the old maps light the view until the end
        window.frame()
    assert len(seen) >= 2 and seen[-1][0] > seen[0][0]
    new = window.maps()
    assert new is not old and new.quality.name == "low"
    assert s.error == ""


def test_adaptive_scale_follows_the_frame_time(window):
    """Slow moving frames lower the adaptive scale a step at a time down to its floor, fast ones
    raise it to 1; the still view is drawn at full size whatever the scale."""
    from alight.frontends.editor.window import ADAPTIVE_MIN_SCALE, ADAPTIVE_STEP

    import time

    s = window.state
    s.adaptive_motion = True
    window.adaptive_scale = 1.0
    window.frame_times.clear()
    window.frame_times.extend([0.5, 0.5, 0.5])          # 2 FPS frames
    window.adapt_motion_scale()
    assert window.adaptive_scale == 1.0 - ADAPTIVE_STEP  # one step per frame, not a jump
    for _ in range(40):
        window.frame_times.append(0.5)
        window.adapt_motion_scale()
    assert window.adaptive_scale == ADAPTIVE_MIN_SCALE
    for _ in range(40):
        window.frame_times.append(0.001)                 # far faster than the target
        window.adapt_motion_scale()
    assert window.adaptive_scale == 1.0
    window.frame_times.extend([1.0 / 30.0] * 3)          # on target: stays
    window.adapt_motion_scale()
    assert window.adaptive_scale == 1.0
    # The check before this one switched to quarry_01, which has a sun: its variants (the suns'
    # loop compiled in, common/suns.glsl IBL_SUNS) are the warm-up process's to compile first, the
    # view keeping the last picture meanwhile (variant_warmup.py). Moving frames until it is done.
    deadline = time.monotonic() + 120.0
    while time.monotonic() < deadline:
        window.adaptive_scale = 0.5
        for turn in (5.0, -5.0):
            window.orbit.orbit(turn, 0.0)
            window.frame()
        warm = window.variant_warmup
        if window._drawn_targets is not None and not (warm.pending or warm.showing_old):
            break
        time.sleep(0.05)
    window.adaptive_scale = 0.5
    window.orbit.orbit(5.0, 0.0)
    window.frame()
    window.orbit.orbit(5.0, 0.0)
    window.frame()                                       # moving: drawn reduced
    assert window._drawn_targets.width < window.view_area()[0]
    window.frame()                                       # still: full size
    assert window._drawn_targets.width == window.view_area()[0]
    s.adaptive_motion = False


def _warm_orbit(window) -> None:
    """Orbit to and fro (the camera ends where it was) until the warm-up process compiled the
    window-drawn variant of an orbit (variant_warmup.py, since the first orbit of a material no
    longer compiles in the frame): the view image is drawn meanwhile, not the window."""
    import time

    deadline = time.monotonic() + 120.0
    while True:
        for turn in (1.0, -1.0):
            window.orbit.orbit(turn, 0.0)
            window.frame()
        warm = window.variant_warmup
        # Done when the last orbit frame went straight into the window (it keeps no view key).
        if (not (warm.pending or warm.showing_old) and window._drawn_key is None) or time.monotonic() > deadline:
            break
        time.sleep(0.05)
    window.frame()


def test_orbiting_frame_in_the_window_matches_the_still_view(window):
    """While the camera moves, a full-size frame is drawn straight into the window and the
    window's write stage applies the sRGB curve (ForwardRenderer.draw_display into_encodes_srgb);
    the still frame is drawn into the view image by the shaders' exact curve and copied. The two
    pictures of one camera differ by at most 1 LSB (llvmpipe's encoder is a polynomial), and not
    on most values."""
    s = window.state
    s.motion_scale, s.adaptive_motion = 1.0, False
    window.finish_bake()   # (run alone, the studio's bake is still being sliced over frames)
    into, encodes_srgb = window.direct_target()
    assert into is not None and encodes_srgb, "Xvfb's llvmpipe window should have depth and sRGB: the path is untested"
    w, h = window.view_area()

    def view_pixels() -> np.ndarray:
        return np.frombuffer(window.ctx.screen.read(viewport=(0, 0, w, h), components=3), np.uint8)\
            .reshape(h, w, 3).astype(int)

    window.frame()
    _warm_orbit(window)
    window.orbit.orbit(7.0, 3.0)
    drawn = window.redraws
    window.draw()                                       # moving: into the window, sRGB by the window
    assert window.redraws == drawn + 1 and window._drawn_key is None   # drawn direct, not kept
    moving = view_pixels()
    window.glfw.swap_buffers(window.window)
    window.draw()                                       # still: the view image, copied
    still = view_pixels()
    window.glfw.swap_buffers(window.window)
    difference = np.abs(moving - still)
    assert difference.max() <= 1, difference.max()
    assert (difference > 0).mean() < 0.35, (difference > 0).mean()
    assert 20.0 < still.mean() < 235.0                  # a picture, not a cleared window
    # Off (a window without sRGB), the shaders encode: the same bytes as the still view.
    window._screen_srgb = False
    try:
        window.orbit.orbit(-7.0, -3.0)
        window.draw()
        window.glfw.swap_buffers(window.window)
        _warm_orbit(window)   # the shader-encoding variant is another warm-up
        window.orbit.orbit(7.0, 3.0)
        window.draw()
        assert np.abs(view_pixels() - still).max() <= 1
        window.glfw.swap_buffers(window.window)
    finally:
        window._screen_srgb = True
        window.frame()


def _drawn_with(window, **attributes) -> np.ndarray:
    """The whole window's pixels (rows bottom-up) after a draw with the window's ``attributes``
    set for it, then restored."""
    saved = {k: getattr(window, k) for k in attributes}
    for k, v in attributes.items():
        setattr(window, k, v)
    try:
        window.draw()
        w, h = window.size
        return np.frombuffer(window.ctx.screen.read(components=3), np.uint8).reshape(h, w, 3).copy()
    finally:
        for k, v in saved.items():
            setattr(window, k, v)


def test_native_imgui_renderer_draws_what_the_python_one_draws(window):
    """The panel is drawn by Dear ImGui's C++ OpenGL 3 renderer (imgui-bundle's), where it starts;
    imgui-bundle's Python renderer, the fallback, draws the same window bytes from the same
    draw data."""
    assert window._native_imgui, "the C++ renderer should start on llvmpipe's GL"
    w = window.size[0]
    window.frame()
    native = _drawn_with(window)
    python = _drawn_with(window, _native_imgui=False)
    window.glfw.swap_buffers(window.window)
    panel = slice(w - round(window.panel_width() * w / window.glfw.get_window_size(window.window)[0]), w)
    assert native[:, panel].std() > 5.0                 # the panel is there
    np.testing.assert_array_equal(native, python)


def test_kept_panel_pixels_are_the_panel_drawn_anew(window):
    """While the panel's draw data stays the same its pixels are copied from an offscreen image
    (panel_image.PanelImage); the window is then byte for byte the window drawn with imgui's
    renderer. A window over the view (here a small imgui window; a tooltip or an open combo box)
    is drawn straight in."""
    kept = window._panel_image
    window.finish_bake()
    # A thumbnail that arrives changes the panel's draw data between the frames compared: let
    # them all arrive first (they render in a child process, seconds under load).
    window.frame()
    window.wait_for_thumbnails(120.0)
    assert not window.thumbnails.pending(), f"{window.thumbnails.pending()} thumbnails still pending after 120 s"
    for _ in range(20):     # (the first frames rasterise glyphs into imgui's atlas: texture updates)
        window.frame()
        if kept.reused:
            break
    assert kept.reused > 0
    # The panel's text can still change between two frames (its frame-time readout): a pair
    # whose draw data changed in between is drawn again, up to 5 times; a copy that differs from
    # the panel drawn anew fails every time.
    for _ in range(5):
        reused = kept.reused
        copied = _drawn_with(window)
        copied_again = kept.reused == reused + 1           # the same draw data: copied
        drawn = _drawn_with(window, keep_panel_pixels=False)
        window.glfw.swap_buffers(window.window)
        if copied_again and np.array_equal(copied, drawn):
            break
    assert copied_again
    np.testing.assert_array_equal(copied, drawn)
    assert copied[:, window.view_area()[0]:].std() > 5.0

    imgui = window.imgui
    for _ in range(3):                                  # an imgui window over the view, every frame
        window.poll_events()
        window.begin_imgui_frame()
        window.panel.draw(window)
        imgui.set_next_window_pos(imgui.ImVec2(4, 4))
        imgui.begin("over the view")
        imgui.text("x")
        imgui.end()
        imgui.render()
        window.render_view()
        reused = kept.reused
        window.render_imgui()
        window.glfw.swap_buffers(window.window)
    # (imgui shows a new window from its second frame on)
    assert kept.reused == reused and kept._key is None  # drawn straight in


def test_a_flat_mesh_seen_edge_on_is_said(window, shared_data):
    """Framed from the default direction (+Z), a y = 0 plane is edge-on and shows nothing: the
    panel says so, as 'alight render' warns (from whatever direction the view has when a mesh
    arrives); the ball says nothing."""
    s = window.state
    window.orbit.yaw_deg = window.orbit.pitch_deg = 0.0    # the default direction (earlier checks orbit)
    try:
        assert s.open_file(str(shared_data / "bad" / "singlevn.obj"))
        window.frame()
        while window.panel.file_jobs.busy:   # (a mesh file is read on the panel's worker thread)
            window.frame()
        window.frame()
        assert "edge-on" in s.message, (s.message, s.error)
    finally:
        s.load_mesh("sphere")
        s.message = ""
    window.frame()
    assert "edge-on" not in s.message


def test_built_in_file_browser(window, tmp_path):
    """Where no native dialog exists the panel's browser is an imgui window: it lists folders
    and the files of the asked types, and a pick goes to the caller (here: the texture slot)."""
    from alight.exchange.output import write_image
    from alight.frontends.editor.file_browser import FileBrowser

    (tmp_path / "sub").mkdir()
    (tmp_path / ".hidden.png").write_bytes(b"x")
    (tmp_path / "notes.txt").write_text("x")
    image = tmp_path / "grey.png"
    write_image(str(image), np.full((8, 8, 3), 128, np.uint8), linear=False)
    browser = window.panel.browser = FileBrowser(native=False)
    picked = []
    browser.open("load base colour map", (".png",), picked.append, start=str(image))
    assert browser.visible and browser.directory == tmp_path.resolve()
    assert browser.entries() == (["sub"], ["grey.png"])
    window.frame()                                   # drawn as an imgui window, the editor runs on
    window.frame()
    assert browser.visible and not picked
    browser.pick(str(image))
    assert picked == [str(image)] and not browser.busy
    # The panel's own use: a pick fills the slot it was opened for.
    s = window.state
    browser.open("load roughness map", (".png",), lambda p: s.set_map("roughness", p))
    browser.pick(str(image))
    assert s.texture_maps.roughness == str(image)
    s.clear_map("roughness")
    window.frame()


def test_quality_auto_bakes_the_choice_and_says_why(window):
    """Bake quality 'auto': the window bakes what app/accuracy/auto_quality.py chose for the material's
    kind and roughness band, and the panel's line (the same Choice) names it with its predicted
    error. A rough gold gets a cheap bake within the budget; a nearly mirror gold, which no
    measured bake brings within 2% on a sharp map, keeps medium and says so."""
    s = window.state
    s.error = ""
    s.load_env("studio")
    s.quality = "auto"
    s.material = s.material.__class__(**{**s.material.__dict__, "base_color": (1.0, 0.71, 0.29),
                                         "metallic": 1.0, "roughness": 0.7})
    window.frame()
    window.finish_bake()
    rough = window.auto_choice()
    assert rough.meets_budget and "within the 2% budget" in rough.line(0.02)
    assert window.maps().quality is rough.quality and rough.name != "medium"
    s.material = s.material.__class__(**{**s.material.__dict__, "roughness": 0.1})
    window.frame()
    window.finish_bake()
    smooth = window.auto_choice()
    assert smooth.name == "medium" and "so the default, medium" in smooth.line(0.02)
    assert window.maps().quality.name == "auto:medium"
    s.material = s.material.__class__(**{**s.material.__dict__, "roughness": 0.15})
    window.frame()
    assert window.auto_choice() is smooth and window.bake_progress is None   # same band: no new bake
    s.quality = "medium"
    assert s.error == ""
