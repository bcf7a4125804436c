import os
import signal

# until the CLI installs its handlers, an interrupt has nothing to clean up: leave quietly with its exit code
signal.signal(signal.SIGINT, lambda *_: os._exit(130))
signal.signal(signal.SIGTERM, lambda *_: os._exit(143))

from matcad.cli import run  # noqa: E402

run()
