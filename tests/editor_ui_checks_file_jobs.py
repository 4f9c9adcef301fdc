"""Checks for `alight edit --ui-test` (run by tests/test_editor_ui_file_jobs.py, window 1280x720):
'open mesh' and 'export glTF' run on the panel's worker thread (app/frontends/editor/file_jobs.py),
so frames keep coming while a big mesh is read or DamagedHelmet written, the view orbits meanwhile, a second
open wins over the first, a second export is refused while one writes, and a bad file leaves the
previous mesh; a bad path typed into 'map file' stays in the field. Each clicks and types as a
user does. Frames are counted, never timed."""

from __future__ import annotations

import os

from alight.frontends.editor.ui_test import editor, files_done

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")
SHARED = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "..", "shared", "data")
HELMET = os.path.abspath(os.path.join(SHARED, "models", "DamagedHelmet", "DamagedHelmet.gltf"))


def type_path(ctx, ref: str, text: str) -> None:
    ctx.item_click(ref)
    ctx.key_chars_replace(text)


def test_frames_keep_coming_and_the_view_orbits_while_a_big_mesh_opens(ctx):
    """A file that takes seconds to read (an 82k-triangle OBJ, 1.9 s here; DamagedHelmet reads in
    0.5 s, less than one frame of this window under load, and then no frame could fall inside
    the read whatever the thread did)."""
    import trimesh
    from imgui_bundle import imgui

    win = editor()
    s = win.state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    big = os.path.join(OUT, "slow_to_read.obj")
    trimesh.creation.icosphere(subdivisions=6).export(big)
    type_path(ctx, "**/mesh", big)
    jobs = win.panel.file_jobs
    yaw, before = win.orbit.yaw_deg, jobs.frames_while_running
    win.panel.shown_job_status = ""
    ctx.item_click("**/open mesh")
    # The view orbits while the file is read (the mouse is over the view, left of the panel).
    w, h = imgui.get_io().display_size.x, imgui.get_io().display_size.y
    ctx.mouse_move_to_pos(imgui.ImVec2(w * 0.2, h * 0.5))
    ctx.mouse_drag_with_delta(imgui.ImVec2(60, 0))
    orbited_busy = win.panel.file_jobs.busy
    assert win.orbit.yaw_deg != yaw, "a left drag in the view did not orbit while the mesh opened"
    files_done(ctx)
    frames = jobs.frames_while_running - before
    assert win.panel.shown_job_status == "opening slow_to_read.obj...", win.panel.shown_job_status
    assert s.mesh_spec == big and not s.error, (s.mesh_spec, s.error)
    assert win.panel.shown_status.startswith(f"opened mesh {big}"), win.panel.shown_status
    # Frames drawn while the file was read (0 when it was read in the click's frame): the
    # status row's and the drag's at least.
    assert frames >= 3, frames
    print(f"frames while the big mesh opened: {frames}; the orbit's drag ended with the open "
          f"{'still running' if orbited_busy else 'done'}")


# The longest frame allowed while DamagedHelmet opens (issue 21). The frame that took the mesh
# used to make its five 2048² textures' mip levels and its self-shadowing test on the GL thread:
# 0.8-1.2 s on a quiet machine, 2.4-3.8 s beside other work. Now the worker thread does that CPU work
# and frames write a few MiB of levels each: about 150 ms the longest here, quiet (the first
# draw of the helmet, as long as any frame that draws it with shadows), 300-500 ms under load.
MAX_FRAME_WHILE_OPENING_S = 0.6


def test_frames_stay_short_while_a_textured_gltf_opens(ctx):
    """DamagedHelmet by 'open mesh': no frame over MAX_FRAME_WHILE_OPENING_S from the one that
    takes the read to the frame after the helmet is drawn, and no texture uploaded whole (GL's
    mipmaps) nor the self-shadowing test run on the GL thread meanwhile (counted, whatever the
    machine's load)."""
    import collections
    import threading

    import alight.render.gpu_mesh as gpu_mesh
    import alight.render.shadows as shadows

    win = editor()
    s = win.state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    s.shadows = "auto"
    on_gl_thread = []

    def counted(name, function):
        def call(*args, **kwargs):
            if threading.current_thread() is threading.main_thread():
                on_gl_thread.append(name)
            return function(*args, **kwargs)
        return call

    saved = gpu_mesh.upload_image, shadows.can_shadow_itself, gpu_mesh.upload_normal_map
    gpu_mesh.upload_image = counted("upload_image", saved[0])
    shadows.can_shadow_itself = counted("can_shadow_itself", saved[1])
    gpu_mesh.upload_normal_map = counted("upload_normal_map", saved[2])   # (a normal map's whole upload)
    try:
        type_path(ctx, "**/mesh", HELMET)
        kept, win.frame_times = win.frame_times, collections.deque()   # (unbounded: every frame of the open)
        ctx.item_click("**/open mesh")
        jobs, read_end = win.panel.file_jobs, None
        ctx.yield_()
        while jobs.busy:
            if read_end is None and getattr(jobs, "staged", None) is not None:
                read_end = len(win.frame_times)   # the frame that took the read was the last one
            ctx.yield_()
        if read_end is None:   # (a tree without the staged upload: the frame that took it was the last)
            read_end = len(win.frame_times)
        ctx.yield_(3)   # the helmet drawn
        gaps = list(win.frame_times)
    finally:
        gpu_mesh.upload_image, shadows.can_shadow_itself, gpu_mesh.upload_normal_map = saved
        win.frame_times = collections.deque(kept + win.frame_times, maxlen=kept.maxlen)
    assert s.mesh_spec == HELMET and not s.error, (s.mesh_spec, s.error)
    reading, taking = gaps[:read_end - 1], gaps[read_end - 1:]
    print(f"frames while DamagedHelmet opened: {len(gaps)}; the longest while it was read "
          f"{1000 * max(reading, default=0):.0f} ms, from the frame that took it to the helmet drawn "
          f"{1000 * max(taking):.0f} ms ({len(taking)} frames)")
    # The frames from the one that took the read to the helmet drawn: what issue 21 moved off
    # the GL thread. (The read's own frames share the cores and the GIL with the worker: under
    # a load of 6-8 on 2 cores one of them took 0.8-1.9 s now and then, before this change too.)
    assert max(taking) < MAX_FRAME_WHILE_OPENING_S, [round(1000 * g) for g in taking]
    assert not on_gl_thread, f"on the GL thread while the helmet opened: {on_gl_thread}"
    ctx.combo_click("preview mesh/sphere")
    ctx.item_close("**/Environment")


def test_a_second_open_while_one_runs_wins(ctx):
    import trimesh

    win = editor()
    s = win.state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.combo_click("preview mesh/sphere")
    big = os.path.join(OUT, "big_sphere.obj")   # seconds to read: still read when 'cube' is asked for
    trimesh.creation.icosphere(subdivisions=6).export(big)
    type_path(ctx, "**/mesh", big)
    jobs = win.panel.file_jobs
    ctx.item_click("**/open mesh")
    ctx.yield_()
    assert "opening big_sphere.obj" in jobs.status(), jobs.status()
    ctx.item_input_value("**/mesh", "cube")   # Enter opens it: the latest asked for
    assert jobs.threads == 2 or "opening big_sphere.obj" not in jobs.status(), (jobs.threads, jobs.status())
    files_done(ctx)
    assert s.mesh_spec == "cube", s.mesh_spec
    while jobs.threads:   # the big file's read, superseded, ends unseen
        ctx.yield_()
    ctx.yield_(3)
    assert s.mesh_spec == "cube" and not s.error, (s.mesh_spec, s.error)
    assert win.panel.mesh_path == "cube", win.panel.mesh_path


def test_a_bad_mesh_file_keeps_the_previous_mesh(ctx):
    win = editor()
    s = win.state
    bad = os.path.join(OUT, "broken.obj")
    with open(bad, "w") as f:
        f.write("v 0 0\nf 1 2 9\n")
    ctx.set_ref("alight")
    mesh = s.mesh
    type_path(ctx, "**/mesh", bad)
    ctx.item_click("**/open mesh")
    files_done(ctx)
    assert s.error and bad in s.error and "\n" not in s.error, s.error
    assert s.mesh is mesh and s.mesh_spec == "cube", s.mesh_spec
    assert win.panel.shown_status.startswith("error: "), win.panel.shown_status
    ctx.combo_click("preview mesh/sphere")
    ctx.item_close("**/Environment")


def test_export_runs_off_the_frame_and_a_second_one_is_refused(ctx):
    from alight.exchange.gltf_material import read_gltf_json

    win = editor()
    s = win.state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.item_input_value("**/mesh", HELMET)
    files_done(ctx)
    assert s.mesh_spec == HELMET, (s.mesh_spec, s.error)
    ctx.item_close("**/Environment")
    path = os.path.join(OUT, "helmet_export.glb")
    ctx.item_input_value("**/glTF file", path)
    jobs = win.panel.file_jobs
    before = jobs.frames_while_running
    win.panel.shown_job_status = ""
    ctx.item_click("**/export glTF")
    ctx.mouse_click()   # again at once, while the first writes
    assert "still being written" in s.error, (s.error, s.message)
    files_done(ctx)
    assert win.panel.shown_job_status == "exporting helmet_export.glb...", win.panel.shown_job_status
    assert jobs.frames_while_running - before >= 2, jobs.frames_while_running - before
    assert not s.error and s.message.startswith(f"exported {path}"), (s.error, s.message)
    assert read_gltf_json(path)["meshes"], "no mesh in the export"
    assert not [n for n in os.listdir(OUT) if ".tmp" in n or n.startswith("tmp")], os.listdir(OUT)
    ctx.item_open("**/Environment")
    ctx.combo_click("preview mesh/sphere")
    ctx.item_close("**/Environment")


def test_a_bad_map_path_stays_typed_in_its_field(ctx):
    """A typo in 'map file' + Enter: the one-line error, the field still shows what was typed
    (to be fixed, not typed again), and the material keeps its last good map."""
    import numpy as np
    from PIL import Image

    win = editor()
    s, panel = win.state, win.panel
    good = os.path.join(OUT, "good_BaseColor.png")
    Image.fromarray(np.full((8, 8, 3), (200, 150, 40), np.uint8)).save(good)
    ctx.set_ref("alight")
    ctx.item_input_value("**/map file", good)
    ctx.yield_(2)
    assert s.texture_maps.base_color == good and not s.error, (s.texture_maps, s.error)
    typo = good.replace("good_", "goood_")
    ctx.item_input_value("**/map file", typo)
    ctx.yield_(2)
    assert typo in s.error, s.error
    assert panel.map_path == typo, f"the map field shows {panel.map_path!r}, not what was typed"
    assert s.texture_maps.base_color == good, s.texture_maps
    ctx.item_input_value("**/map file", good)   # the typo fixed
    ctx.yield_(2)
    assert not s.error and panel.map_path == good, (s.error, panel.map_path)


def test_closing_while_an_export_writes_finishes_it(ctx):
    """The last check: 'export glTF' clicked and the editor closed at once (the runner closes the
    window after this check). The export's thread was a daemon, stopped at exit with its
    temporary file left and no export; the window's close now finishes it first (the runner's
    side reads the file and stderr)."""
    win = editor()
    s = win.state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.item_input_value("**/mesh", HELMET)
    files_done(ctx)
    assert s.mesh_spec == HELMET, (s.mesh_spec, s.error)
    ctx.item_close("**/Environment")
    path = os.path.join(OUT, "closing_export.glb")
    ctx.item_input_value("**/glTF file", path)
    ctx.item_click("**/export glTF")
