"""Bounded reading of the user's input files: only regular files, never more than a per-kind limit.

Every input (spec, calibration, CSV data, WAV header) is opened here before it is parsed. A FIFO, a device
such as /dev/zero, or a directory is refused without reading a byte (opening with O_NONBLOCK so that a FIFO
without a writer cannot block), and a file above its limit is refused from its size alone. Limits in bytes.
"""

from __future__ import annotations

import os
import stat
from contextlib import contextmanager
from pathlib import Path

from matcad.errors import InputError

SPEC_MAX_BYTES = 1 << 20
"""A spec is ~3 kB; 1 MiB leaves room for comments and refuses anything that is not a spec."""
CALIBRATION_MAX_BYTES = 1 << 20
CSV_MAX_BYTES = 64 << 20
"""~2 million force/frequency rows; a calibration has tens."""


@contextmanager
def open_regular(path: str | Path, what: str):
    """An open binary file object for ``path`` if it is a regular file (symlinks followed); else InputError."""
    p = Path(path)
    try:
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    except OSError as exc:
        raise InputError(f"{what} {p}: cannot be opened ({exc.strerror or exc.__class__.__name__})") from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            kind = ("a folder" if stat.S_ISDIR(mode) else "a pipe (FIFO)" if stat.S_ISFIFO(mode) else
                    "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "not a regular file")
            raise InputError(f"{what} {p}: is {kind}; give a regular file")
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        f = os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise
    with f:
        yield f


def read_bounded(path: str | Path, what: str, limit: int) -> bytes:
    """The whole content of a regular file of at most ``limit`` bytes; else InputError."""
    with open_regular(path, what) as f:
        size = os.fstat(f.fileno()).st_size
        data = f.read(limit + 1) if size <= limit else b""
        if size > limit or len(data) > limit:
            raise InputError(f"{what} {path}: {max(size, len(data))} bytes, larger than the {limit} bytes "
                             f"allowed for a {what}")
        return data


def read_text(path: str | Path, what: str, limit: int) -> str:
    """As :func:`read_bounded`, decoded as UTF-8 (InputError if it is not). A leading byte-order mark (Excel's
    "CSV UTF-8", Windows editors) is dropped."""
    try:
        return read_bounded(path, what, limit).decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputError(f"{what} {path}: is not UTF-8 text") from None
