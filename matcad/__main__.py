import os

# until the CLI installs its handlers, an interrupt has nothing to clean up: leave quietly with its exit code. A
# Ctrl-C while Python still builds the signal module's enums (its first milliseconds) is caught the same way.
try:
    import signal

    signal.signal(signal.SIGINT, lambda *_: os._exit(130))
    signal.signal(signal.SIGTERM, lambda *_: os._exit(143))
except KeyboardInterrupt:
    os._exit(130)

from matcad.cli import run  # noqa: E402

run()
