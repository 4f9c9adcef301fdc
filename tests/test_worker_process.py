"""The editor's child-process protocol (app/frontends/editor/worker_process.py): a job's arrays
reach the child intact, and the frame that submits a job does not
wait for its file to be written (a mesh's decoded textures are tens of MB)."""

from __future__ import annotations

import textwrap
import threading

import numpy as np

from alight.frontends.editor import worker_process
from alight.frontends.editor.worker_process import WorkerProcess

CHILD = textwrap.dedent('''
    import sys, zlib
    import numpy as np
    from alight.frontends.editor.worker_process import serve

    def handle(job, progress, superseded):
        image = job["image"]
        with open(job["out"], "w") as f:
            f.write(f"{job['name']} {image.shape} {image.dtype} {zlib.crc32(np.ascontiguousarray(image).tobytes())}")
        return True

    sys.exit(serve(handle, niceness=0))
''')


def _worker(tmp_path, monkeypatch) -> WorkerProcess:
    (tmp_path / "echo_worker.py").write_text(CHILD)
    import os

    monkeypatch.setenv("PYTHONPATH", str(tmp_path) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return WorkerProcess("echo_worker")


def _done(worker, job_ids, timeout_s=60.0):
    words = {}
    for job_id in job_ids:
        for i, word, text in worker.wait(job_id, timeout_s):
            if word != "progress":
                words[i] = (word, text)
    return words


def test_arrays_reach_the_child_intact(tmp_path, monkeypatch):
    import zlib

    worker = _worker(tmp_path, monkeypatch)
    rng = np.random.default_rng(1)
    images = [rng.random((512, 256, 4)).astype(np.float32),
              (rng.random((300, 301, 3)) * 255).astype(np.uint8),
              np.arange(64, dtype=np.uint16).reshape(8, 8)[:, ::2]]   # not contiguous: pickled in band
    try:
        for k, image in enumerate(images):   # one at a time: a job sent while another waits supersedes it
            job_id = worker.submit({"name": f"job{k}", "image": image, "out": str(tmp_path / f"out{k}.txt")})
            assert _done(worker, [job_id])[job_id][0] == "done"
            expected = f"job{k} {image.shape} {image.dtype} {zlib.crc32(np.ascontiguousarray(image).tobytes())}"
            assert (tmp_path / f"out{k}.txt").read_text() == expected
    finally:
        worker.close()


def test_submit_does_not_wait_for_the_file(tmp_path, monkeypatch):
    """The job's file is written by the worker's thread: submit returns while that write is held
    back, and the child gets the job once it is let go."""
    worker = _worker(tmp_path, monkeypatch)
    gate, entered = threading.Event(), threading.Event()
    write_job = worker_process.write_job

    def held_write(f, head, buffers):
        entered.set()
        assert gate.wait(60)
        write_job(f, head, buffers)

    monkeypatch.setattr(worker_process, "write_job", held_write)
    image = np.ones((1024, 1024, 4), np.float32)
    try:
        job_id = worker.submit({"name": "held", "image": image, "out": str(tmp_path / "held.txt")})
        assert entered.wait(30), "the worker's thread never began writing the job"
        assert not (tmp_path / "held.txt").exists()
        assert worker.answers() == []
        gate.set()
        assert _done(worker, [job_id])[job_id][0] == "done"
        assert (tmp_path / "held.txt").read_text().startswith("held (1024, 1024, 4) float32")
    finally:
        gate.set()
        worker.close()
