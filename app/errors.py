"""The one exception type a user sees as a message rather than a traceback."""


class AlightError(Exception):
    """A user's mistake or a bad input file.

    The CLI prints it as one line (``alight: error: <message>``) and exits with status 2.
    Messages name the file (or option) first and the problem second, e.g.
    ``memorial.exr: not a 2:1 equirectangular map (512x768)``.
    """


_WARNED: set[str] = set()


def warn(message: str) -> None:
    """Print ``alight: warning: <message>`` on stderr, once per distinct message per process:
    what alight did without (a cache it could not use, a repair it made), never repeated."""
    import sys

    line = " ".join(str(message).split())
    if line in _WARNED:
        return
    _WARNED.add(line)
    print(f"alight: warning: {line}", file=sys.stderr)
