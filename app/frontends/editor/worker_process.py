"""A long-lived child process that does the editor's slow GL work away from its frames: one
Python process with its own EGL context (a ``ForwardRenderer`` of its own), started once and
fed jobs, as the thumbnails' render process is (thumbnail_worker.py).

The editor's frame never waits on it: a software GL (llvmpipe) holds the GIL and the CPU for
seconds in a shader's first draw or in a reference sum, so neither a thread of the editor nor
its own context could do this work without stalling the window.

Protocol, one line each way:

- to the child: ``ID<TAB>JOB.pickle`` (a pickled job the child's ``handle`` reads; the parent
  deletes the file once answered);
- from the child: ``ID<TAB>WORD<TAB>TEXT``, WORD one of ``progress`` (TEXT a fraction),
  ``done`` (TEXT the job's seconds), ``error`` (TEXT one line) or ``cancelled``.

A job sent while another runs supersedes it: the child's job sees ``superseded()`` between its
steps and stops (``cancelled``).

Parent side: ``WorkerProcess``; child side: ``serve``.
"""

from __future__ import annotations

import os
import pickle
import queue
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

# A long job (the reference's sum) runs below the editor's priority: the frames first.
CHILD_NICENESS = 10


class WorkerProcess:
    """The parent's handle on one child process ``python -m MODULE`` (started on the first job,
    started again if it ended). ``answers()`` returns the lines that came back since the last
    call, as (job id, word, text); none of its calls blocks but ``wait``."""

    def __init__(self, module: str):
        self.module = module
        self._process = None
        self._answers: queue.Queue = queue.Queue()
        self._next_id = 0
        self._scratch = Path(tempfile.mkdtemp(prefix="alight-worker-"))
        self._files: dict[int, Path] = {}

    def submit(self, job) -> int:
        """Send ``job`` (picklable); returns its id. A child that cannot be started or written to
        answers ``error`` for it."""
        self._next_id += 1
        job_id = self._next_id
        path = self._scratch / f"job-{job_id}.pickle"
        with open(path.with_suffix(".tmp"), "wb") as f:
            pickle.dump(job, f, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(path.with_suffix(".tmp"), path)
        self._files[job_id] = path
        try:
            if self._process is None or self._process.poll() is not None:
                self._start()
            self._process.stdin.write(f"{job_id}\t{path}\n")
            self._process.stdin.flush()
        except (OSError, ValueError) as exc:
            self._answers.put((job_id, "error", f"the worker process could not be started ({exc})"))
        return job_id

    def scratch_file(self, name: str) -> Path:
        """A path in this worker's scratch folder (a job's output the child writes)."""
        return self._scratch / name

    def _start(self) -> None:
        self._process = subprocess.Popen([sys.executable, "-m", self.module], stdin=subprocess.PIPE,
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
        # The child ended: every job it had not answered fails (the parent may start another).
        self._answers.put((0, "ended", ""))

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
    jobs = _Jobs()
    while True:
        item = jobs.next()
        if item is None:
            return 0
        job_id, path = item
        start = time.perf_counter()
        try:
            with open(path, "rb") as f:
                job = pickle.load(f)
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
