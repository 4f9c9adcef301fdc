"""The two ways a mesh file reached the editor on its UI thread, now through the panel's worker
(file_jobs.py) and the staged upload: run by tests/test_editor_ui_file_jobs.py in a fresh
interpreter (``python tests/editor_window_mesh_loads.py restore|script``) with DISPLAY set; exits
0 with an 'ok' line, 1 with a line saying what happened.

- ``restore``: `alight edit` reopening the last session, whose mesh is DamagedHelmet (run.py's
  start, the editor's own loop): the window drew nothing until the helmet was read, decoded and
  its textures' levels made (seconds). Now the frames come from the start, the helmet appears
  whole, with the session's camera and 'mesh file's own materials' box.
- ``script``: ``--script mesh=HELMET --script roughness=0.4 --screenshot``: the script's next edit
  and the screenshot still see the helmet (the script waits for it, as for ``open=``).
- ``close``: the window closed before the restored helmet came: the session saved keeps the
  helmet's own-materials box, not the placeholder's.

Both count what ran on the main thread: no read of the helmet, no texture uploaded whole and no
self-shadowing test there (whatever the machine's load); and the longest gap between frames is
bounded in the main thread's CPU time (MAX_CPU_GAP_S: what the UI thread itself did between two
frames, which another process's load does not stretch) and loosely in wall time (MAX_GAP_S),
the latter only where the machine is not overloaded (see ``gap_failure``)."""

from __future__ import annotations

import json
import os
import sys
import tempfile
import threading
import time

SHARED = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "..", "shared", "data")
HELMET = os.path.abspath(os.path.join(SHARED, "models", "DamagedHelmet", "DamagedHelmet.gltf"))
# The longest time between two frames' ends while the helmet comes. On the UI thread its read,
# decoding and mip levels took 2.5-6 s here; through the worker the frames that draw the new mesh
# take up to 0.3-0.6 s under load, and one sharing the cores with the read now and then more.
MAX_GAP_S = 2.0
# The main thread's CPU time between two frames' ends: the read, decoding and levels it did
# before were 2.5-6 s of it; a frame drawing the new mesh, its upload steps included, 0.1-0.4 s.
MAX_CPU_GAP_S = 1.0


def counters():
    """Wrap what must not run on the main thread while the helmet comes: {name: calls there}."""
    import alight.exchange.meshes as meshes
    import alight.frontends.editor.state as editor_state
    import alight.render.gpu_mesh as gpu_mesh
    import alight.render.shadows as shadows

    seen: dict = {}

    def counted(module, name, which=lambda args: True):
        function = getattr(module, name)

        def call(*args, **kwargs):
            if threading.current_thread() is threading.main_thread() and which(args):
                seen[name] = seen.get(name, 0) + 1
            return function(*args, **kwargs)
        setattr(module, name, call)

    def helmet(args):
        return bool(args) and "DamagedHelmet" in str(args[0])

    counted(meshes, "load_mesh", helmet)
    counted(editor_state, "read_mesh", helmet)
    counted(gpu_mesh, "upload_image")
    counted(gpu_mesh, "upload_normal_map")   # (a normal map's whole upload in the frame, its spread included)
    # The self-shadowing test: its arrays noted (the built-in sphere shown first is tested on the
    # main thread, rightly); ``helmet_tested_here`` looks for the helmet's among them.
    seen["_tested"] = tested = []
    test = shadows.can_shadow_itself

    def noted(parts, *args, **kwargs):
        if threading.current_thread() is threading.main_thread():
            tested.extend(id(positions) for positions, _ in parts)
        return test(parts, *args, **kwargs)
    shadows.can_shadow_itself = noted
    return seen


def on_main_thread(seen: dict, mesh) -> dict:
    """What ran on the main thread for the helmet (``mesh``, the state's once it arrived)."""
    found = {k: v for k, v in seen.items() if not k.startswith("_")}
    if any(id(part.positions) in seen["_tested"] for part in mesh.parts):
        found["can_shadow_itself"] = 1
    return found


def timed_frames():
    """Each EditorWindow.frame's end, in order: (time.monotonic, the main thread's
    time.thread_time)."""
    from alight.frontends.editor.window import EditorWindow

    ends: list = []
    frame = EditorWindow.frame

    def timed(self, *args, **kwargs):
        result = frame(self, *args, **kwargs)
        ends.append(mark())
        return result
    EditorWindow.frame = timed
    return ends


def mark() -> tuple[float, float]:
    return time.monotonic(), time.thread_time()


def gap_failure(ends: list, what: str) -> tuple[str | None, str]:
    """(a line saying which bound the gaps between frames broke, or None; the gaps for the ok
    line). The CPU bound always holds; the wall bound only where the 1-minute load is at most
    twice the cores: at load 9-13 on this 2-core machine (other sessions' renders) frames that
    took 0.3-0.6 s came 2-3 s apart on old and new code alike, with the main thread idle."""
    wall = [b[0] - a[0] for a, b in zip(ends, ends[1:])]
    cpu = [b[1] - a[1] for a, b in zip(ends, ends[1:])]
    load, cores = os.getloadavg()[0], os.cpu_count() or 1
    said = f"the longest gaps {longest(wall)}; in main-thread CPU {longest(cpu)}; load {load:.1f}"
    if max(cpu) > MAX_CPU_GAP_S:
        return (f"the main thread ran {max(cpu):.2f} s of CPU between two frames while {what} "
                f"(bound {MAX_CPU_GAP_S} s): {longest(cpu)}"), said
    if max(wall) > MAX_GAP_S:
        if load <= 2 * cores:
            return (f"a frame came {max(wall):.2f} s after the one before while {what} "
                    f"(bound {MAX_GAP_S} s, load {load:.1f}): {longest(wall)}"), said
        said += f" (the wall bound {MAX_GAP_S} s not checked above load {2 * cores})"
    return None, said


def longest(gaps: list) -> str:
    """The three longest gaps, with their places: '1.20 s (frame 0), ...'."""
    top = sorted(range(len(gaps)), key=lambda i: -gaps[i])[:3]
    return ", ".join(f"{gaps[i]:.2f} s (frame {i})" for i in top)


def restore() -> int:
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import save_session
    from alight.frontends.editor.state import EditorState

    # The last session: the helmet (by its path, not read here), its own materials unticked, a
    # camera of its own.
    last = EditorState()
    last.load_env("studio")
    last.mesh_spec, last.use_file_materials = HELMET, False
    camera = OrbitCamera()
    camera.yaw_deg, camera.pitch_deg, camera.distance = 61.0, 17.0, 4.25
    save_session(last, camera)

    from alight.frontends.cli import build_parser
    from alight.frontends.editor.run import build_state, open_last_session
    from alight.frontends.editor.window import EditorWindow

    seen, ends = counters(), timed_frames()
    args = build_parser().parse_args(["edit", "--size", "640x400"])
    state = build_state(args)
    win = EditorWindow(state, args.size)
    try:
        ends.append(mark())   # the gap to the first frame holds the session's restore
        open_last_session(win, state)   # as `alight edit` starts (run.py)
        deadline = time.monotonic() + 600
        while state.mesh_spec != HELMET or win.panel.file_jobs.busy:
            if state.error or time.monotonic() > deadline:
                print(f"the restored helmet did not arrive: mesh {state.mesh_spec}, error {state.error!r}")
                return 1
            win.frame()
        for _ in range(3):   # the helmet drawn
            win.frame()
        failed, gaps = gap_failure(sorted(ends), "the restored helmet came")
        own, yaw, distance = state.use_file_materials, win.orbit.yaw_deg, win.orbit.distance
        here = on_main_thread(seen, state.mesh)
    finally:
        win.close()
    if here:
        print(f"on the main thread while the restored helmet came: {here}")
        return 1
    if failed:
        print(failed)
        return 1
    if own or (yaw, distance) != (61.0, 4.25):
        print(f"the session's own-materials box {own} (saved False) or camera yaw {yaw}, distance {distance} "
              f"(saved 61, 4.25) not kept for the restored mesh")
        return 1
    print(f"ok: restored helmet in {len(ends) - 1} frames, {gaps}")
    return 0


def script() -> int:
    from alight.frontends.cli import main as cli_main
    from alight.frontends.editor.state import EditorState

    seen, ends = counters(), timed_frames()
    applied, states = [], []
    apply_edit = EditorState.apply_edit

    def noting(self, edit):   # what the mesh is when each edit comes
        applied.append((edit, self.mesh_spec))
        states.append(self)
        return apply_edit(self, edit)
    EditorState.apply_edit = noting
    shot = os.path.join(tempfile.mkdtemp(prefix="alightmesh"), "helmet.png")
    code = cli_main(["edit", "--new", "--size", "320x240", "--script", f"mesh={HELMET}", "--script", "roughness=0.4",
                     "--screenshot", shot, "--frames", "2"])
    if code != 0 or not os.path.isfile(shot):
        print(f"alight edit --script mesh= exited {code}; screenshot written: {os.path.isfile(shot)}")
        return 1
    here = on_main_thread(seen, states[-1].mesh)
    if here:
        print(f"on the main thread while --script mesh= opened the helmet: {here}")
        return 1
    if applied[-1] != ("roughness=0.4", HELMET):
        print(f"the edit after mesh= did not see the helmet: {applied}")
        return 1
    failed, gaps = gap_failure(ends, "mesh= opened the helmet")
    if failed:
        print(failed)
        return 1
    print(f"ok: --script mesh= in {len(ends)} frames, {gaps}; {json.dumps(applied)}")
    return 0


def close() -> int:
    """The window closed while the last session's helmet is still being read: the session saved
    then keeps the helmet and its own-materials box as saved (ticked), not the box of the
    placeholder on screen meanwhile (the built-in sphere's, unticked)."""
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.session import save_session, session_path
    from alight.frontends.editor.state import EditorState

    last = EditorState()
    last.load_env("studio")
    last.mesh_spec, last.use_file_materials = HELMET, True
    save_session(last, OrbitCamera())

    from alight.frontends.cli import build_parser
    from alight.frontends.editor.run import build_state, open_last_session
    from alight.frontends.editor.window import EditorWindow

    args = build_parser().parse_args(["edit", "--size", "320x240"])
    state = build_state(args)
    win = EditorWindow(state, args.size)
    try:
        open_last_session(win, state)
        win.frame()
        waiting = win.panel.file_jobs.opening
        shown = (state.mesh_spec, state.use_file_materials)
        # The close as the window manager asks it, and what run.py does after the loop ends.
        win.glfw.set_window_should_close(win.window, True)
        win.run()
        save_session(state, win.orbit, win.turntable, win.panel)
    finally:
        win.close()
    if waiting != HELMET:
        print(f"the helmet was not still being read at the close (opening {waiting!r}): nothing tested")
        return 1
    saved = json.loads(session_path().read_text(encoding="utf-8"))
    got = (saved["mesh"], saved["settings"]["use_file_materials"])
    if got != (HELMET, True):
        print(f"closed while the helmet was read (on screen {shown}): the session saved {got}, not ({HELMET!r}, True)")
        return 1
    print(f"ok: closed while the helmet was read (on screen {shown}); saved {got}")
    return 0


if __name__ == "__main__":
    sys.exit({"restore": restore, "script": script, "close": close}[sys.argv[1]]())
