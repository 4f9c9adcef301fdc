"""A long-lived child process that does the editor's slow GL work away from its frames: one
Python process with its own EGL context (a ``ForwardRenderer`` of its own), started once and
fed jobs, as the thumbnails' render process is (thumbnail_worker.py).

The editor's frame never waits on it: a software GL (llvmpipe) holds the GIL and the CPU for
seconds in a shader's first draw or in a reference sum, so neither a thread of the editor nor
its own context could do this work without stalling the window.

Protocol, one line each way:

- to the child: ``ID<TAB>JOB.pickle`` (a job file the child's ``handle`` reads, ``write_job``'s
  layout; the parent deletes the file once answered);
- from the child: ``ID<TAB>WORD<TAB>TEXT``, WORD one of ``progress`` (TEXT a fraction),
  ``done`` (TEXT the job's seconds), ``error`` (TEXT one line) or ``cancelled``.

A job sent while another runs supersedes it: the child's job sees ``superseded()`` between its
steps and stops (``cancelled``).

Parent side: ``WorkerProcess``; child side: ``serve``.

A job is pickled with protocol 5's out-of-band buffers: its arrays (a mesh's decoded textures,
85 MB for DamagedHelmet) are not copied into the pickle but written from them by a thread of
the parent, whose file writes release the GIL. The frame that submits pays only the pickle of
the rest (the whole pickle took that frame 0.82-0.87 s with the helmet: benchmarks/results/
editor_occlusion.md). The job's arrays must not be changed in place after ``submit``; alight's
meshes and scenes are replaced, never changed in place.
"""

from __future__ import annotations

import os
import pickle
import queue
import struct
import subprocess
import sys
import tempfile
import threading
import time
import weakref
from pathlib import Path

# A long job (the reference's sum) runs below the editor's priority: the frames first.
CHILD_NICENESS = 10

_JOB_MAGIC = b"ALJOB5\0\0"

# The parent's workers with their jobs (``busy``), and what a child's answer calls (``set_waker``):
# an idle editor waits for events rather than drawing frames, and wakes when an answer comes.
_LIVE: weakref.WeakSet = weakref.WeakSet()
_waker = None


def set_waker(function) -> None:
    """``function()`` is called (on a reader thread) whenever a child answers; None: nothing.
    The editor's window passes glfw.post_empty_event, which ends its wait for events."""
    global _waker
    _waker = function


def busy() -> bool:
    """Whether any worker of this process has a job not answered yet (or answered, not taken)."""
    return any(w._files for w in list(_LIVE))


def job_pickle(job) -> tuple[bytes, list]:
    """``job`` pickled with protocol 5: (the pickle, its out-of-band buffers as memoryviews of
    the job's own arrays, uncopied)."""
    buffers: list = []
    head = pickle.dumps(job, protocol=5, buffer_callback=buffers.append)
    return head, [b.raw() for b in buffers]


def write_job(f, head: bytes, buffers: list) -> None:
    """The job file: magic, the buffer count, the pickle's and each buffer's length (little-endian
    uint64), the pickle, the buffers."""
    f.write(_JOB_MAGIC + struct.pack(f"<{2 + len(buffers)}Q", len(buffers), len(head), *(b.nbytes for b in buffers)))
    f.write(head)
    for b in buffers:
        f.write(b)


def read_job(f):
    """The job ``write_job`` wrote to the open file ``f``."""
    if f.read(len(_JOB_MAGIC)) != _JOB_MAGIC:
        raise ValueError("not a worker job file")
    count, head_size = struct.unpack("<2Q", f.read(16))
    sizes = struct.unpack(f"<{count}Q", f.read(8 * count)) if count else ()
    head = f.read(head_size)
    buffers = []
    for size in sizes:
        b = bytearray(size)
        if f.readinto(b) != size:
            raise ValueError("a worker job file ends early")
        buffers.append(b)
    return pickle.loads(head, buffers=buffers)


class WorkerProcess:
    """The parent's handle on one child process ``python -m MODULE ARGS...`` (started on the first job,
    started again if it ended). ``answers()`` returns the lines that came back since the last
    call, as (job id, word, text); none of its calls blocks but ``wait``."""

    def __init__(self, module: str, args: tuple[str, ...] = ()):
        self.module, self.args = module, tuple(args)
        self._process = None
        self._answers: queue.Queue = queue.Queue()
        self._next_id = 0
        self._scratch = Path(tempfile.mkdtemp(prefix="alight-worker-"))
        self._files: dict[int, Path] = {}
        self._outbox: queue.Queue = queue.Queue()   # jobs for the writer thread, in order
        self._writer = None
        _LIVE.add(self)

    def submit(self, job) -> int:
        """Send ``job`` (picklable; its arrays left unchanged from now on); returns its id. The
        file is written and the child told by a thread of this object, so the caller's frame
        pays only the pickle without the arrays' bytes. A child that cannot be started or
        written to answers ``error`` for it."""
        self._next_id += 1
        job_id = self._next_id
        path = self._scratch / f"job-{job_id}.pickle"
        self._files[job_id] = path
        self._outbox.put((job_id, path, *job_pickle(job)))
        if self._writer is None:
            self._stop = threading.Event()
            self._writer = threading.Thread(target=self._write, args=(self._outbox, self._stop),
                                            name=f"alight-{self.module}-writer", daemon=True)
            self._writer.start()
        return job_id

    def _write(self, outbox: queue.Queue, stop: threading.Event) -> None:
        while True:
            item = outbox.get()
            if item is None or stop.is_set():
                return
            job_id, path, head, buffers = item
            try:
                with open(path.with_suffix(".tmp"), "wb") as f:
                    write_job(f, head, buffers)
                os.replace(path.with_suffix(".tmp"), path)
                if stop.is_set():   # closed while this job was written: no child started for it
                    return
                if self._process is None or self._process.poll() is not None:
                    self._start()
                self._process.stdin.write(f"{job_id}\t{path}\n")
                self._process.stdin.flush()
            except (OSError, ValueError, AttributeError) as exc:
                self._answers.put((job_id, "error", f"the worker process could not be started ({exc})"))

    def scratch_file(self, name: str) -> Path:
        """A path in this worker's scratch folder (a job's output the child writes)."""
        return self._scratch / name

    def _start(self) -> None:
        self._process = subprocess.Popen([sys.executable, "-m", self.module, *self.args], stdin=subprocess.PIPE,
                                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, bufsize=1)
        threading.Thread(target=self._read, args=(self._process,), name=f"alight-{self.module}",
                         daemon=True).start()

    def _read(self, process) -> None:
        for line in process.stdout:
            job_id, _, rest = line.rstrip("\n").partition("\t")
            word, _, text = rest.partition("\t")
            try:
                self._answers.put((int(job_id), word, text))
            except ValueError:
                continue
            _wake()
        # The child ended: every job it had not answered fails (the parent may start another).
        self._answers.put((0, "ended", ""))
        _wake()

    def answers(self) -> list[tuple[int, str, str]]:
        out = []
        while True:
            try:
                job_id, word, text = self._answers.get_nowait()
            except queue.Empty:
                return out
            out.extend(self._settle(job_id, word, text))

    def wait(self, job_id: int, timeout_s: float) -> list[tuple[int, str, str]]:
        """Block until job ``job_id`` is answered (done, error or cancelled) or ``timeout_s``
        passes; returns every line that came back meanwhile, as ``answers``."""
        out, end = [], time.monotonic() + timeout_s
        while time.monotonic() < end:
            try:
                job_id_now, word, text = self._answers.get(timeout=max(0.0, min(0.5, end - time.monotonic())))
            except queue.Empty:
                continue
            out.extend(self._settle(job_id_now, word, text))
            if any(i == job_id and w != "progress" for i, w, _ in out):
                return out
        out.append((job_id, "error", f"no answer in {timeout_s:.0f} s"))
        return out

    def _settle(self, job_id, word, text):
        if word == "ended":   # the pending jobs' answers
            pending = sorted(self._files)
            for i in pending:
                self._forget(i)
            return [(i, "error", "the worker process ended") for i in pending]
        if word != "progress":
            self._forget(job_id)
        return [(job_id, word, text)]

    def _forget(self, job_id) -> None:
        path = self._files.pop(job_id, None)
        if path is not None:
            path.unlink(missing_ok=True)

    def close(self) -> None:
        if self._writer is not None:   # (a job being written is abandoned with the child)
            self._stop.set()
            self._outbox.put(None)
            self._writer.join(timeout=2)
            self._writer, self._outbox = None, queue.Queue()
        process, self._process = self._process, None
        if process is not None and process.poll() is None:
            try:
                process.stdin.close()
                process.wait(timeout=2)
            except (OSError, subprocess.TimeoutExpired):
                process.kill()
        for path in self._scratch.glob("*"):
            path.unlink(missing_ok=True)
        try:
            self._scratch.rmdir()
        except OSError:
            pass


def _wake() -> None:
    waker = _waker
    if waker is not None:
        try:
            waker()
        except Exception:   # (the window closing meanwhile: its loop is gone anyway)
            pass


# --- the child's side ----------------------------------------------------------------------------

class _Jobs:
    """The jobs read from stdin by a thread, so a running job can see a newer one waiting."""

    def __init__(self):
        self._queue: queue.Queue = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for line in sys.stdin:
            job_id, _, path = line.rstrip("\n").partition("\t")
            self._queue.put((job_id, path))
        self._queue.put(None)

    def next(self):
        """The newest job waiting (older ones answered ``cancelled``), blocking; None at the end."""
        item = self._queue.get()
        while item is not None and not self._queue.empty():
            nxt = self._queue.get()
            if nxt is None:
                self._queue.put(None)
                break
            answer(item[0], "cancelled")
            item = nxt
        return item

    def waiting(self) -> bool:
        return not self._queue.empty()


def answer(job_id, word: str, text: str = "") -> None:
    print(f"{job_id}\t{word}\t{' '.join(str(text).split())}", flush=True)


def serve(handle, niceness: int = CHILD_NICENESS) -> int:
    """The child's loop: ``handle(job, progress, superseded)`` for each job, ``job`` unpickled,
    ``progress(fraction)`` to report, ``superseded()`` True once a newer job waits (the handler
    may then stop early and return False: answered ``cancelled``). Any exception is the job's one-line error."""
    try:   # the editor's frames first: a child that sums takes what they leave of the cores
        if niceness:
            os.nice(niceness)
    except OSError:
        pass
    from alight.errors import on_stderr

    with on_stderr():   # the child's warnings as the editor's own: 'alight: warning:' lines on stderr
        return _serve(handle)


def _serve(handle) -> int:
    jobs = _Jobs()
    while True:
        item = jobs.next()
        if item is None:
            return 0
        job_id, path = item
        start = time.perf_counter()
        try:
            with open(path, "rb") as f:
                job = read_job(f)
            finished = handle(job, lambda fraction: answer(job_id, "progress", f"{fraction:.4f}"), jobs.waiting)
            if finished is False:
                answer(job_id, "cancelled")
            else:
                answer(job_id, "done", f"{time.perf_counter() - start:.3f}")
        except Exception as exc:   # one line back, and the next job goes on
            answer(job_id, "error", f"{type(exc).__name__}: {exc}" if not _is_alight(exc) else str(exc))


def _is_alight(exc) -> bool:
    from alight.errors import AlightError

    return isinstance(exc, AlightError)
