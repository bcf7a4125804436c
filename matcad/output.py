"""Output folders that are never half-written, never lost and never littered.

A kit is written into a hidden sibling of the target, ``.<name>.tmp-<owner>-<random>``, finished with a
manifest (:data:`MANIFEST`: every file matcad wrote, with its size and sha256) and then put in place:

- on Linux by one atomic exchange of the two folders (``renameat2(RENAME_EXCHANGE)``): there is no moment at
  which the target is missing; the previous kit, now in the hidden folder, is deleted afterwards;
- elsewhere by two renames through ``.<name>.old-<owner>-<random>``; if the process dies between them, the
  next run finds the backup without its target and restores it.

``<owner>`` is the writing process's pid and start time, so the next run tells a dead writer's leftovers
(removed, or restored as above) from a live concurrent build's (left alone). Parent folders created for a
build that then fails are removed again. A non-empty target is replaced only if it is exactly what matcad
wrote there: its manifest lists every file in it with unchanged content. Anything else in it (a user's notes
next to report.json, an edited report) makes the build refuse (exit 2) rather than delete it. Folders are made
with the permissions the umask allows, like the files.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import secrets
import shutil
from contextlib import contextmanager
from pathlib import Path

from matcad.errors import WRITTEN, OutputError

MANIFEST = ".matcad-manifest.json"
"""Written last into every output folder: {"matcad": version, "files": {relative path: {bytes, sha256}}}."""
_LEFTOVER = re.compile(r"\.(?P<name>.+)\.(?P<kind>tmp|old)-(?P<pid>\d+)-(?P<start>\d+)-[0-9a-f]+")


def _start_time(pid: int) -> int:
    """The process's start time in clock ticks since boot (Linux /proc), 0 where unknown."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
        return int(stat.rsplit(")", 1)[1].split()[19])
    except (OSError, ValueError, IndexError):
        return 0


def _owner() -> str:
    return f"{os.getpid()}-{_start_time(os.getpid())}"


def _alive(pid: int, start: int) -> bool:
    """Whether the process that wrote a leftover still runs (a reused pid has another start time)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's live process
        return True
    except OSError:
        return False
    return start == 0 or _start_time(pid) in (0, start)


def _sweep(parent: Path) -> None:
    """Deal with what dead matcad processes left in ``parent``: a backup whose target is missing (death between
    the two renames) is restored; every other leftover of a dead process is deleted."""
    try:
        entries = list(parent.iterdir())
    except OSError:
        return
    for entry in entries:
        m = _LEFTOVER.fullmatch(entry.name)
        if not m or entry.is_symlink() or not entry.is_dir() or _alive(int(m["pid"]), int(m["start"])):
            continue
        target = parent / m["name"]
        if m["kind"] == "old" and not target.exists() and not target.is_symlink():
            os.rename(entry, target)
        else:
            shutil.rmtree(entry, ignore_errors=True)


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _files(folder: Path) -> set[str]:
    return {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file() or p.is_symlink()}


def write_manifest(folder: Path) -> dict:
    """List every file in ``folder`` with its size and sha256 in :data:`MANIFEST`; returns the listing."""
    from matcad import __version__

    files = {name: {"bytes": (folder / name).stat().st_size, "sha256": _sha256(folder / name)}
             for name in sorted(_files(folder))}
    (folder / MANIFEST).write_text(json.dumps({"matcad": __version__, "files": files}, indent=1) + "\n",
                                   encoding="utf-8")
    return files


def _check_target(target: Path) -> None:
    """Refuse to replace anything but an empty folder or exactly what matcad wrote there."""
    if not target.exists() and not target.is_symlink():
        return
    if target.is_symlink() or not target.is_dir():
        raise OutputError(f"output folder {target}: exists and is not a folder; refusing to replace it")
    present = _files(target) - {MANIFEST}
    if not present and not any(p.is_dir() for p in target.iterdir()):
        return
    try:
        listed = json.loads((target / MANIFEST).read_text(encoding="utf-8"))["files"]
        assert isinstance(listed, dict)
    except (OSError, ValueError, KeyError, TypeError, AssertionError):
        raise OutputError(f"output folder {target}: exists and is not a matcad output folder (no {MANIFEST}); "
                          "refusing to replace it: choose another --out or empty it") from None
    foreign = sorted(present - set(listed))
    changed = sorted(name for name in present & set(listed)
                     if (target / name).is_symlink() or _sha256(target / name) != listed[name].get("sha256"))
    if foreign or changed:
        what = "; ".join(x for x in (f"not written by matcad: {', '.join(foreign[:5])}" if foreign else "",
                                     f"changed since: {', '.join(changed[:5])}" if changed else "") if x)
        raise OutputError(f"output folder {target}: holds files matcad would delete ({what}); refusing to "
                          "replace it: move them out or choose another --out")


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap two folders (Linux renameat2 RENAME_EXCHANGE); False where unsupported."""
    import ctypes
    import sys

    if not sys.platform.startswith("linux"):
        return False
    try:  # the C library this process already runs on (ctypes.util.find_library spawns ldconfig: ~40 ms)
        renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    if renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    if err in (22, 38, 95):  # EINVAL, ENOSYS, EOPNOTSUPP: this file system cannot: fall back to renames
        return False
    raise OSError(err, os.strerror(err), str(b))


def _replace(tmp: Path, target: Path, backup: Path) -> None:
    """Put the finished ``tmp`` in place of ``target``; the previous kit survives any failure or interrupt."""
    if not target.exists():
        os.rename(tmp, target)
        return
    if _exchange(tmp, target):
        shutil.rmtree(tmp, ignore_errors=True)  # now the previous kit
        return
    os.rename(target, backup)
    try:
        os.rename(tmp, target)
    except BaseException:
        if not target.exists():
            os.rename(backup, target)
        raise
    shutil.rmtree(backup, ignore_errors=True)


def _make_parents(parent: Path) -> list[Path]:
    """Create ``parent`` and its missing ancestors; returns those created, deepest last."""
    missing = []
    p = parent
    while not p.exists() and p != p.parent:
        missing.append(p)
        p = p.parent
    for p in reversed(missing):
        try:
            p.mkdir()
        except FileExistsError:
            pass
    return list(reversed(missing))


@contextmanager
def staged_output(target: Path):
    """Yield a hidden temporary sibling of ``target``; on success it is given a manifest and replaces
    ``target``, on any failure or interrupt it is deleted, ``target`` is left as it was and no parent folder
    created for it remains."""
    target = Path(os.path.abspath(target))
    if target == target.parent:
        raise OutputError(f"output folder {target}: is the file-system root; choose a folder")
    if target.parent.is_dir():
        _sweep(target.parent)
    _check_target(target)
    created = _make_parents(target.parent)
    tag = f"{_owner()}-{secrets.token_hex(4)}"
    tmp = target.parent / f".{target.name}.tmp-{tag}"
    try:
        tmp.mkdir()  # mode 0777 less the umask, as for the files written into it (mkdtemp would force 0700)
        yield tmp
        write_manifest(tmp)
        _replace(tmp, target, target.parent / f".{target.name}.old-{tag}")
        WRITTEN.append(target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        for p in reversed(created):
            try:
                p.rmdir()
            except OSError:
                break
        raise
