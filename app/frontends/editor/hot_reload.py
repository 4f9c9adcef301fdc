"""Shader hot reload: saving a file under shaders/ rebuilds the editor's programs.

The new programs are compiled into a separate ShaderLibrary first; only when every one of them
compiles does the ForwardRenderer switch to it, so a compile error (shown in the panel with its file
and line) leaves the last good programs in use.
"""

from __future__ import annotations

import time
from pathlib import Path

from alight.core.gpu import ShaderCompileError, ShaderLibrary

# The programs the editor draws with (renderer.py's names); every variant the renderer has
# compiled so far (its defines: debug view, display output, maps, ...) is rebuilt too.
EDITOR_PROGRAMS = (("render/pbr.vert", "render/pbr.frag"),
                   ("render/background.vert", "render/background.frag"),
                   ("render/fullscreen.vert", "render/tonemap.frag"))


class ShaderWatcher:
    def __init__(self, root: Path, interval_s: float = 0.5):
        self.root = Path(root)
        self.interval_s = interval_s
        self._next = 0.0
        self._stamp = self._scan()

    def _scan(self) -> tuple:
        # (path, mtime_ns, size) of every file: an editor saving in place changes one of them.
        out = []
        for p in sorted(self.root.rglob("*")):
            try:
                st = p.stat()
            except OSError:
                continue
            if p.is_file():
                out.append((str(p), st.st_mtime_ns, st.st_size))
        return tuple(out)

    def changed(self, force: bool = False) -> bool:
        """At most one directory scan per interval (a scan every frame would cost frame time)."""
        now = time.monotonic()
        if not force and now < self._next:
            return False
        self._next = now + self.interval_s
        stamp = self._scan()
        if stamp == self._stamp:
            return False
        self._stamp = stamp
        return True


def rebuild(renderer, root: Path) -> str:
    """Compile the editor's programs from ``root`` into a new library and switch the renderer to
    it. Returns '' on success, else the compile error's one line (file:line: message)."""
    library = ShaderLibrary(renderer.ctx, root)
    try:
        for vertex, fragment in EDITOR_PROGRAMS:
            library.program(vertex, fragment)
        for key in list(renderer.shaders._programs):
            if key[0] == "program":
                library.program(key[1], key[2], dict(key[3]))
    except ShaderCompileError as exc:
        library.reload()   # release whatever compiled; the renderer keeps its programs
        return " ".join(str(exc).split())
    renderer.use_shaders(library)
    return ""
