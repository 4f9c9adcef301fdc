"""The compare view's GL side: half A drawn into its own image, then A left of the divider and B
(the live view) right of it put together in one image, which the window shows and reads as it
does the plain view.

Only the renderer's public calls draw: ``draw_display`` for a forward half (its own ``_Targets``,
so B's image stays B's and neither redraws when only the divider moves), ``render`` for the
screenshot's halves, and ``tonemap`` for the reference (``ReferenceRenderer.render``'s linear
radiance, tone mapped with the view's display settings, so both halves share one curve). The
halves meet in one full-screen pass that fetches each pixel from A or B (no filtering: the image
is exactly A's or B's pixels); the reference has no background, so B shows through around it.
"""

from __future__ import annotations

import time
import types

import numpy as np

from alight.errors import AlightError
from alight.frontends.editor import compare as cmp

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


class CompareView:
    def __init__(self, ctx, renderer):
        self.ctx, self.renderer = ctx, renderer
        self._a_targets = None
        self._a_key = None        # what A's image shows now
        self._a_ok = False        # whether A's image holds a picture (the reference may have failed)
        self._ref_key = None
        self._out = None          # (texture, framebuffer) of the put-together image
        self._prog = self._vao = None
        self.reference_seconds = None
        self.redraws = 0          # A's image drawn (tests read it)

    # --- half A -----------------------------------------------------------------------------

    def _targets_for(self, size, aa):
        from alight.render.renderer import _Targets   # as the window's own view targets

        t = self._a_targets
        if t is None or (t.width, t.height, t.aa) != (size[0], size[1], aa):
            if t is not None:
                t.release()
            t = self._a_targets = _Targets(self.ctx, size[0], size[1], aa, 4)
        return t

    def draw_a(self, win, scene, maps, size, moving: bool) -> None:
        """Bring A's image up to date for this frame (only when what it shows changed)."""
        c = win.state.compare
        targets = self._targets_for(size, win.state.aa)
        if c.mode == "reference":
            key = ("reference", win._view_key(scene, None, size), id(win.state.env))
            if key == self._a_key:
                return
            if moving:   # the sum takes a second or more on a software GL: drawn when still
                self._a_ok = False
                return
            self._a_ok = self._draw_reference(win, scene, targets)
            self._a_key = key
            self.redraws += 1
            return
        a = cmp.a_scene(c, scene)
        key = ("forward", win._view_key(a, maps, size))
        if key == self._a_key and self._a_ok:
            return
        self.renderer.draw_display(a, maps, targets)
        self._a_key, self._a_ok = key, True
        self.redraws += 1

    def _draw_reference(self, win, scene, targets) -> bool:
        """The exact reference into A's display image; False (and the panel's error line) where
        it cannot be drawn."""
        problem = cmp.reference_problem(win.state)
        if problem:
            win.state.fail(AlightError(problem))
            return False
        try:
            linear = self.reference_linear(win, scene, targets.width, targets.height)
        except AlightError as exc:
            win.state.fail(AlightError(f"reference compare: {exc}"))
            return False
        tex = self.ctx.texture((targets.width, targets.height), 4,
                               np.ascontiguousarray(linear[::-1], np.float32).tobytes(), dtype="f4")
        try:
            self.renderer.tonemap(tex, scene.display, targets.display_fbo, opaque=False)
        finally:
            tex.release()
        return True

    def reference_linear(self, win, scene, width: int, height: int) -> np.ndarray:
        """``alight reference``'s radiance of the view, (H, W, 4) float32, top row first, alpha the
        coverage. Errors: AlightError (a roughness below the reference's minimum, ...)."""
        from alight.accuracy.reference import ReferenceRenderer

        env = win.state.env
        t0 = time.perf_counter()
        result = ReferenceRenderer(self.renderer).render(scene, None if env is None else env.radiance, width, height)
        self.reference_seconds = time.perf_counter() - t0
        return result.linear

    # --- putting the halves together -------------------------------------------------------------

    def compose(self, win, scene, maps, b_targets, moving: bool):
        """A left of the divider, ``b_targets``' display image right of it, in an image of B's size.
        Returns an object with the attributes the window reads from a _Targets (display,
        display_fbo, width, height)."""
        c = win.state.compare
        size = (b_targets.width, b_targets.height)
        self.draw_a(win, scene, maps, size, moving)
        if self._out is None or self._out[0].size != size:
            if self._out is not None:
                for obj in self._out:
                    obj.release()
            tex = self.ctx.texture(size, 4, dtype="f1")
            self._out = (tex, self.ctx.framebuffer([tex]))
        if self._prog is None:
            self._prog = self.ctx.program(vertex_shader=_VERTEX, fragment_shader=_FRAGMENT)
            self._vao = self.ctx.vertex_array(self._prog, [])
        tex, fbo = self._out
        self._a_targets.display.use(0)
        b_targets.display.use(1)
        prog = self._prog
        prog["u_a"], prog["u_b"] = 0, 1
        prog["u_split"] = split_column(c.divider, size[0])
        prog["u_has_a"] = bool(self._a_ok)
        prog["u_b_behind_a"] = c.mode == "reference"
        fbo.use()
        self.ctx.viewport = (0, 0) + size
        self._vao.render(vertices=3)
        return types.SimpleNamespace(display=tex, display_fbo=fbo, width=size[0], height=size[1])

    def compose_frame(self, win, scene, maps, b_srgb: np.ndarray, aa: str) -> np.ndarray:
        """The screenshot's split picture: B's pixels ``b_srgb`` (H, W, C) uint8, top row first,
        with A drawn again at that size left of the divider."""
        c = win.state.compare
        h, w = b_srgb.shape[:2]
        if c.mode == "reference":
            targets = self._targets_for((w, h), "none")
            self._a_key = None   # A's image is the screenshot's now
            if not self._draw_reference(win, scene, targets):
                return b_srgb
            a = np.frombuffer(targets.display_fbo.read(components=4, dtype="f1"), np.uint8).reshape(h, w, 4)[::-1]
            return composite_rows(a, _with_alpha(b_srgb), c.divider, b_behind_a=True)[..., :b_srgb.shape[2]]
        frame = self.renderer.render(cmp.a_scene(c, scene), maps, w, h, aa=aa, read_linear=False, read_srgb=True)
        return composite_rows(frame.srgb[..., :b_srgb.shape[2]], b_srgb, c.divider)

    def release(self) -> None:
        if self._a_targets is not None:
            self._a_targets.release()
        for obj in (self._out or ()) + tuple(x for x in (self._vao, self._prog) if x is not None):
            obj.release()
        self._a_targets = self._out = self._vao = self._prog = None


def _with_alpha(image: np.ndarray) -> np.ndarray:
    if image.shape[2] == 4:
        return image
    return np.concatenate([image, np.full(image.shape[:2] + (1,), 255, np.uint8)], axis=2)
