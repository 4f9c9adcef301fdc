"""SIGTERM and a closed stdout, ended as the user expects: what is being written is removed, no traceback."""

from __future__ import annotations

import os
import sys


class Terminated(KeyboardInterrupt):
    """SIGTERM (a job scheduler's or `kill`'s), raised where the process is, so that what is
    being written is removed as on Ctrl-C (alight.exchange.output.atomic_path) before it exits."""


def _on_terminate(signum, frame):
    raise Terminated()


def _catch_termination():
    """SIGTERM as ``Terminated`` in the main thread; returns the handler it replaces (None
    where signals cannot be set: another thread, an embedding host)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return None
    try:
        return signal.signal(signal.SIGTERM, _on_terminate)
    except (ValueError, OSError):
        return None


def _restore_termination(previous) -> None:
    if previous is not None:
        import signal

        signal.signal(signal.SIGTERM, previous)


def _quiet_stdout() -> None:
    """Point stdout at /dev/null so that Python's final flush of the closed pipe is silent."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
