"""The command line's first lines, for `matcad` (the console script) and `python -m matcad`: until the CLI installs its
own handlers an interrupt has nothing to clean up, so SIGINT and SIGTERM leave at once with their exit codes (130,
143), a Ctrl-C while Python still builds the signal module's enums (its first milliseconds) too. Importing matcad as
a library installs nothing."""

import os

try:
    import signal

    signal.signal(signal.SIGINT, lambda *_: os._exit(130))
    signal.signal(signal.SIGTERM, lambda *_: os._exit(143))
except KeyboardInterrupt:
    os._exit(130)


def run() -> None:
    """Run the command line (:func:`matcad.cli.run`)."""
    from matcad.cli import run as cli

    cli()
