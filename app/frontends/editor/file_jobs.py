"""Opening a mesh file and exporting glTF off the editor's UI thread.

A new user saw the window freeze for seconds, no frame drawn, while 'open mesh' read
DamagedHelmet (its JSON, buffers and five 2048x2048 textures decoded) and while 'export glTF'
encoded and wrote it. Both now run on a worker thread: the thread does the file's CPU work
(``state.read_mesh``: parse, decode, tangents; ``EditorState.export_job``: encode, write
atomically through ``alight.exchange.output``), and the window's frame takes the result
(``Panel.take_file_jobs``). A mesh's read also makes the CPU side of its GPU upload
(alight.render.mesh_upload: every texture's mip levels, the self-shadowing test), which the frame
that took the mesh did before (1.2 s for DamagedHelmet, no frame drawn); the frames after write a
few MiB of its levels each (``staged``, GL objects are made on the GL thread only) and the one that
completes it assigns the mesh to the state. The thread runs niced (``WORKER_NICE``): the frames
come first on a busy machine, the open finishing later.

Meanwhile the status row says "opening NAME..." / "exporting NAME...", frames keep coming and the
view orbits. A second 'open mesh' while one runs wins: the earlier one's result is dropped when
it comes (its thread cannot be stopped, and finishes unseen). A second 'export glTF' while one
runs is refused with a line in the status row: the first is writing a file, and a second write
to the same name would race it. A failure gives the usual one-line error and leaves the previous
mesh in place (nothing is assigned before the read is whole).

The numpy and image decoding release the GIL for much of the read; the rest is Python, which the
interpreter shares between the frame and the thread (benchmarks/bench_editor_open_mesh.py
measures the frames drawn and the longest gap during the helmet's open).
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass


@dataclass
class Done:
    """A finished job: ``kind`` 'open' or 'export', what it was for (the mesh's spec, the file
    written), and its value (the mesh, the export's note) or the exception it raised."""
    kind: str
    target: str
    value: object = None
    error: Exception | None = None


class FileJobs:
    """The panel's file work on worker threads: one open (the latest) and one export at a time."""

    def __init__(self):
        self._lock = threading.Lock()
        self._open_id = 0              # the latest open asked for; an older one's result is dropped
        self._opening = ""             # its spec, '' when none runs
        self._exporting = ""           # the file an export writes, '' when none runs
        self._done: list[Done] = []    # finished, not yet taken by a frame
        self.wake = None               # called on the worker thread when a job ends (the window's idle wait)
        self.started = 0               # jobs started so far (tests and the benchmark read it)
        self.threads = 0               # worker threads alive, superseded ones included
        self.frames_while_running = 0  # frames that found a job running (``take``): drawn meanwhile
        # A mesh read, its GPU upload going on over frames (the panel's ``take_file_jobs``):
        # (spec, mesh, alight.render.mesh_upload.MeshUpload), None when none.
        self.staged = None
        # Called once the latest open's mesh is in the state (a restored session's own-materials
        # box and camera, which the mesh it comes with must find); None when nothing waits.
        self.then = None
        # The 'own materials' box the mesh being opened gets when it comes: ticked wherever the
        # file has materials, or a restored session's. A session saved meanwhile keeps it (the
        # placeholder's box on screen is not the artist's choice).
        self.own_materials = True

    @property
    def busy(self) -> bool:
        """Whether a job runs or a result waits for a frame to take it."""
        with self._lock:
            return bool(self._opening or self._exporting or self._done or self.staged is not None)

    def status(self) -> str:
        """The status row's line while a job runs, else ''."""
        with self._lock:
            opening = self._opening or (self.staged[0] if self.staged is not None else "")
            parts = [f"{verb} {os.path.basename(target) or target}..."
                     for verb, target in (("opening", opening), ("exporting", self._exporting)) if target]
        return "; ".join(parts)

    @property
    def opening(self) -> str:
        """The spec of the mesh being read or uploaded, '' when none (the session saved meanwhile
        keeps it: the mesh the artist is waiting for)."""
        with self._lock:
            return self._opening or (self.staged[0] if self.staged is not None else "")

    def open_mesh(self, spec: str, read, then=None, own_materials: bool = True) -> None:
        """Read ``spec`` with ``read(spec)`` on a thread; a later call supersedes this one (and a
        mesh of an earlier one still being uploaded). ``then()`` is called once the mesh is in
        the state; not where another open superseded this one or the read failed.
        ``own_materials``: the 'own materials' box ``then`` gives the mesh (``self.own_materials``)."""
        self.drop_open()
        self.then, self.own_materials = then, own_materials
        with self._lock:
            self._open_id += 1
            job, self._opening = self._open_id, spec
        self._start(lambda: self._run_open(job, spec, read))

    def drop_open(self) -> None:
        """Forget the open that runs (another mesh was chosen since): its result is dropped, and
        so is a mesh still being uploaded (its textures released)."""
        self.then, self.own_materials = None, True
        with self._lock:
            self._open_id += 1
            self._opening = ""
            staged, self.staged = self.staged, None
        if staged is not None:
            staged[2].drop()

    def export(self, path: str, run) -> bool:
        """Run ``run()`` (the export, writing ``path``) on a thread. Returns False, starting
        nothing, while another export runs."""
        with self._lock:
            if self._exporting:
                return False
            self._exporting = path
        self._export_thread = self._start(lambda: self._run_export(path, run))
        return True

    def finish_export(self, timeout: float | None = None) -> str:
        """Wait for the export that runs (the window closing: a daemon thread stopped at exit
        left its temporary file and no export). Returns the file it writes, '' when none ran."""
        path = self.exporting
        thread = getattr(self, "_export_thread", None)
        if path and thread is not None:
            thread.join(timeout)
        return path

    @property
    def exporting(self) -> str:
        with self._lock:
            return self._exporting

    def take(self) -> list[Done]:
        """The jobs finished since the last call (on the GL thread, once a frame)."""
        with self._lock:
            done, self._done = self._done, []
            if self._opening or self._exporting or self.staged is not None:
                self.frames_while_running += 1
        return done

    def _start(self, target) -> threading.Thread:
        self.started += 1
        with self._lock:
            self.threads += 1

        def run():
            _lower_priority()
            try:
                target()
            finally:
                with self._lock:
                    self.threads -= 1
        thread = threading.Thread(target=run, name="alight-file-job", daemon=True)
        thread.start()
        return thread

    def _run_open(self, job: int, spec: str, read) -> None:
        try:
            result = Done("open", spec, value=read(spec))
        except Exception as exc:   # reported as one line by the frame that takes it
            result = Done("open", spec, error=exc)
        with self._lock:
            if job != self._open_id:
                return   # superseded: a later open is what the user asked for
            self._opening = ""
            self._done.append(result)
        self._wake()

    def _run_export(self, path: str, run) -> None:
        try:
            result = Done("export", path, value=run())
        except Exception as exc:
            result = Done("export", path, error=exc)
        with self._lock:
            self._exporting = ""
            self._done.append(result)
        self._wake()

    def _wake(self) -> None:
        if self.wake is not None:
            self.wake()


# How much lower than the window's the worker thread runs (Linux nice levels, this thread alone).
# On a busy 2-core machine the read and the mip levels (a second of CPU for DamagedHelmet)
# competed with the frames for the cores: a frame waited up to 1.9 s for one in a test run.
WORKER_NICE = 10


def _lower_priority() -> None:
    """The calling thread niced by WORKER_NICE (Linux: setpriority on a thread id affects that
    thread only); elsewhere, or where it is refused, nothing."""
    try:
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), WORKER_NICE)
    except (AttributeError, OSError):
        pass
