"""Output folders that are never half-written: build in a hidden sibling, then one atomic move into place.

The previous folder survives any failure; a folder that is not an earlier matcad output (no report.json) is
never replaced.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

from matcad.errors import OutputError


def _check_target(target: Path) -> None:
    """Refuse to replace anything that is not an earlier matcad build (or an empty folder)."""
    if not target.exists() and not target.is_symlink():
        return
    if target.is_symlink() or not target.is_dir():
        raise OutputError(f"output folder {target}: exists and is not a folder; refusing to replace it")
    if any(target.iterdir()) and not (target / "report.json").is_file():
        raise OutputError(f"output folder {target}: exists and is not a matcad output folder (no report.json); "
                          "refusing to replace it")


def _replace(tmp: Path, target: Path) -> None:
    """Move the finished build into place; the previous build survives any failure."""
    backup = None
    if target.exists():
        backup = target.with_name(f".{target.name}.old-{os.getpid()}")
        os.rename(target, backup)
    try:
        os.rename(tmp, target)
    except OSError:
        if backup is not None:
            os.rename(backup, target)
        raise
    if backup is not None:
        shutil.rmtree(backup, ignore_errors=True)


@contextmanager
def staged_output(target: Path):
    """Yield a hidden temporary sibling of ``target``; on success it replaces ``target`` in one move, on any
    failure it is deleted and ``target`` is left as it was."""
    _check_target(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.tmp-", dir=target.parent))
    try:
        yield tmp
        _replace(tmp, target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
