"""The split view's and the reference's passes drawn once by a niced child process at the
editor's start, so that their first use in a frame is a read of Mesa's shader disk cache.

Opening the split view draws the composite pass (compare_view.py) for the first time, and the
reference compare tone maps its summed rows through render/tonemap.frag (one program a tone
curve); neither goes through the scene's gate (variant_warmup.py), and on llvmpipe with an empty
Mesa cache their first draws took 640 ms and 1142 ms in the frame. The child
(``python -m alight.frontends.editor.pass_warmup``, worker_process.py, niced) draws the same
passes, with the same code, formats and state, once: the composite pass, then the tone map pass
with the view's tone curve, then with the others; Mesa keeps the generated code, and the
editor's own first draws take a few milliseconds. Where the driver keeps no such cache this
only costs the child's CPU, below the editor's priority. The child ends when done.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

START_AFTER_FRAMES = 3   # the first frames are the view's alone


@dataclass
class PassWarmupJob:
    tonemaps: tuple        # the tone curves to draw the tone map pass with, the view's first


class PassWarmup:
    """The parent's side: ``step(display)`` each frame starts the child once and closes it when
    it has answered. ``done``: it answered (done, error or cancelled)."""

    def __init__(self):
        self._frames = 0
        self._worker = None
        self._job_id = None
        self.done = False
        self.seconds = None   # the child's time for the job (tests and benchmarks read it)

    def step(self, display) -> None:
        if self.done:
            return
        self._frames += 1
        if self._worker is None:
            if self._frames <= START_AFTER_FRAMES:
                return
            from alight.core.scene import TONEMAPS
            from alight.frontends.editor.worker_process import WorkerProcess

            self._worker = WorkerProcess("alight.frontends.editor.pass_warmup")
            curves = (display.tonemap,) + tuple(t for t in TONEMAPS if t != display.tonemap)
            self._job_id = self._worker.submit(PassWarmupJob(tonemaps=curves))
            return
        for job_id, word, text in self._worker.answers():
            if job_id == self._job_id and word != "progress":
                self.seconds = float(text) if word == "done" else None
                self.done = True
                self.close()
                return

    def close(self) -> None:
        if self._worker is not None:
            self._worker.close()
            self._worker = None


def main() -> int:
    import dataclasses

    import numpy as np

    from alight.core.scene import Display
    from alight.frontends.editor.compare_view import composite, composite_program, tonemap_rows
    from alight.frontends.editor.worker_process import serve
    from alight.render.renderer import ForwardRenderer
    from alight.render.targets import Targets

    renderer = ForwardRenderer()
    ctx = renderer.ctx

    def handle(job: PassWarmupJob, progress, superseded) -> bool:
        import time

        from alight.frontends.editor.variant_warmup import CACHE_SETTLE_S

        # The editor's kinds of images (EditorWindow.new_targets; the composite's output texture):
        # llvmpipe's generated code depends on their formats, not on their size.
        a, b = (Targets(ctx, 64, 64, "none", 4) for _ in range(2))
        out = ctx.texture((64, 64), 4, dtype="f1")
        fbo = ctx.framebuffer([out])
        prog, vao = composite_program(ctx)
        try:
            composite(ctx, prog, vao, a.display, b.display, fbo, 32, True, True)
            ctx.finish()
            rows = np.zeros((16, 16, 4), np.float32)
            for i, curve in enumerate(job.tonemaps):
                progress(i / len(job.tonemaps))
                tonemap_rows(ctx, renderer, rows, dataclasses.replace(Display(), tonemap=curve), a)
                ctx.finish()
        finally:
            for obj in (vao, prog, fbo, out):
                obj.release()
            a.release()
            b.release()
        # Mesa writes its disk cache from a thread of its own: a moment for the last entries
        # (variant_warmup.py's CACHE_SETTLE_S).
        time.sleep(CACHE_SETTLE_S)
        return True

    return serve(handle)


if __name__ == "__main__":
    sys.exit(main())
