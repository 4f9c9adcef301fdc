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


class FileWatcher:
    """Texture maps and the environment file reloaded when they change on disk: a daemon thread
    stats the watched files every ``interval_s`` (mtime and size, off the render thread, so a
    frame never waits on the file system), and the window takes what changed once a frame
    (``take_changed``) and decodes it again. Polling rather than OS notifications: it sees a
    file replaced by a rename (what image editors and exporters do) as well as one written in
    place, on every platform, for a handful of files at a cost of a few stat calls a second."""

    def __init__(self, interval_s: float = 0.25):
        import threading

        self.interval_s = interval_s
        self._lock = threading.Lock()
        self._paths: frozenset[str] = frozenset()
        self._stamps: dict[str, tuple | None] = {}
        self._changed: set[str] = set()
        self.on_change = None   # called (on the watcher's thread) when a file changed
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="alight-file-watcher", daemon=True)
        self._thread.start()

    @staticmethod
    def _stamp(path: str) -> tuple | None:
        try:
            st = Path(path).stat()
        except OSError:
            return None   # gone for now (a save by rename): its return counts as a change
        return (st.st_mtime_ns, st.st_size)

    def watch(self, paths) -> None:
        """The files to watch now (the main thread calls this each frame; cheap when unchanged).
        A path newly watched is taken as it is now: only later changes count."""
        paths = frozenset(p for p in paths if p)
        if paths == self._paths:
            return
        with self._lock:
            for p in paths - self._paths:
                self._stamps[p] = self._stamp(p)
            for p in self._paths - paths:
                self._stamps.pop(p, None)
                self._changed.discard(p)
            self._paths = paths

    def poll(self) -> None:
        """One round of stat calls (the thread's loop body; tests may call it directly)."""
        with self._lock:
            paths = list(self._paths)
        for p in paths:
            stamp = self._stamp(p)
            with self._lock:
                if p in self._stamps and stamp != self._stamps[p]:
                    self._stamps[p] = stamp
                    if stamp is not None:
                        self._changed.add(p)
                        if self.on_change is not None:   # an idle editor's wait ends (window.py)
                            self.on_change()

    def has_changed(self) -> bool:
        """Whether a watched file changed since the last ``take_changed`` (takes nothing)."""
        with self._lock:
            return bool(self._changed)

    def take_changed(self) -> set[str]:
        """The watched files changed since the last call (and present now)."""
        with self._lock:
            out, self._changed = self._changed, set()
        return out

    def _run(self) -> None:
        while not self._stop.wait(self.interval_s):
            self.poll()

    def stop(self) -> None:
        self._stop.set()
