"""Where a new shader variant's time goes: the program's link against its first draw. Not a test.

    .venv/bin/python benchmarks/bench_variant_first_draw.py            # an empty Mesa shader cache, then warm

Runs itself twice in fresh processes sharing one new MESA_SHADER_CACHE_DIR: first with the
cache empty (a new machine), then warm (the driver's disk cache holds what the first run
compiled). Each process draws the editor's view (``draw_display``, 800x720, no AA, the built-in
sphere and studio at the 'low' bake) with gold, then with clearcoat, sheen and iridescence
switched on one after another, each twice. "link" is ``ctx.program`` then ``ctx.finish()`` for
each program compiled during the draw; "draw" is the whole draw with ``ctx.finish()``, link
included. Prints one line a draw.
"""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
import tempfile
import time


def child() -> None:
    from alight.core.gpu import ShaderLibrary
    from alight.exchange.presets import load_preset
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.state import EditorState
    from alight.render.renderer import ForwardRenderer
    from alight.render.targets import Targets

    links: list[float] = []
    build = ShaderLibrary.program

    def timed(self, vertex, fragment, defines=None):
        new = self.program_key(vertex, fragment, defines) not in self._programs
        t0 = time.perf_counter()
        prog = build(self, vertex, fragment, defines)
        if new:
            self.ctx.finish()
            links.append(time.perf_counter() - t0)
        return prog

    ShaderLibrary.program = timed
    state = EditorState()
    state.material = load_preset("gold")
    state.load_mesh("sphere")
    state.load_env("studio")
    r = ForwardRenderer()
    maps = r.bake(state.env, "low")
    camera = OrbitCamera().camera()
    targets = Targets(r.ctx, 800, 720, "none", 4)

    def draw(label: str) -> None:
        links.clear()
        t0 = time.perf_counter()
        r.draw_display(state.scene(camera), maps, targets)
        r.ctx.finish()
        total = time.perf_counter() - t0
        print(f"  {label}: draw {total * 1000:.0f} ms, link {sum(links) * 1000:.0f} ms ({len(links)} programs)",
              flush=True)

    draw("gold, first")
    draw("gold, again")
    for layer, fields in (("clearcoat", {"clearcoat": 1.0}), ("sheen", {"sheen_color": (1.0, 0.5, 0.5)}),
                          ("iridescence", {"iridescence": 1.0})):
        state.material = dataclasses.replace(state.material, **fields)
        draw(f"+{layer}, first")
        draw(f"+{layer}, again")


def main() -> None:
    if "--child" in sys.argv:
        child()
        return
    with tempfile.TemporaryDirectory(prefix="alight-bench-variant-", ignore_cleanup_errors=True) as tmp:
        env = dict(os.environ, MESA_SHADER_CACHE_DIR=os.path.join(tmp, "mesa"),
                   ALIGHT_CACHE_DIR=os.path.join(tmp, "cache"))
        for name in ("empty shader cache", "warm shader cache"):
            print(name, flush=True)
            subprocess.run([sys.executable, os.path.abspath(__file__), "--child"], env=env, check=True)


if __name__ == "__main__":
    main()
