"""The `matcad` commands: one module each, registered in :data:`COMMANDS` (their order in `matcad --help`).

A command module declares ``HELP`` (one line for `matcad --help`), ``OUT`` (its default output folder, or None when
it writes none), ``JSON`` (False for the two commands that print no result: completion, serve), ``arguments(parser)``
adding its own arguments (``--json`` and ``--out`` are added for it from ``JSON`` and ``OUT``) and ``run(args)``
returning an exit code of :data:`matcad.errors.EXIT_CODES`. A command imports what it needs inside ``run``, so
building the parser loads no heavy library. Adding a command is one module and one entry here;
:func:`parser` builds the command line from the registry and :mod:`matcad.cli` dispatches to ``run``.
"""

from __future__ import annotations

import argparse
import importlib
from pathlib import Path

COMMANDS = ("predict", "check", "build", "coupon", "analyze", "calibrate", "infer", "sense", "sweep", "design", "schema",
            "init", "completion", "serve")
"""Every command, in the order of `matcad --help`; each is the module ``matcad.commands.<name>``."""


def command(name: str):
    """The module of command ``name``."""
    return importlib.import_module(f"{__name__}.{name}")


def out_path(text: str) -> Path:
    """``--out``: made absolute at once, so that `--out .` stays meaningful after the folder is replaced. On POSIX a
    Windows path (``C:\\Users\\lab\\out``, ``\\\\server\\share``, any backslash) is refused: it would make one folder
    with that literal name in the current folder."""
    import os
    import re

    if os.sep == "/" and (re.match(r"[A-Za-z]:([\\/]|$)", text) or "\\" in text):
        from matcad.errors import shorten

        raise argparse.ArgumentTypeError(f"{shorten(text)} looks like a Windows path; on this system folders are "
                                         "separated by '/' (e.g. --out out/kit or --out /home/you/kit)")
    return Path(os.path.abspath(text))


def parser(only: str | None = None) -> argparse.ArgumentParser:
    """The whole command line: every registered command with its arguments, ``run`` as its ``func``; with ``only``
    (a command's name: the one being run) just that command's, which parses its arguments alike and skips
    building the other thirteen (a few tens of ms on every run)."""
    import matcad
    from matcad.errors import EXIT_CODES

    top = argparse.ArgumentParser(prog="matcad", description=matcad.__doc__,
                                  epilog="exit codes: " + "; ".join(f"{k} {v}" for k, v in EXIT_CODES.items()),
                                  usage=f"matcad [-h] [--version] {{{','.join(COMMANDS)}}} ..." if only else None)
    top.add_argument("--version", action="version", version=f"matcad {matcad.__version__}")
    sub = top.add_subparsers(dest="command", required=True)
    for name in (only,) if only in COMMANDS else COMMANDS:
        module = command(name)
        cmd = sub.add_parser(name, help=module.HELP)
        cmd.set_defaults(func=module.run)
        if getattr(module, "JSON", True):
            cmd.add_argument("--json", action="store_true", help="print JSON instead of text")
        if getattr(module, "OUT", None):
            cmd.add_argument("--out", type=out_path, help=f"output folder (default {module.OUT})")
        module.arguments(cmd)
    return top
