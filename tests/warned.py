"""What alight says it drew without, as a test sees it through the Python API: the
AlightWarnings issued within the block (alight.errors.warn), under Python's default filter (once
per message and calling line), as a user's script sees them."""

from __future__ import annotations

import contextlib
import warnings


@contextlib.contextmanager
def alight_warnings():
    """``with alight_warnings() as lines: ...``: ``lines`` holds the warnings' text once the
    block ends (other warnings are left to the filters)."""
    from alight.errors import AlightWarning

    lines: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        try:
            yield lines
        finally:
            lines.extend(str(w.message) for w in caught if issubclass(w.category, AlightWarning))
