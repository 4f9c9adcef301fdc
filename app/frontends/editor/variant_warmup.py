"""New shader variants compiled away from the editor's frames.

A layer switched on or a map loaded needs a shader variant the editor has not compiled. On
llvmpipe the program's link is the small part (0.1-0.4 s here) and the first draw the large one
(0.8-7 s: llvmpipe generates the fragment code for the draw's state then); Mesa keeps both in
its shader disk cache, after which the same compile and first draw take a few tens of ms.
GPU drivers keep such a cache too (NVIDIA's GLCache), and a GPU's link is what costs there.

So the view's draw runs with the shader library's ``gate`` (alight.core.gpu.ShaderLibrary): a
program not compiled yet raises ProgramPending instead of compiling. The window then draws the
last picture's scene (its programs all compiled) with the current camera, and this module asks
its child process (``python -m alight.frontends.editor.variant_warmup``, its own EGL context)
to draw the new scene once, the same way (the same size, anti-aliasing and bake quality): that
compiles the new programs into the driver's cache and reports their keys. Those keys pass the
gate afterwards, and the view draws the new picture, its compile now a cache read. Where the
child cannot help (it fails, or the driver keeps no cache) the compile happens in the frame, as
without this module.

An orbiting view is drawn straight into the window (``draw_display``'s ``into``): another
program (SRGB_BY_FRAMEBUFFER) and, on llvmpipe, other fragment code, generated for the window's
framebuffer format. The child draws those jobs into a hidden window configured as the editor's
(gl_window.py), so its cache entries are the window's; meanwhile the view draws the last picture
into the view image, whose programs are compiled. (Without this, the first orbit of each new
material took 0.7 s of the main thread's time with an empty Mesa cache, in the held-back
frame's fallback: benchmarks/results/editor_stalls.md.)
"""

from __future__ import annotations

import dataclasses
import os
import pickle
import sys
import time
from dataclasses import dataclass

CACHE_SETTLE_S = 0.3
# The presets' variants are drawn once by a niced child this many frames after the view settled
# (``PresetPrefetch``), so a preset's first click reads Mesa's cache instead of waiting seconds
# for a compile (a layered preset: 3+ s here with an empty cache).
PREFETCH_AFTER_FRAMES = 30
PREFETCH_SIZE = (64, 64)   # llvmpipe's generated code depends on formats and state, not on size


@dataclass
class WarmupJob:
    scene: object          # alight.core.scene.Scene, as the view draws it (mesh None: the last one sent)
    env: object            # the environment (alight.ibl.environment.Environment), None: the last one sent
    quality: object        # the bake's alight.ibl.bake.BakeQuality (None without an environment)
    size: tuple            # the view's (width, height)
    aa: str                # the view's anti-aliasing
    out: str               # where the child writes the keys it compiled (a pickle)
    mesh_token: int = 0    # which mesh and environment these are (0: none): each is sent once, then named by token
    env_token: int = 0
    direct: bool = False        # drawn straight into the window (draw_display's into), as the view was
    direct_srgb: bool = False   # ... with the window's framebuffer encoding sRGB (into_encodes_srgb)
    materials: tuple = ()       # the scene drawn once with each of these instead (PresetPrefetch)


def _compiled_keys(path) -> set:
    """The program keys a child wrote to ``path`` (nothing where it could not be read)."""
    try:
        with open(path, "rb") as f:
            return set(pickle.load(f))
    except (OSError, pickle.UnpicklingError, EOFError):
        return set()


class VariantWarmup:
    """The parent's side: ``gate`` for the view's draws, ``request`` when one was held back,
    ``step`` each frame. ``pending``: a draw waits for the child now."""

    def __init__(self):
        self._worker = None
        self._job_id = None
        self._job_trigger = None   # the key that started the job
        self._warm: set = set()    # program keys the child compiled (or that may compile here)
        self.drawn_by_child: set = set()   # program keys the child compiled (tests read it)
        self.jobs = 0              # warm-ups asked of the child (tests read it)
        self.held = 0              # draws held back for a program not compiled yet
        self._sent = (None, None)  # the tokens of the mesh and environment the child has
        self.showing_old = False   # the view's last draw was the last complete picture's scene
        self._holds = None

    @property
    def pending(self) -> bool:
        return self._job_id is not None

    def gate(self, key) -> bool:
        return key in self._warm

    def request(self, win, exc, scene, maps, size, direct: bool = False, direct_srgb: bool = False) -> None:
        """A draw of ``scene`` was held back for ``exc.key``: start the child's draw of it
        (unless one runs: the draw after it asks again for what it did not compile).
        ``direct``, ``direct_srgb``: the view's draw went straight into the window (sRGB-encoding)."""
        self.held += 1
        if self._job_id is not None:
            return
        from alight.frontends.editor.worker_process import WorkerProcess

        if self._worker is None:
            self._worker = WorkerProcess("alight.frontends.editor.variant_warmup")
        out = self._worker.scratch_file(f"keys-{self.jobs}.pickle")
        env = win.state.env if maps is not None else None
        # A mesh or environment of millions of values is pickled once (in this frame), not per job.
        mesh_token, env_token = (0 if x is None else id(x) for x in (scene.mesh, env))
        send_mesh, send_env = mesh_token != self._sent[0], env_token != self._sent[1]
        self._sent = (mesh_token, env_token)
        self._holds = (scene.mesh, env)   # so neither id is reused while the child names it
        job = WarmupJob(scene=scene if send_mesh else dataclasses.replace(scene, mesh=None),
                        env=env if send_env else None,
                        quality=maps.quality if maps is not None else None, size=tuple(size),
                        aa=win.state.aa, out=str(out), mesh_token=mesh_token, env_token=env_token,
                        direct=direct, direct_srgb=direct_srgb)
        self._job_id, self._job_trigger, self._out = self._worker.submit(job), exc.key, out
        self.jobs += 1

    def step(self) -> bool:
        """Take the child's answers; True when a job ended this call and the view shows the old
        picture (the view then draws again; one drawn whole since, by a screenshot, needs not)."""
        if self._worker is None or self._job_id is None:
            return False
        for job_id, word, _text in self._worker.answers():
            if job_id != self._job_id or word == "progress":
                continue
            if word == "done":
                self.add_drawn(_compiled_keys(self._out))
                self._out.unlink(missing_ok=True)
            else:   # the child may have restarted: send the mesh and environment again
                self._sent = (None, None)
            # Whatever the child managed, the key that started the job compiles now (a failed or
            # partial warm-up must never keep the view on the old picture).
            self._warm.add(self._job_trigger)
            self._job_id = self._job_trigger = None
            return self.showing_old
        return False

    def add_drawn(self, keys) -> None:
        """Program keys another child drew (PresetPrefetch): they pass the gate from now on."""
        self._warm.update(keys)
        self.drawn_by_child.update(keys)

    def close(self) -> None:
        if self._worker is not None:
            self._worker.close()
            self._worker = None


class PresetPrefetch:
    """The panel's presets drawn once, after the view has settled, by a child of their own at a
    lower priority than the editor (``python -m alight.frontends.editor.variant_warmup --niced``):
    their programs' keys then pass the view's gate, and a preset's first click compiles from
    Mesa's cache in its frame instead of waiting for the warm-up process. Once per session, for
    the first scene drawn with the panel's material; ``step`` each frame."""

    def __init__(self):
        self._worker = None
        self._job_id = None
        self._out = None
        self._frames = 0
        self.done = False
        self.keys: set = set()   # what the child compiled (tests read it)

    def step(self, win, scene, maps, size) -> None:
        if self.done:
            return
        if self._worker is None:
            warm = win.variant_warmup
            if warm.pending or warm.showing_old or scene.mesh is None or scene.use_file_materials:
                self._frames = 0
                return
            self._frames += 1
            if self._frames < PREFETCH_AFTER_FRAMES:
                return
            from alight.exchange.presets import list_presets, load_preset
            from alight.frontends.editor.worker_process import WorkerProcess

            materials = []
            for name in list_presets():
                try:
                    materials.append(load_preset(name))
                except Exception:   # (a broken preset file is the panel's to report)
                    continue
            self._worker = WorkerProcess("alight.frontends.editor.variant_warmup", ("--niced",))
            self._out = self._worker.scratch_file("prefetch-keys.pickle")
            env = win.state.env if maps is not None else None
            self._job_id = self._worker.submit(WarmupJob(
                scene=scene, env=env, quality=maps.quality if maps is not None else None, size=PREFETCH_SIZE,
                aa=win.state.aa, out=str(self._out), mesh_token=0 if scene.mesh is None else 1,
                env_token=0 if env is None else 1, materials=tuple(materials)))
            return
        for job_id, word, _text in self._worker.answers():
            if job_id != self._job_id or word == "progress":
                continue
            if word == "done":
                self.keys = _compiled_keys(self._out)
                win.variant_warmup.add_drawn(self.keys)
            self.done = True
            self.close()
            return

    @property
    def busy(self) -> bool:
        """Counting the frames before it starts, or its child drawing: the editor keeps drawing
        frames (at the idle loop's background rate, window.py) until it is done."""
        return not self.done and (self._worker is not None or self._frames > 0)

    def cancel(self) -> None:
        """No prefetch in this session (a stopped one adds nothing)."""
        self.done = True
        self.close()

    def close(self) -> None:
        if self._worker is not None:
            self._worker.close()
            self._worker = None


def draw_view(win, scene, maps, targets, into, into_srgb, gated: bool):
    """``renderer.draw_display`` of the view, with the gate when ``gated``: a program not
    compiled yet is handed to the child and the last complete picture's scene is drawn instead
    (with this frame's camera, unless the mesh changed: then with its own). Returns (the
    framebuffer drawn into, whether it is ``scene``); (None, False) where nothing could be drawn
    without a compile and the window's last view image (``last_view_image``) is to be shown again."""
    from alight.core.gpu import ProgramPending

    renderer, warmup = win.renderer, win.variant_warmup
    old = getattr(win, "_last_complete_scene", None)
    if not gated or old is None:   # (nothing drawn yet: no old picture to keep)
        drawn = renderer.draw_display(scene, maps, targets, into=into, into_encodes_srgb=into_srgb)
        warmup._warm.update(renderer.shaders.compiled_keys())
        win._last_complete_scene, warmup.showing_old = scene, False
        return drawn, True
    renderer.shaders.gate = warmup.gate
    try:
        drawn = renderer.draw_display(scene, maps, targets, into=into, into_encodes_srgb=into_srgb)
        warmup._warm.update(renderer.shaders.compiled_keys())
        win._last_complete_scene, warmup.showing_old = scene, False
        return drawn, True
    except ProgramPending as exc:
        warmup.request(win, exc, scene, maps, (targets.width, targets.height),
                       direct=into is not None, direct_srgb=into_srgb)
    finally:
        renderer.shaders.gate = None
    if into is not None:
        # Only the window's variant missing (a first orbit): the scene itself into the view
        # image, whose programs the still view compiled, while the child draws the window's.
        renderer.shaders.gate = warmup.gate
        try:
            drawn = renderer.draw_display(scene, maps, targets)
            win._last_complete_scene, warmup.showing_old = scene, False
            return drawn, True
        except ProgramPending:
            pass
        finally:
            renderer.shaders.gate = None
    if old.mesh is scene.mesh:
        # The same mesh: the last look follows the orbit. A new mesh's camera frames the new
        # mesh; the old mesh seen from it was the trial's "helmet turned to the shader ball's
        # 3/4 view", so the last picture stays as it was until the new one is ready.
        old = dataclasses.replace(old, camera=scene.camera)
    warmup.showing_old = True
    # The last picture where its programs are compiled: into the window if it was drawn there,
    # else into the view image (a first orbit: the window's variants are the child's job now).
    renderer.shaders.gate = warmup.gate
    try:
        for target, srgb in ((into, into_srgb), (None, False)) if into is not None else ((None, False),):
            try:
                return renderer.draw_display(old, maps, targets, into=target, into_encodes_srgb=srgb), False
            except ProgramPending:
                continue
    finally:
        renderer.shaders.gate = None
    if getattr(win, "last_view_image", lambda: None)() is not None:
        # Neither (an orbit that reaches a view whose programs differ, as the built-in sphere's
        # background ring): the view image drawn last is shown again (render_view), a few degrees
        # behind the hand until the child is done, rather than a compile in this frame.
        return None, False
    return renderer.draw_display(old, maps, targets, into=into, into_encodes_srgb=into_srgb), False


# --- the child process ---------------------------------------------------------------------------

def main() -> int:
    from alight.frontends.editor.worker_process import serve
    from alight.render.renderer import ForwardRenderer
    from alight.render.targets import Targets

    from alight.frontends.editor.gl_window import hidden_window_context

    # A hidden window as the editor's (where a display is), for the view's moving frames; its
    # context serves the offscreen draws too (the same llvmpipe, the same shader cache).
    prefetch = "--niced" in sys.argv[1:]   # (PresetPrefetch's child: offscreen draws only, no window)
    window = None if prefetch else hidden_window_context()
    renderer = ForwardRenderer(window[1] if window is not None else None)
    targets = {}
    have = {"mesh": (None, None), "env": (None, None)}   # token -> the object last sent

    def kept(name, token, sent):
        if sent is not None:
            have[name] = (token, sent)
        elif have[name][0] != token:
            raise RuntimeError(f"the {name} named {token} was never sent")
        return have[name][1]

    def handle(job: WarmupJob, progress, superseded) -> bool:
        scene = job.scene
        if job.mesh_token:   # (0: no mesh, or no environment)
            scene = dataclasses.replace(scene, mesh=kept("mesh", job.mesh_token, scene.mesh))
        env = kept("env", job.env_token, job.env) if job.env_token else None
        maps = renderer.bake(env, job.quality) if env is not None and job.quality is not None else None
        key = (job.size, job.aa)
        if key not in targets:
            for t in targets.values():
                t.release()
            targets.clear()
            targets[key] = Targets(renderer.ctx, job.size[0], job.size[1], job.aa, 4)
        into = renderer.ctx.screen if job.direct and window is not None else None
        for material in job.materials or (None,):
            if material is not None:
                if superseded():
                    return False
                scene = dataclasses.replace(scene, material=material)
            renderer.draw_display(scene, maps, targets[key], into=into,
                                  into_encodes_srgb=job.direct_srgb and into is not None)
            renderer.ctx.finish()   # the first draw's code generation happens by here
        # Mesa writes its shader disk cache from a thread of its own: a moment for the entries
        # to be on disk when the editor compiles the same programs.
        time.sleep(CACHE_SETTLE_S)
        with open(job.out + ".tmp", "wb") as f:
            pickle.dump(renderer.shaders.compiled_keys(), f)
        os.replace(job.out + ".tmp", job.out)
        return True

    # Not below the editor's priority where the view waits for this job (the old picture shows);
    # the presets' prefetch (--niced) is work ahead of need, below it.
    from alight.frontends.editor.worker_process import CHILD_NICENESS

    return serve(handle, niceness=CHILD_NICENESS if prefetch else 0)


if __name__ == "__main__":
    sys.exit(main())
