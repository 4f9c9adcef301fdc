"""``alight``: render materials headless, bake environments, list presets.

A user's mistake (a bad file, a bad option) prints one line ``alight: error: ...`` and exits
with status 2; nothing is written. Heavy modules are imported after the arguments are parsed,
so ``--help`` and argument errors are instant.

The package holds one module per subcommand; each declares its ``Command`` (its arguments and
its run function) and ``COMMANDS`` lists them in the order ``alight --help`` shows. What several
subcommands share is in ``arguments`` (types, the parser, option groups).
"""

from __future__ import annotations

import argparse
import sys

from alight.errors import AlightError, on_stderr
from alight.frontends.cli import (
    bake,
    batch,
    cache,
    chart,
    compare,
    edit,
    export,
    presets,
    reference,
    render,
)
from alight.frontends.cli.arguments import QUALITIES, TONEMAP_CHOICES, _Parser
from alight.frontends.cli.termination import Terminated, _catch_termination, _quiet_stdout, _restore_termination

__all__ = ["COMMANDS", "QUALITIES", "TONEMAP_CHOICES", "build_parser", "main"]

# The subcommands, in the order of 'alight --help'.
COMMANDS = {c.name: c for c in (render.COMMAND, bake.COMMAND, export.COMMAND, batch.COMMAND, reference.COMMAND,
                                 compare.COMMAND, chart.COMMAND, presets.COMMAND, cache.COMMAND, edit.COMMAND)}


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="alight", description="A physically based material renderer "
                                     "(Cook-Torrance, split-sum image-based lighting) on ModernGL.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for command in COMMANDS.values():
        command.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """The ``alight`` command; returns the exit status. A reader that closes the pipe early
    (``alight presets | head``) ends the command quietly, as ``cat`` does: status 141 (128 +
    SIGPIPE), no traceback."""
    try:
        try:
            return _main(argv)
        finally:
            sys.stdout.flush()   # inside the try: a closed pipe shows here, not at interpreter exit
    except BrokenPipeError:
        _quiet_stdout()
        return 128 + 13


def _main(argv: list[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        import os

        if not os.environ.get("DISPLAY"):
            parser.print_help()
            return 0
        args = parser.parse_args(["edit"])   # with a display, plain 'alight' opens the editor
    previous = _catch_termination()
    try:
        # What a command draws without is said as 'alight: warning:' lines on stderr, once
        # per process, not as Python warnings (the API's way: alight.errors.warn).
        with on_stderr():
            return COMMANDS[args.command].run(args)
    except AlightError as exc:
        print(f"alight: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    except Terminated:
        print("alight: terminated", file=sys.stderr)
        return 128 + 15
    except KeyboardInterrupt:
        print("alight: interrupted", file=sys.stderr)
        return 130
    finally:
        _restore_termination(previous)
