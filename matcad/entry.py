"""The command line's first lines, for `matcad` (the console script) and `python -m matcad`: until the CLI installs its
own handlers an interrupt has nothing to clean up, so SIGINT and SIGTERM leave at once with their exit codes (130,
143), a Ctrl-C while Python still builds the signal module's enums (its first milliseconds) too. Importing matcad as
a library installs nothing, and leaves the garbage collector as it was."""

import gc
import os

try:
    import signal

    signal.signal(signal.SIGINT, lambda *_: os._exit(130))
    signal.signal(signal.SIGTERM, lambda *_: os._exit(143))
except KeyboardInterrupt:
    os._exit(130)


GC_THRESHOLD = (200_000, 30, 30)
"""The cyclic garbage collector's thresholds in a matcad process (CPython's default: 700, 10, 10). With
OpenCASCADE loaded the heap holds millions of objects, and every full collection walks them all again: a full
``build`` of the paper's taxel spent ~0.3 s of 2.7 s collecting (2.75 -> 2.40 s wall, benchmarks/floors.py); commands
without the kernel and sweeps are unchanged (memory within 1 %). The values mypy sets for the same reason
(mypy/build.py)."""


def run() -> None:
    """Run the command line (:func:`matcad.cli.run`) with :data:`GC_THRESHOLD`."""
    gc.set_threshold(*GC_THRESHOLD)
    from matcad.cli import run as cli

    cli()
