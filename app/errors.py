"""The one exception type a user sees as a message rather than a traceback, and the one way
alight says what it drew without (``warn``)."""

import contextlib
import os


class AlightError(Exception):
    """A user's mistake or a bad input file.

    The CLI prints it as one line (``alight: error: <message>``) and exits with status 2.
    Messages name the file (or option) first and the problem second, e.g.
    ``memorial.exr: not a 2:1 equirectangular map (512x768)``.
    """


class AlightWarning(UserWarning):
    """What alight drew without (a cache it could not use, a repair it made, a map feature it
    does not draw), as the Python API reports it: a Python warning, so ``warnings.catch_warnings``,
    ``pytest.warns`` and pytest's per-test warning capture see it, and ``-W
    error::alight.AlightWarning`` turns it into an error (docs/guides/python-api.md)."""


_WARNED: set[str] = set()
_ON_STDERR = False   # the CLI's way (on_stderr) rather than the API's Python warning
_PACKAGE = os.path.dirname(os.path.abspath(__file__))


def warn(message: str) -> None:
    """Say ``message`` (one line) the front end's way. Under the CLI (``on_stderr``): ``alight:
    warning: <message>`` on stderr, once per distinct message per process, as it always was.
    Elsewhere (the API, the pytest plugin): an AlightWarning from the caller's own line, so
    Python's filters decide how often it shows (the default: once per message and line, again
    in each pytest test, whose warning capture resets them)."""
    import sys

    line = " ".join(str(message).split())
    if not _ON_STDERR:
        import warnings

        warnings.warn(line, AlightWarning, stacklevel=_outside_depth())
        return
    if line in _WARNED:
        return
    _WARNED.add(line)
    print(f"alight: warning: {line}", file=sys.stderr)


def _outside_depth() -> int:
    """warnings.warn's stacklevel of the first frame outside this package (the user's call), so
    the warning points at the user's line and the default filter counts it there (Python 3.12's
    skip_file_prefixes does this; alight runs on 3.11)."""
    import sys

    frame, level = sys._getframe(2), 2   # warn's caller, as warn's stacklevel 2 names it
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(_PACKAGE + os.sep):
        frame, level = frame.f_back, level + 1
    return level if frame is not None else 2


@contextlib.contextmanager
def on_stderr():
    """Within it, ``warn`` prints the CLI's ``alight: warning:`` lines (once per process)
    instead of issuing Python warnings; restored on leaving, so a test that runs the CLI in
    process leaves the API's warnings as they were."""
    global _ON_STDERR
    previous, _ON_STDERR = _ON_STDERR, True
    try:
        yield
    finally:
        _ON_STDERR = previous
