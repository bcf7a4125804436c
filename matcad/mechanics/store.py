"""Cap mechanics curves kept on disk, keyed by their :class:`~matcad.mechanics.case.CapCase`: a board's loaded
bands cost no FElupe run once any command has computed its caps. Lengths mm, forces N, volumes mm³.

A curve is a pure function of its case and of the solver's code, so the key is the SHA-256 of the case's repr, the
FElupe version and the source of the modules that compute it (:data:`SOURCES`): a changed solver, mesh or law
misses the cache instead of reading a stale curve. Files are numpy ``.npz`` archives read with
``allow_pickle=False`` (numbers and text only: nothing in the cache can run code), written to a temporary name and
renamed into place, so a crash or a concurrent writer never leaves half a file; a file that does not read back
(truncated, another format, another case under the same hash) is ignored and recomputed.

Where: ``$MATCAD_CACHE_DIR`` when set (empty: no cache), else ``$XDG_CACHE_HOME/matcad/cap-curves`` (the CLI
points ``XDG_CACHE_HOME`` at a private folder in the temporary directory unless the user chose one, so nothing is
written under ``$HOME`` by default), else the same private temporary folder.

Measured (``benchmarks/analyze.py --startup-only``, a loaded machine): the 4-taxel template's listening bands take
69 s on a cold cache and 1.9 s on a warm one; the whole `matcad analyze REC --spec` 69 s and 5.8 s.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np

SOURCES = ("solver.py", "mesh.py", "material.py", "section.py", "case.py")
"""Modules of :mod:`matcad.mechanics` whose source is part of the key."""
FORMAT = 1


def folder() -> Path | None:
    """The cache folder (see the module docstring), or None when ``$MATCAD_CACHE_DIR`` is set empty."""
    chosen = os.environ.get("MATCAD_CACHE_DIR")
    if chosen is not None:
        return Path(chosen) if chosen else None
    base = os.environ.get("XDG_CACHE_HOME") or str(
        Path(tempfile.gettempdir()) / f"matcad-cache-{os.getuid() if hasattr(os, 'getuid') else 0}")
    return Path(base) / "matcad" / "cap-curves"


def _code_version() -> str:
    from importlib.metadata import version

    here = Path(__file__).parent
    digest = hashlib.sha256(f"{FORMAT} felupe {version('felupe')}".encode())
    for name in SOURCES:
        digest.update((here / name).read_bytes())
    return digest.hexdigest()


def key(case) -> tuple[str, str]:
    """(file stem, full key text) of a case: the text is stored in the file and compared on reading."""
    text = f"{_code_version()}\n{case!r}"
    return hashlib.sha256(text.encode()).hexdigest()[:32], text


def load(case, curve_type, step_type):
    """The stored curve of ``case`` as a ``curve_type`` of ``step_type`` steps (:class:`~matcad.mechanics.solver.
    CapCurve`, :class:`~matcad.mechanics.solver.CapStep`: the solver passes its own types), or None (no cache, no
    file, a file that does not read back as this case's curve)."""
    where = folder()
    if where is None:
        return None
    stem, text = key(case)
    path = where / f"{stem}.npz"
    try:
        with np.load(path, allow_pickle=False) as data:
            if str(data["key"]) != text:
                return None
            meta = json.loads(str(data["meta"]))
            steps = tuple(step_type(s["displacement_mm"], s["force_n"], s["cavity_volume_mm3"],
                                  np.array(data[f"outline_{i}"]), s["peak_strain"], tuple(s["volume_ratio_range"]))
                          for i, s in enumerate(meta["steps"]))
            return curve_type(section=case.section, material=case.material, contact=case.contact,
                            unloaded_volume_mm3=meta["unloaded_volume_mm3"],
                            unloaded_outline=np.array(data["unloaded_outline"]), corner=meta["corner"], steps=steps,
                            complete=meta["complete"], message=meta["message"], nodes=meta["nodes"],
                            cells=meta["cells"], element_size_mm=meta["element_size_mm"],
                            newton_iterations=meta["newton_iterations"], seconds=meta["seconds"])
    except (OSError, KeyError, ValueError, TypeError, json.JSONDecodeError):
        return None


def save(case, curve) -> None:
    """Store ``curve`` under ``case`` (atomically; silently nothing when the folder cannot be written)."""
    where = folder()
    if where is None:
        return
    stem, text = key(case)
    scalars = ("unloaded_volume_mm3", "corner", "complete", "message", "nodes", "cells", "element_size_mm",
               "newton_iterations", "seconds")
    meta = {name: getattr(curve, name) for name in scalars}
    meta["steps"] = [{k: v for k, v in dataclasses.asdict(s).items() if k != "cavity_outline"} for s in curve.steps]
    arrays = {f"outline_{i}": np.asarray(s.cavity_outline, dtype=float) for i, s in enumerate(curve.steps)}
    try:
        where.mkdir(parents=True, exist_ok=True, mode=0o700)
        fd, tmp = tempfile.mkstemp(prefix=f".{stem}-", suffix=".npz", dir=where)
        try:
            with os.fdopen(fd, "wb") as out:
                np.savez(out, key=np.array(text), meta=np.array(json.dumps(meta, default=float)),
                         unloaded_outline=np.asarray(curve.unloaded_outline, dtype=float), **arrays)
            os.replace(tmp, where / f"{stem}.npz")
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    except OSError:
        return
