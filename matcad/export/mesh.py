"""STL and STEP writers for solids (build123d, mm) and mesh checks (trimesh)."""

from __future__ import annotations

import functools
from pathlib import Path


CHORDAL_FLOOR_PER_SIZE = 1e-4
"""Finest chordal deviation used, as a fraction of the part's bounding-box diagonal. The paper's parts (18-44 mm)
give the same triangles from 0.01 mm down to this floor (0.002-0.004 mm: 1.5k-5.8k triangles each), while
1e-5 mm on the same parts takes 10x the triangles and time; finer than 1e-4 of the size is below any printer's
resolution and only burns memory."""


def effective_tolerance_mm(shape, tolerance_mm: float) -> float:
    """The chordal deviation (mm) actually used for ``shape``: the spec's, floored at
    :data:`CHORDAL_FLOOR_PER_SIZE` x its bounding-box diagonal (mm)."""
    size = shape.bounding_box().size
    return max(tolerance_mm, CHORDAL_FLOOR_PER_SIZE * (size.X ** 2 + size.Y ** 2 + size.Z ** 2) ** 0.5)


def _write_failed(path: Path, kind: str) -> OSError:
    """The kernel's writers return False without a reason; the usual one is the disk (full or read-only)."""
    import errno
    import shutil

    try:
        free = shutil.disk_usage(path.parent).free
    except OSError:
        free = 0
    if free < (1 << 20):
        return OSError(errno.ENOSPC, f"{kind} export failed: no space left on the device", str(path))
    return OSError(errno.EIO, f"{kind} export failed (the file could not be written)", str(path))


def write_stl(shape, path: Path, tolerance_mm: float, angular_tolerance_rad: float, matrix=None) -> float:
    """Binary STL in mm with an explicit chordal (mm, floored by :func:`effective_tolerance_mm`) and angular
    (rad) tessellation tolerance; returns the chordal tolerance used (mm). ``matrix`` (4 x 4) moves the
    tessellated mesh (not the B-rep: shared vertices stay bit-identical, so the STL stays closed). Raises
    OSError if it cannot write."""
    from build123d import export_stl

    tolerance = effective_tolerance_mm(shape, tolerance_mm)
    if not export_stl(shape, str(path), tolerance=tolerance, angular_tolerance=angular_tolerance_rad):
        raise _write_failed(path, "STL")
    if matrix is not None:
        import numpy as np
        import trimesh

        mesh = trimesh.load_mesh(str(path), file_type="stl", process=False)
        mesh.apply_transform(np.array(matrix))
        mesh.export(str(path), file_type="stl")
    return tolerance


def write_step(shape, path: Path) -> None:
    """STEP AP214 in mm, byte-for-byte reproducible: a fixed timestamp, and assembly-occurrence ids numbered per
    file (OpenCASCADE numbers them from a process-wide counter, so a second export in one process differs)."""
    import itertools
    import re

    from build123d import Unit, export_step

    if not export_step(shape, str(path), unit=Unit.MM, timestamp="2000-01-01T00:00:00"):
        raise _write_failed(path, "STEP")
    text = path.read_text(encoding="utf-8")
    count = itertools.count(1)

    def renumber(m):
        return f"NEXT_ASSEMBLY_USAGE_OCCURRENCE('{next(count)}'" + re.sub(r"\s*\n\s*", "", m.group(1)) + ";"

    fixed = re.sub(r"NEXT_ASSEMBLY_USAGE_OCCURRENCE\('\d+'(.*?);", renumber, text, flags=re.S)
    if fixed != text:
        path.write_text(fixed, encoding="utf-8")


def load_stl(path: Path):
    """The STL at ``path`` as a trimesh mesh (vertices merged), read once per file version (path, size, mtime):
    the read-back checks, the preview and the print job of one build share it. Do not modify the mesh."""
    st = Path(path).stat()
    return _load_stl(str(path), st.st_size, st.st_mtime_ns)


@functools.lru_cache(maxsize=32)
def _load_stl(path: str, size: int, mtime_ns: int):
    import trimesh

    return trimesh.load_mesh(path, file_type="stl")


def mesh_checks(path: Path) -> dict:
    """Read an STL back: watertight, is_volume, bodies, volume (mm³), triangle count."""
    mesh = load_stl(path)
    bodies = mesh.split(only_watertight=False)
    return {"watertight": bool(mesh.is_watertight), "is_volume": bool(mesh.is_volume),
            "bodies": len(bodies), "volume_mm3": float(mesh.volume), "triangles": int(len(mesh.faces))}
