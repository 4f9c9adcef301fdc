"""The compare view's GL side: half A drawn into its own image, then A left of the divider and B
(the live view) right of it put together in one image, which the window shows and reads as it
does the plain view.

Only the renderer's public calls draw: ``draw_display`` for a forward half (framebuffers of its
own, so B's image stays B's and neither redraws when only the divider moves), ``render`` for the
screenshot's halves, and ``tonemap`` for the reference (``ReferenceRenderer.render_gbuffer``'s
linear radiance, summed by a process of its own, reference_worker.py, and tone mapped here
with the view's display settings, so both halves share one curve). The halves meet in one
full-screen pass that fetches each pixel from A or B (no filtering: the image is exactly A's
or B's pixels); the reference has no background, so B shows through around it.
"""

from __future__ import annotations

import dataclasses
import time
import types

import numpy as np

from alight.core.scene import Display
from alight.errors import AlightError
from alight.frontends.editor import compare as cmp

# The reference is summed by a process of its own (reference_worker.py): the frame only tone
# maps the rows summed so far, at most this often while the sum runs (a few ms at 800x720).
REFERENCE_SHOW_S = 0.25
# What a screenshot or a test (``finish``) waits for a sum at most.
REFERENCE_WAIT_S = 1200.0
# Finished references kept, by everything they depend on: closing and reopening compare, or
# going back to a view summed before, shows it at once.
REFERENCE_CACHE = 8
_NO_DISPLAY = Display()

_VERTEX = """#version 450 core
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
    gl_Position = vec4(p, 0.0, 1.0);
}
"""
# Left of u_split A's pixel, else B's; where A is uncovered (the reference's background) and
# u_a_covers is off, B's.
_FRAGMENT = """#version 450 core
uniform sampler2D u_a;
uniform sampler2D u_b;
uniform int u_split;
uniform bool u_has_a;
uniform bool u_b_behind_a;
layout(location = 0) out vec4 out_color;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 b = texelFetch(u_b, p, 0);
    vec4 a = u_has_a ? texelFetch(u_a, p, 0) : b;
    out_color = (p.x < u_split && !(u_b_behind_a && a.a == 0.0)) ? a : b;
}
"""


def split_column(divider: float, width: int) -> int:
    """The first column of B in an image ``width`` wide."""
    return int(round(min(1.0, max(0.0, divider)) * width))


def composite_rows(a: np.ndarray, b: np.ndarray, divider: float, b_behind_a: bool = False) -> np.ndarray:
    """The numpy twin of the composite pass for images (H, W, C), top row first."""
    out = b.copy()
    split = split_column(divider, b.shape[1])
    left = a[:, :split]
    if b_behind_a and a.shape[2] == 4:
        covered = left[..., 3:4] > 0
        out[:, :split] = np.where(covered, left, b[:, :split])
    else:
        out[:, :split] = left
    return out


def composite_program(ctx):
    """The composite pass's (program, vertex array)."""
    prog = ctx.program(vertex_shader=_VERTEX, fragment_shader=_FRAGMENT)
    return prog, ctx.vertex_array(prog, [])


def composite(ctx, prog, vao, a_display, b_display, fbo, split: int, has_a: bool, b_behind_a: bool) -> None:
    """The composite pass: A's image left of column ``split``, B's right of it, into ``fbo``
    (the GL side of ``composite_rows``). pass_warmup.py draws the same pass, so the same state."""
    a_display.use(0)
    b_display.use(1)
    prog["u_a"], prog["u_b"] = 0, 1
    prog["u_split"] = split
    prog["u_has_a"] = has_a
    prog["u_b_behind_a"] = b_behind_a
    fbo.use()
    ctx.viewport = (0, 0) + fbo.size
    vao.render(vertices=3)


def tonemap_rows(ctx, renderer, src: np.ndarray, display, targets) -> None:
    """The reference's radiance ``src`` (h, w, 4) float32, top row first, upscaled to ``targets``
    (nearest: each summed pixel a block) and tone mapped with ``display`` into its display
    image; alpha the coverage."""
    h, w = targets.height, targets.width
    rows = np.minimum((np.arange(h) + 0.5) * src.shape[0] / h, src.shape[0] - 1).astype(int)
    cols = np.minimum((np.arange(w) + 0.5) * src.shape[1] / w, src.shape[1] - 1).astype(int)
    full = src[rows][:, cols]
    tex = ctx.texture((w, h), 4, np.ascontiguousarray(full[::-1], np.float32).tobytes(), dtype="f4")
    try:
        renderer.tonemap(tex, display, targets.display_fbo, opaque=False)
    finally:
        tex.release()


class CompareView:
    def __init__(self, ctx, renderer, new_targets):
        """``new_targets(size, aa)``: view framebuffers of A's own (EditorWindow.new_targets)."""
        self.ctx, self.renderer, self.new_targets = ctx, renderer, new_targets
        self._a_targets = None
        self._a_key = None        # what A's image shows now
        self._a_ok = False        # whether A's image holds a picture (the reference may have failed)
        self._ref_key = None      # what the reference job sums (the scene less its display)
        self._ref_job_id = None   # the reference process's job while it sums (_start_reference)
        self._ref_linear = None   # its radiance so far
        self._ref_out = None      # the .npy the process writes the rows into
        self._ref_shown = 0.0     # when the rows were last tone mapped into A's image
        self._ref_holds = None
        # (key, radiance, holds), the last used last (the keys hold dataclasses that do not hash)
        self._ref_cache: list = []
        self._worker = None       # the reference process (worker_process.WorkerProcess), started on first use
        self.reference_jobs = 0   # sums asked of the process (tests read it)
        self.reference_cache_hits = 0   # references shown from the cache
        self.reference_progress = None   # the fraction summed while it runs (the panel shows it)
        self._out = None          # (texture, framebuffer) of the put-together image
        self._prog = self._vao = None
        self.reference_seconds = None
        self.redraws = 0          # A's image drawn (tests read it)

    @property
    def a_ready(self) -> bool:
        """Whether A's image holds A's picture now (the reference may be summing or refused)."""
        return bool(self._a_ok)

    # --- half A -----------------------------------------------------------------------------

    def _targets_for(self, size, aa):
        t = self._a_targets
        if t is None or (t.width, t.height, t.aa) != (size[0], size[1], aa):
            if t is not None:
                self.ctx.screen.use()   # never release a bound framebuffer
                t.release()
            t = self._a_targets = self.new_targets(size, aa)
        return t

    def draw_a(self, win, scene, maps, size, moving: bool, finish: bool = False) -> None:
        """Bring A's image up to date for this frame (only when what it shows changed). The
        reference is summed by a process of its own (``finish``: waits for it to end, for
        screenshots and tests)."""
        c = win.state.compare
        targets = self._targets_for(size, win.state.aa)
        if c.mode == "reference":
            self._step_reference(win, scene, targets, moving, finish)
            return
        a = cmp.a_scene(c, scene)
        key = ("forward", win._view_key(a, maps, size))
        if key == self._a_key and self._a_ok:
            return
        self.renderer.draw_display(a, maps, targets)
        self._a_key, self._a_ok = key, True
        self.redraws += 1

    def _step_reference(self, win, scene, targets, moving: bool, finish: bool) -> None:
        """The exact reference: taken from the cache when this view was summed before, else
        asked of the reference process (reference_worker.py) when what it shows changed and the
        view stands still; the rows it has summed are tone mapped into A's image every
        ``REFERENCE_SHOW_S`` (rows not summed yet are uncovered: B shows through them). The frame
        never waits for the sum but with ``finish``."""
        c = win.state.compare
        size = (targets.width, targets.height)
        # Everything the sum depends on; not the display (exposure, tone map): those re-tone-map only.
        key = (win._view_key(dataclasses.replace(scene, display=_NO_DISPLAY), None, size), id(win.state.env),
               c.reference_scale)
        changed = self._take_answers(win)
        if key != self._ref_key and not moving:
            if self._ref_job_id is not None:   # the sum of what the view showed before stops
                self._worker.submit(None)
            self._ref_key, self._ref_linear, self._a_ok = key, None, False
            self._ref_job_id, self.reference_progress = None, None
            cached = next((entry for entry in self._ref_cache if entry[0] == key), None)
            problem = cmp.reference_problem(win.state)
            if cached is not None:
                self._ref_cache.remove(cached)
                self._ref_cache.append(cached)
                self._ref_linear, changed = cached[1], True
                self.reference_cache_hits += 1
            elif problem:
                if problem not in win.state.error:   # (an undo's row names the step, then this)
                    win.state.fail(AlightError(problem))
            else:
                self._start_reference(win, scene, size, c.reference_scale, key)
        if self._ref_key != key:   # moving: A's half waits for the view to stand still
            self._a_ok = False
            return
        if finish and self._ref_job_id is not None:
            changed |= self._take_answers(win, wait=True)
        display_key = (key, scene.display)
        now = time.perf_counter()
        if self._ref_linear is None:
            self._a_ok = False
        elif (changed and (self._ref_job_id is None or now - self._ref_shown >= REFERENCE_SHOW_S)) \
                or self._a_key != display_key:
            self._tonemap_reference(scene, targets)
            self._a_key, self._a_ok, self._ref_shown = display_key, True, now
            self.redraws += 1

    def _start_reference(self, win, scene, size, scale, key) -> None:
        from alight.frontends.editor.reference_worker import ReferenceJob
        from alight.frontends.editor.worker_process import WorkerProcess

        if self._worker is None:
            self._worker = WorkerProcess("alight.frontends.editor.reference_worker")
        self._ref_out = self._worker.scratch_file(f"reference-{len(self._ref_cache)}-{self.reference_jobs}.npy")
        self._ref_out.unlink(missing_ok=True)
        # The scene without the maps' images it does not read (the reference shades factors).
        job = ReferenceJob(scene=scene, env=win.state.env, width=size[0], height=size[1], scale=scale,
                           out=str(self._ref_out))
        self._ref_job_id = self._worker.submit(job)
        self._ref_started, self.reference_progress = time.perf_counter(), 0.0
        # The cache holds the mesh and environment the key names by id, so neither id is reused.
        self._ref_holds = (win.state.mesh, win.state.env)
        self.reference_jobs += 1

    def _take_answers(self, win, wait: bool = False) -> bool:
        """The reference process's lines about the current job; whether new rows came."""
        if self._worker is None:
            return False
        if wait:
            lines = self._worker.wait(self._ref_job_id, REFERENCE_WAIT_S)
        else:
            lines = self._worker.answers()
        changed = False
        for job_id, word, text in lines:
            if job_id != self._ref_job_id:
                continue   # a job superseded since
            if word == "progress":
                self.reference_progress = float(text)
                changed |= self._read_rows()
            elif word == "done":
                changed |= self._read_rows()
                self._ref_job_id, self.reference_progress = None, None
                self.reference_seconds = time.perf_counter() - self._ref_started
                if self._ref_linear is not None:
                    self._ref_cache.append((self._ref_key, self._ref_linear, self._ref_holds))
                    del self._ref_cache[:-REFERENCE_CACHE]
                self._ref_out.unlink(missing_ok=True)
            else:   # error, cancelled: nothing more comes for this job
                self._ref_job_id, self._ref_linear, self.reference_progress = None, None, None
                self._a_ok = False
                if word == "error":
                    win.state.fail(AlightError(f"reference compare: {text}"))
        return changed

    def _read_rows(self) -> bool:
        try:
            self._ref_linear = np.load(self._ref_out, mmap_mode="r").copy()
        except (OSError, ValueError):   # not written yet
            return False
        return True

    def _tonemap_reference(self, scene, targets) -> None:
        """The reference's radiance, upscaled to A's image (nearest: each summed pixel a block),
        tone mapped with the view's display settings; alpha the coverage."""
        tonemap_rows(self.ctx, self.renderer, self._ref_linear, scene.display, targets)

    # --- putting the halves together -------------------------------------------------------------

    def compose(self, win, scene, maps, b_targets, moving: bool, finish: bool = False):
        """A left of the divider, ``b_targets``' display image right of it, in an image of B's size.
        Returns an object with the attributes the window reads from a Targets (display,
        display_fbo, width, height)."""
        c = win.state.compare
        size = (b_targets.width, b_targets.height)
        self.draw_a(win, scene, maps, size, moving, finish)
        if self._out is None or self._out[0].size != size:
            if self._out is not None:
                self.ctx.screen.use()
                for obj in self._out:
                    obj.release()
            tex = self.ctx.texture(size, 4, dtype="f1")
            self._out = (tex, self.ctx.framebuffer([tex]))
        if self._prog is None:
            self._prog, self._vao = composite_program(self.ctx)
        tex, fbo = self._out
        composite(self.ctx, self._prog, self._vao, self._a_targets.display, b_targets.display, fbo,
                  split_column(c.divider, size[0]), bool(self._a_ok), c.mode == "reference")
        return types.SimpleNamespace(display=tex, display_fbo=fbo, width=size[0], height=size[1])

    def compose_frame(self, win, scene, maps, b_srgb: np.ndarray, aa: str) -> np.ndarray:
        """The screenshot's split picture: B's pixels ``b_srgb`` (H, W, C) uint8, top row first,
        with A drawn again at that size left of the divider."""
        c = win.state.compare
        h, w = b_srgb.shape[:2]
        if c.mode == "reference":
            targets = self._targets_for((w, h), win.state.aa)
            self.draw_a(win, scene, maps, (w, h), False, finish=True)
            if not self._a_ok:
                return b_srgb
            a = np.frombuffer(targets.display_fbo.read(components=4, dtype="f1"), np.uint8).reshape(h, w, 4)[::-1]
            return composite_rows(a, _with_alpha(b_srgb), c.divider, b_behind_a=True)[..., :b_srgb.shape[2]]
        frame = self.renderer.render(cmp.a_scene(c, scene), maps, w, h, aa=aa, read_linear=False, read_srgb=True)
        return composite_rows(frame.srgb[..., :b_srgb.shape[2]], b_srgb, c.divider)

    def release(self) -> None:
        if self._worker is not None:
            self._worker.close()
            self._worker = None
        self.ctx.screen.use()
        if self._a_targets is not None:
            self._a_targets.release()
        for obj in (self._out or ()) + tuple(x for x in (self._vao, self._prog) if x is not None):
            obj.release()
        self._a_targets = self._out = self._vao = self._prog = None


def _with_alpha(image: np.ndarray) -> np.ndarray:
    if image.shape[2] == 4:
        return image
    return np.concatenate([image, np.full(image.shape[:2] + (1,), 255, np.uint8)], axis=2)
