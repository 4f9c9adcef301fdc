"""Files dropped on `alight edit`'s window through the X drag-and-drop protocol, as a file manager
drops them (issue 22): not through the window's drop function.

``python tests/editor_x_drop.py source WINDOW X Y FILE...`` is a small XDND source
(freedesktop.org's XDND, version 5, over python-xlib): it owns the XdndSelection, sends the
target XdndEnter with ``text/uri-list``, XdndPosition at the window's (X, Y), waits for its
XdndStatus, sends XdndDrop, answers the target's SelectionRequest with the files' ``file://``
URIs and waits for XdndFinished. glfw turns that into the window's drop callback. Exit 0 once the
target says it finished and accepted, 1 with one line otherwise.

``python tests/editor_x_drop.py checks`` (DISPLAY set; run by tests/test_editor_ui_drop.py) runs
the editor's own loop and drops, each through a source process while the window draws its
frames: an HDR (the environment changes, in the view's pixels), a mesh file (the mesh is loaded,
the view changes), five texture maps at once (one texture set: each file in its slot, the
slots' rows in the panel name them, the view changes), one image with the roughness slot armed
(that slot alone takes it), a .json preset (the material, its maps cleared) and a folder (its
images one texture set). Prints one line per failure.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from urllib.parse import quote

XDND_VERSION = 5
URI_LIST = "text/uri-list"


def uri_list(paths) -> bytes:
    """text/uri-list (RFC 2483): one file:// URI a line, CRLF-terminated, as file managers send."""
    return "".join(f"file://{quote(os.path.abspath(p))}\r\n" for p in paths).encode()


def xdnd_drop(window_id: int, x: int, y: int, paths, timeout_s: float = 60.0) -> str:
    """Drop ``paths`` on the X window ``window_id`` at its (x, y) as an XDND source; returns ''
    when the target finished and accepted, else what went wrong (one line)."""
    from Xlib import X, display
    from Xlib.protocol import event

    d = display.Display()
    root = d.screen().root
    atom = {name: d.intern_atom(name) for name in
            ("XdndAware", "XdndEnter", "XdndPosition", "XdndStatus", "XdndDrop", "XdndFinished",
             "XdndLeave", "XdndSelection", "XdndActionCopy", URI_LIST)}
    target = d.create_resource_object("window", window_id)
    aware = target.get_full_property(atom["XdndAware"], X.AnyPropertyType)
    if aware is None or not len(aware.value):
        return f"window {window_id:#x} is not XdndAware"
    version = min(XDND_VERSION, int(aware.value[0]))
    source = root.create_window(-10, -10, 1, 1, 0, X.CopyFromParent)
    source.set_selection_owner(atom["XdndSelection"], X.CurrentTime)
    if d.get_selection_owner(atom["XdndSelection"]) != source:
        return "could not own the XdndSelection"
    position = root.translate_coords(target, x, y)   # the point in root coordinates
    data = uri_list(paths)

    def send(kind: str, *longs: int) -> None:
        message = event.ClientMessage(window=target, client_type=atom[kind],
                                      data=(32, [source.id, *longs] + [0] * (4 - len(longs))))
        target.send_event(message, event_mask=0)
        d.flush()

    send("XdndEnter", version << 24, atom[URI_LIST], 0, 0)
    send("XdndPosition", 0, (position.x << 16) | position.y, X.CurrentTime, atom["XdndActionCopy"])
    accepted = dropped = None
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if not d.pending_events():
            time.sleep(0.005)
            continue
        ev = d.next_event()
        if ev.type == X.ClientMessage and ev.client_type == atom["XdndStatus"]:
            accepted = bool(ev.data[1][1] & 1)
            if not accepted:
                send("XdndLeave", 0, 0, 0)
                return "the window refused the drop (XdndStatus without accept)"
            if dropped is None:
                dropped = True
                send("XdndDrop", 0, X.CurrentTime, 0)
        elif ev.type == X.SelectionRequest:
            prop = ev.property or ev.target
            if ev.target == atom[URI_LIST]:
                ev.requestor.change_property(prop, atom[URI_LIST], 8, data)
            else:
                prop = X.NONE
            ev.requestor.send_event(event.SelectionNotify(time=ev.time, requestor=ev.requestor,
                                                          selection=ev.selection, target=ev.target,
                                                          property=prop), event_mask=0)
            d.flush()
        elif ev.type == X.ClientMessage and ev.client_type == atom["XdndFinished"]:
            # XDND 5 says bit 0 of l[1] is success; glfw puts the byte count of the data it read
            # there (0: nothing read), so any non-zero value is a success here.
            return "" if version < 5 or ev.data[1][1] else f"XdndFinished without success ({list(ev.data[1])})"
    return f"no XdndFinished within {timeout_s:g} s (accepted: {accepted})"


# --- the editor's side (run as 'checks') -----------------------------------------------------------

def _write_inputs(folder: str) -> dict:
    """A mesh file and a texture set of five maps in Substance's names."""
    import numpy as np
    import trimesh
    from PIL import Image

    os.makedirs(folder, exist_ok=True)
    mesh = os.path.join(folder, "dropped_box.obj")
    trimesh.creation.box(extents=(1.2, 1.2, 1.2)).export(mesh)
    rng = np.random.default_rng(3)
    grey = lambda v: np.full((16, 16, 3), v, np.uint8)   # noqa: E731
    n = rng.normal(0.0, 0.4, (16, 16, 3))
    n[..., 2] = 1.0
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    maps = {"base_color": ("BaseColor", np.dstack([grey(40)[..., 0], grey(150)[..., 0], grey(220)[..., 0]])),
            "normal": ("Normal", np.round((n * 0.5 + 0.5) * 255).astype(np.uint8)),
            "roughness": ("Roughness", grey(90)), "metallic": ("Metallic", grey(255)),
            "occlusion": ("AO", grey(200))}
    files = {}
    for slot, (suffix, pixels) in maps.items():
        files[slot] = os.path.join(folder, f"tiles_{suffix}.png")
        Image.fromarray(pixels).save(files[slot])
    preset = os.path.join(folder, "copper.json")   # the preset as alight ships it, from elsewhere
    shutil.copyfile(os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "presets", "copper.json"), preset)
    return {"mesh": mesh, "maps": files, "preset": preset}


def _grey_png(path: str, level: int) -> None:
    import numpy as np
    from PIL import Image

    Image.fromarray(np.full((16, 16), level, np.uint8)).save(path)


def _checks(env_file: str) -> int:
    import numpy as np

    from alight.frontends.editor.state import EditorState
    from alight.frontends.editor.window import EditorWindow

    inputs = _write_inputs(os.path.abspath("drop_inputs"))
    state = EditorState()
    state.load_mesh("sphere")
    state.load_env("studio")
    win = EditorWindow(state, (1280, 720))
    for _ in range(3):
        win.frame()
    win.finish_bake()
    window_id = subprocess.run(["xdotool", "search", "--onlyvisible", "--pid", str(os.getpid())], capture_output=True,
                               text=True, check=True).stdout.split()[0]
    w, h = win.view_area()

    def drop(*paths: str) -> str:
        """The files dropped at the view's middle by a source process, while the window draws."""
        proc = subprocess.Popen([sys.executable, __file__, "source", window_id, str(w // 2), str(h // 2), *paths],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        while proc.poll() is None:
            win.frame()
        while win.panel.file_jobs.busy:   # a mesh file is read on the panel's worker thread
            win.frame()
        for _ in range(3):
            win.frame()
        win.finish_bake()
        win.frame()
        return proc.stdout.read().strip() if proc.returncode else ""

    def keep(name: str, pixels) -> None:   # to look at
        from PIL import Image

        Image.fromarray(pixels).save(f"{name}.png")

    def changed(before, after) -> float:
        return float(np.abs(after.astype(np.float64) - before).mean())

    failures = 0

    def fail(line: str) -> None:
        nonlocal failures
        failures += 1
        print(line)

    before = win.view_pixels()
    problem = drop(env_file)
    after = win.view_pixels()
    keep("dropped_hdr", after)
    if problem or state.env_spec != env_file:
        fail(f"hdr: the environment is {state.env_spec!r} ({problem or state.error})")
    elif changed(before, after) < 2.0:
        fail(f"hdr: the view hardly changed ({changed(before, after):.2f} mean levels)")
    else:
        print(f"hdr: {os.path.basename(env_file)} is the environment; the view changed by "
              f"{changed(before, after):.1f} mean levels")
    before = after
    problem = drop(inputs["mesh"])
    after = win.view_pixels()
    keep("dropped_mesh", after)
    if problem or state.mesh_spec != inputs["mesh"]:
        fail(f"mesh: the mesh is {state.mesh_spec!r} ({problem or state.error})")
    elif changed(before, after) < 2.0:
        fail(f"mesh: the view hardly changed ({changed(before, after):.2f} mean levels)")
    else:
        print(f"mesh: {os.path.basename(inputs['mesh'])} is the mesh; the view changed by "
              f"{changed(before, after):.1f} mean levels")
    state.load_mesh("sphere")   # (the scene set up again: the maps on the ball)
    for _ in range(3):
        win.frame()
    before = win.view_pixels()
    problem = drop(*inputs["maps"].values())
    after = win.view_pixels()
    keep("dropped_set", after)
    got = state.texture_maps.paths()
    wrong = {slot: got.get(slot) for slot, path in inputs["maps"].items() if got.get(slot) != path}
    if problem or wrong:
        fail(f"texture set: slots not as dropped: {wrong} ({problem or state.error})")
    elif not state.message.startswith("texture set:"):
        fail(f"texture set: the status row says {state.message!r}")
    elif changed(before, after) < 2.0:
        fail(f"texture set: the view hardly changed ({changed(before, after):.2f} mean levels)")
    else:
        print(f"texture set: {len(got)} maps in their slots ({', '.join(sorted(got))}); the view changed by "
              f"{changed(before, after):.1f} mean levels")
    # One image with a slot armed (the radio button is operated in editor_ui_checks.py; here the
    # drop is the control under test): it fills that slot and no other.
    before = after
    rough = os.path.join(os.path.dirname(inputs["mesh"]), "smooth_patch.png")
    _grey_png(rough, 10)
    state.armed_slot = "roughness"
    problem = drop(rough)
    after = win.view_pixels()
    keep("dropped_image", after)
    got_now = state.texture_maps.paths()
    if problem or got_now.get("roughness") != rough or got_now.get("base_color") != got.get("base_color"):
        fail(f"armed slot: roughness is {got_now.get('roughness')!r}, base colour "
             f"{got_now.get('base_color')!r} ({problem or state.error})")
    elif changed(before, after) < 1.0:
        fail(f"armed slot: the view hardly changed ({changed(before, after):.2f} mean levels)")
    elif not state.message.endswith("as the roughness map"):   # which slot, in the status row
        fail(f"armed slot: the status row says {state.message!r}")
    else:
        print(f"armed slot: {os.path.basename(rough)} is the roughness map; the view changed by "
              f"{changed(before, after):.1f} mean levels")
    # A .json preset: the whole material, its maps cleared (a preset has none).
    before = after
    problem = drop(inputs["preset"])
    after = win.view_pixels()
    keep("dropped_preset", after)
    if problem or state.material.name != "copper" or state.texture_maps.paths():
        fail(f"preset: the material is {state.material.name!r} with maps {state.texture_maps.paths()} "
             f"({problem or state.error})")
    elif changed(before, after) < 2.0:
        fail(f"preset: the view hardly changed ({changed(before, after):.2f} mean levels)")
    else:
        print(f"preset: copper.json is the material; the view changed by {changed(before, after):.1f} mean levels")
    # A folder, as a file manager drags one: its images are one texture set.
    before = after
    folder = os.path.dirname(inputs["mesh"])
    problem = drop(folder)
    after = win.view_pixels()
    got = state.texture_maps.paths()
    wrong = {slot: got.get(slot) for slot, path in inputs["maps"].items() if got.get(slot) != path}
    if problem or wrong or state.error:
        fail(f"folder: slots not as in the folder: {wrong} ({problem or state.error})")
    elif changed(before, after) < 2.0:
        fail(f"folder: the view hardly changed ({changed(before, after):.2f} mean levels)")
    else:
        print(f"folder: {len(got)} maps in their slots; the view changed by {changed(before, after):.1f} mean levels")
    win.close()
    print(f"x drop: {failures} failures in 6 drops")
    return failures


if __name__ == "__main__":
    if len(sys.argv) >= 5 and sys.argv[1] == "source":
        problem = xdnd_drop(int(sys.argv[2], 0), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5:])
        if problem:
            print(f"xdnd: {problem}")
        sys.exit(1 if problem else 0)
    if len(sys.argv) >= 3 and sys.argv[1] == "checks":
        sys.exit(1 if _checks(sys.argv[2]) else 0)
    print("usage: editor_x_drop.py source WINDOW X Y FILE... | checks ENV.hdr", file=sys.stderr)
    sys.exit(2)
